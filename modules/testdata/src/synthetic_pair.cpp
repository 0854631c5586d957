#include "colonflat/testdata/synthetic_pair.h"

#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include <Eigen/Geometry>

#include "colonflat/flatten/flat_artifact.h"

namespace cf {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// A centre line sampled every 0.25 mm of its parameter, with arc length and a parallel-transport frame.
struct Curve {
  std::vector<Eigen::Vector3d> p, e1, e2;
  std::vector<double> arc;
  // Index of the sample at arc length s.
  size_t at_arc(double s) const {
    return std::min(arc.size() - 1, size_t(std::lower_bound(arc.begin(), arc.end(), s) - arc.begin()));
  }
};

Curve sample_curve(const std::function<Eigen::Vector3d(double)>& f, double t_max) {
  Curve c;
  for (double t = 0; t <= t_max; t += 0.25) c.p.push_back(f(t));
  const size_t n = c.p.size();
  c.arc.assign(n, 0.0);
  for (size_t i = 1; i < n; ++i) c.arc[i] = c.arc[i - 1] + (c.p[i] - c.p[i - 1]).norm();
  Eigen::Vector3d r(1, 0, 0);  // transported from a fixed start vector: same start in both scans
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d t = (c.p[std::min(n - 1, i + 1)] - c.p[i == 0 ? 0 : i - 1]).normalized();
    r = (r - r.dot(t) * t).normalized();
    c.e1.push_back(r);
    c.e2.push_back(t.cross(r));
  }
  return c;
}

struct Fold { double sigma, phi, depth; };

// The tube in material coordinates: lumen radius at (sigma, phi).
struct Tube {
  SyntheticPairOptions o;
  std::vector<Fold> folds;
  std::vector<SyntheticPolyp> polyps;
  double radius(double sigma, double phi) const {
    double r = o.radius_mm * (1 + 0.15 * std::sin(kTwoPi * sigma / 230 + 1) + 0.08 * std::sin(kTwoPi * sigma / 97));
    for (const auto& f : folds) {
      const double ds = (sigma - f.sigma) / 2.5;
      if (std::abs(ds) > 4) continue;
      const double da = std::remainder(phi - f.phi, kTwoPi);  // crescent: 2/3 of the circumference
      const double w = std::abs(da) < 2.1 ? 0.5 * (1 + std::cos(da / 2.1 * 3.14159265)) : 0.0;
      r -= f.depth * std::exp(-ds * ds) * std::sqrt(w);
    }
    for (const auto& q : polyps) {
      const double d2 = std::pow(sigma - q.sigma_mm, 2) + std::pow(o.radius_mm * std::remainder(phi - q.phi_rad, kTwoPi), 2);
      r -= 0.5 * q.size_mm * std::exp(-d2 / (2 * std::pow(q.size_mm / 3, 2)));
    }
    return r;
  }
};

Tube make_tube(const SyntheticPairOptions& o) {
  Tube tube{o, {}, {}};
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (double s = 15 + 20 * u(rng); s < o.length_mm - 15; s += 18 + 22 * u(rng))
    tube.folds.push_back({s, kTwoPi * u(rng), o.radius_mm * (0.15 + 0.15 * u(rng))});
  for (int i = 0; i < o.polyps; ++i) {
    SyntheticPolyp q;
    q.id = i + 1;
    q.sigma_mm = 40 + (o.length_mm - 80) * (i + 0.2 + 0.6 * u(rng)) / std::max(1, o.polyps);
    q.phi_rad = kTwoPi * u(rng);
    q.size_mm = 6 + 6 * u(rng);
    tube.polyps.push_back(q);
  }
  return tube;
}

// One scan's wall: rings at material sigma, placed on `curve` at arc `place(sigma)`.
struct Placement {
  const Curve* curve;
  std::function<double(double)> arc_of_sigma;  // material sigma -> arc length on the curve
  double twist = 0;                            // rad
};

Eigen::Vector3d wall_point(const Tube& tube, const Placement& pl, double sigma, double phi) {
  const size_t i = pl.curve->at_arc(pl.arc_of_sigma(sigma));
  const double a = phi + pl.twist;
  return pl.curve->p[i] + tube.radius(sigma, phi) * (std::cos(a) * pl.curve->e1[i] + std::sin(a) * pl.curve->e2[i]);
}

struct Grid {
  std::vector<double> sigma, phi;  // per vertex
  int rings = 0, around = 0;
};

// Out of the lumen at material (sigma, phi): the cross product of the wall's two tangents.
Eigen::Vector3d wall_normal(const Tube& tube, const Placement& pl, double s, double f) {
  const double ds = 0.5, dp = 0.01;
  Eigen::Vector3d normal = (wall_point(tube, pl, s + ds, f) - wall_point(tube, pl, s - ds, f))
                               .cross(wall_point(tube, pl, s, f + dp) - wall_point(tube, pl, s, f - dp));
  const Eigen::Vector3d centre = pl.curve->p[pl.curve->at_arc(pl.arc_of_sigma(s))];
  if (normal.dot(wall_point(tube, pl, s, f) - centre) < 0) normal = -normal;
  return normal.normalized();
}

bool removed(const std::vector<std::pair<double, double>>& cuts, double sigma) {
  for (const auto& [a, b] : cuts)
    if (sigma >= a && sigma < b) return true;
  return false;
}

// The kept rings in runs (a stretch left out of the segmentation splits the colon): run id per ring, -1 = left out.
std::vector<int> ring_runs(const Grid& g, const std::vector<std::pair<double, double>>& cuts, int& runs) {
  std::vector<int> run(size_t(g.rings), -1);
  runs = 0;
  for (int r = 0; r < g.rings; ++r) {
    if (removed(cuts, g.sigma[size_t(r * g.around)])) continue;
    if (r == 0 || run[size_t(r - 1)] < 0) ++runs;
    run[size_t(r)] = runs - 1;
  }
  return run;
}

// One band per run of kept rings, in order, ends labelled as flatten labels them (rectum on the
// first, cecum on the last, end A / end B where the colon was cut), `order` reversed among the
// middle bands when `shuffle` (the placement must not rely on flatten's chain).
void add_segments(FlatMap& flat, const Tube& tube, const Placement& pl, const Grid& g, const std::vector<int>& run,
                  int runs, bool with_arc, bool shuffle) {
  double offset = 0;
  for (int k = 0; k < runs; ++k) {
    int r0 = -1, r1 = -1;
    for (int r = 0; r < g.rings; ++r)
      if (run[size_t(r)] == k) r1 = r, r0 = r0 < 0 ? r : r0;
    FlatSegment seg;
    seg.id = k;
    seg.period = kTwoPi * tube.o.radius_mm;
    seg.length = g.sigma[size_t(r1 * g.around)] - g.sigma[size_t(r0 * g.around)];
    seg.order = shuffle && k > 0 && k + 1 < runs ? runs - 1 - k : k;
    if (with_arc) {  // contract 1: a map along the centreline, ends named
      seg.map = "area-balanced";
      seg.centreline_length = pl.arc_of_sigma(g.sigma[size_t(r1 * g.around)]) - pl.arc_of_sigma(g.sigma[size_t(r0 * g.around)]);
      seg.centreline_offset = offset;
      offset += seg.centreline_length;
      seg.x0_end = k == 0 ? "rectum" : "end A";
      seg.x1_end = k + 1 == runs ? "cecum" : "end B";
    }
    flat.segments.push_back(seg);
  }
}

// One scan's flat map: the grid at flat x = flat_x(sigma), y = radius x angle from the cut; with
// `with_arc`, centreline_mm (from each band's x0 end) and angle_rad per vertex and the ends
// labelled. Rings in `cuts` are left out (the colon then has several bands).
FlatMap grid_flat_map(const Tube& tube, const Placement& pl, const Grid& g, const std::function<double(double)>& flat_x,
                      double cut, bool with_arc, const std::vector<std::pair<double, double>>& cuts, bool shuffle) {
  FlatMap flat;
  int runs = 0;
  const std::vector<int> run = ring_runs(g, cuts, runs);
  std::vector<double> run_start(size_t(runs), -1);
  std::vector<int> index(g.sigma.size(), -1);
  for (size_t v = 0; v < g.sigma.size(); ++v) {
    const int k = run[v / size_t(g.around)];
    if (k < 0) continue;
    const double s = g.sigma[v], f = g.phi[v];
    if (run_start[size_t(k)] < 0) run_start[size_t(k)] = s;
    const double angle = std::fmod(f - cut + 2 * kTwoPi, kTwoPi);
    const Eigen::Vector3d p = wall_point(tube, pl, s, f), n = wall_normal(tube, pl, s, f);
    index[v] = int(flat.uv.size());
    flat.uv.push_back({flat_x(s), tube.o.radius_mm * angle});
    flat.position.push_back({p.x(), p.y(), p.z()});
    flat.normal.push_back({n.x(), n.y(), n.z()});
    flat.segment.push_back(k);
    flat.source_vertex.push_back(int(v));
    if (with_arc)
      flat.centreline_mm.push_back(pl.arc_of_sigma(s) - pl.arc_of_sigma(run_start[size_t(k)])), flat.angle_rad.push_back(angle);
  }
  for (int r = 0; r + 1 < g.rings; ++r)
    for (int a = 0; a + 1 < g.around; ++a) {
      const int v = r * g.around + a;
      if (index[size_t(v)] < 0 || index[size_t(v + g.around)] < 0) continue;
      const int w = index[size_t(v)], up = index[size_t(v + g.around)];
      flat.triangles.push_back({w, up, w + 1});
      flat.triangles.push_back({w + 1, up, up + 1});
    }
  add_segments(flat, tube, pl, g, run, runs, with_arc, shuffle);
  return flat;
}

Grid make_grid(double length, double spacing, double radius, double phase) {
  Grid g;
  g.rings = int(length / spacing) + 1;
  g.around = int(std::round(kTwoPi * radius / spacing));
  for (int r = 0; r < g.rings; ++r)
    for (int a = 0; a < g.around; ++a) {
      g.sigma.push_back(std::min(length, r * spacing));
      g.phi.push_back(std::fmod(kTwoPi * (a + phase) / g.around, kTwoPi));
    }
  return g;
}

}  // namespace

SyntheticPair make_synthetic_pair(const SyntheticPairOptions& o) {
  Tube tube = make_tube(o);
  auto base = [](double t) { return Eigen::Vector3d(90 * std::sin(t / 110), 35 * std::sin(t / 170 + 0.5), 0.8 * t); };
  const Curve sup_curve = sample_curve(base, o.length_mm * 1.3);
  const double t_mid = 0.5 * o.length_mm;
  auto shifted = [&](double t) -> Eigen::Vector3d {
    return base(t) + o.shift_mm * std::exp(-std::pow((t - t_mid) / (o.length_mm / 6), 2)) * Eigen::Vector3d(0.8, 0.6, 0);
  };
  const Curve pro_curve = sample_curve(shifted, o.length_mm * 1.3);
  const double L = o.length_mm;
  Placement sup{&sup_curve, [](double s) { return s; }, 0.0};
  Placement pro{&pro_curve, [&](double s) {
                  const double slid = s + o.slide_mm * std::sin(kTwoPi * s / L);
                  return pro_curve.arc[sup_curve.at_arc(slid)] - pro_curve.arc[sup_curve.at_arc(0)];
                }, o.twist_deg * kTwoPi / 360};
  SyntheticPair out;
  const Grid gs = make_grid(L, o.spacing_mm, o.radius_mm, 0.0), gp = make_grid(L, 1.1 * o.spacing_mm, o.radius_mm, 0.37);
  const double pro_len = pro.arc_of_sigma(L);
  auto pro_x = [&](double s) { return o.reverse_prone ? pro_len - 0.95 * pro.arc_of_sigma(s) : 0.95 * pro.arc_of_sigma(s); };
  const FlatMap sup_flat = grid_flat_map(tube, sup, gs, [](double s) { return s; }, 0.3, o.centreline,
                                         o.supine_removed, o.shuffle_pieces);
  const FlatMap pro_flat = grid_flat_map(tube, pro, gp, pro_x, 2.0, o.centreline && !o.reverse_prone, o.prone_removed,
                                         o.shuffle_pieces);
  out.supine = scan_from_polydata(flat_to_polydata(sup_flat), "synthetic supine");
  out.prone = scan_from_polydata(flat_to_polydata(pro_flat), "synthetic prone");
  auto kept = [](const Grid& g, const std::vector<std::pair<double, double>>& cuts, std::vector<double>& sigma,
                 std::vector<double>& phi) {  // material coordinates of the flat vertices (rings left out skipped)
    for (size_t v = 0; v < g.sigma.size(); ++v)
      if (!removed(cuts, g.sigma[v])) sigma.push_back(g.sigma[v]), phi.push_back(g.phi[v]);
  };
  kept(gs, o.supine_removed, out.supine_sigma, out.supine_phi);
  kept(gp, o.prone_removed, out.prone_sigma, out.prone_phi);
  std::mt19937_64 rng(o.seed + 17);
  std::uniform_real_distribution<double> u(0, 1);
  for (auto& q : tube.polyps) {
    q.supine_lps = wall_point(tube, sup, q.sigma_mm, q.phi_rad);
    q.prone_lps = wall_point(tube, pro, q.sigma_mm, q.phi_rad);
    q.in_supine = !removed(o.supine_removed, q.sigma_mm);
    q.in_prone = !removed(o.prone_removed, q.sigma_mm);
    const double size_s = q.size_mm * (0.9 + 0.2 * u(rng)), size_p = q.size_mm * (0.9 + 0.2 * u(rng));
    if (q.in_supine) out.supine.candidates.push_back({q.id, q.supine_lps, size_s, 0.7});
    if (q.in_prone) out.prone.candidates.push_back({q.id, q.prone_lps, size_p, 0.7});
  }
  for (int k = 0; k < o.extra_candidates; ++k) {  // stool or noise: seen in one scan only
    const double ss = L * (0.2 + 0.6 * u(rng)), fs = kTwoPi * u(rng), sp = L * (0.2 + 0.6 * u(rng)), fp = kTwoPi * u(rng);
    if (!removed(o.supine_removed, ss)) out.supine.candidates.push_back({100 + k, wall_point(tube, sup, ss, fs), 7, 0.6});
    if (!removed(o.prone_removed, sp)) out.prone.candidates.push_back({200 + k, wall_point(tube, pro, sp, fp), 7, 0.6});
  }
  out.polyps = tube.polyps;
  return out;
}

}  // namespace cf
