#include "colonflat/render/polyps.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticCellLocator.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/vertex_graph.h"

namespace cf {
namespace {

using V3 = Eigen::Vector3d;

V3 P(const TriangleList& s, int i) { return {s.points[i][0], s.points[i][1], s.points[i][2]}; }

std::vector<double> vertex_areas(const TriangleList& s) {
  std::vector<double> a(s.points.size(), 0.0);
  for (const auto& t : s.triangles) {
    const double ar = 0.5 * (P(s, t[1]) - P(s, t[0])).cross(P(s, t[2]) - P(s, t[0])).norm();
    for (int v : t) a[v] += ar / 3;
  }
  return a;
}

// Vertices within Euclidean distance r of `c`, reached through edges (at least the 2-ring).
void neighbourhood(const VertexGraph& g, const TriangleList& s, int c, double r, std::vector<int>& stamp, int tag,
                   std::vector<int>& out) {
  out.clear();
  out.push_back(c);
  stamp[c] = tag;
  const V3 pc = P(s, c);
  const double r2 = r * r;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const int v = out[k];
    const bool near_ring = k == 0 || (P(s, v) - pc).squaredNorm() <= r2;
    if (!near_ring) continue;
    for (int q = g.start[v]; q < g.start[v + 1]; ++q) {
      const int w = g.neighbours[q];
      if (stamp[w] == tag) continue;
      stamp[w] = tag;
      if ((P(s, w) - pc).squaredNorm() <= r2 || k == 0) out.push_back(w);
    }
  }
}

// The normal equations of the weighted quadric fit h = q0 x^2/2 + q1 xy + q2 y^2/2 + q3 x + q4 y
// over the neighbours `nb` of vertex i (weights exp(-d^2 / fit_radius^2)), in the tangent frame
// (t1, t2, n): A's lower triangle and b. Returns the number of neighbours used.
int quadric_normal_equations(const TriangleList& s, int i, const std::vector<int>& nb, const V3& t1, const V3& t2,
                             const V3& n, double fit_radius, Eigen::Matrix<double, 5, 5>& A,
                             Eigen::Matrix<double, 5, 1>& b) {
  A.setZero();
  b.setZero();
  const V3 pc = P(s, i);
  const double inv_r2 = 1.0 / (fit_radius * fit_radius);
  int used = 0;
  for (int j : nb) {
    if (j == i) continue;
    const V3 d = P(s, j) - pc;
    const double x = d.dot(t1), y = d.dot(t2), h = d.dot(n);
    const double w = std::exp(-d.squaredNorm() * inv_r2);
    const double r[5] = {0.5 * x * x, x * y, 0.5 * y * y, x, y};
    for (int p = 0; p < 5; ++p) {
      const double wr = w * r[p];
      b[p] += wr * h;
      for (int q = p; q < 5; ++q) A(q, p) += wr * r[q];
    }
    ++used;
  }
  return used;
}

// Shape index and curvedness of vertex i from a weighted quadric fit of its neighbourhood `nb`
// in its tangent frame (normal into the lumen); false when fewer than 5 neighbours.
bool fit_vertex(const TriangleList& s, const std::array<double, 3>& normal, int i, const std::vector<int>& nb,
                double fit_radius, Curvature& c) {
  const V3 n = -V3(normal[0], normal[1], normal[2]).normalized();  // into the lumen
  const V3 t1 = (std::abs(n.x()) < 0.9 ? V3::UnitX() : V3::UnitY()).cross(n).normalized();
  const V3 t2 = n.cross(t1);
  Eigen::Matrix<double, 5, 5> A;
  Eigen::Matrix<double, 5, 1> b;
  if (quadric_normal_equations(s, i, nb, t1, t2, n, fit_radius, A, b) < 5) return false;
  A.diagonal().array() += 1e-12 * (A.trace() + 1e-30);
  const Eigen::Matrix<double, 5, 1> q = A.selfadjointView<Eigen::Lower>().ldlt().solve(b);
  Eigen::Matrix2d H;
  H << q[0], q[1], q[1], q[2];
  const Eigen::Vector2d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(-H).eigenvalues();  // ascending
  const double k1 = ev[1], k2 = ev[0];
  c.k1[i] = k1;
  c.k2[i] = k2;
  c.si[i] = k1 - k2 > 1e-12 ? 2 / M_PI * std::atan((k1 + k2) / (k1 - k2)) : (k1 > 0 ? 1.0 : k1 < 0 ? -1.0 : 0.0);
  c.cv[i] = std::sqrt(0.5 * (k1 * k1 + k2 * k2));
  return true;
}

// surface_curvature() over a given vertex graph: each vertex on its own (contiguous chunks of
// vertices over the threads, each with its own visit stamps), so any thread count gives the same.
Curvature curvature_on_graph(const TriangleList& s, const VertexGraph& g,
                             const std::vector<std::array<double, 3>>& normals, double fit_radius) {
  const std::size_t nv = s.points.size();
  Curvature c;
  c.k1.assign(nv, 0);
  c.k2.assign(nv, 0);
  c.si.assign(nv, 0);
  c.cv.assign(nv, 0);
  parallel_for(nv, [&](std::size_t begin, std::size_t end) {
    std::vector<int> stamp(nv, -1), nb;
    for (std::size_t i = begin; i < end; ++i) {
      neighbourhood(g, s, int(i), fit_radius, stamp, int(i), nb);
      fit_vertex(s, normals[i], int(i), nb, fit_radius, c);
    }
  });
  return c;
}

}  // namespace

Curvature surface_curvature(const TriangleList& s, const std::vector<std::array<double, 3>>& normals,
                            double fit_radius) {
  return curvature_on_graph(s, vertex_graph(s), normals, fit_radius);
}

namespace {

// detect_polyps() as named steps: seeds grown into cap regions, each cap measured (centre, apex,
// footprint, elongation, size, score), then candidates of one polyp merged.
class PolypDetector {
 public:
  PolypDetector(const TriangleList& s, const std::vector<std::array<double, 3>>& normals, const PolypOptions& o)
      : s_(s), normals_(normals), o_(o), g_(vertex_graph(s)), c_(curvature_on_graph(s, g_, normals, o.fit_radius)), area_(vertex_areas(s)),
        region_(s.points.size(), -1), footprint_stamp_(s.points.size(), -1) {}
  std::vector<PolypCandidate> run(Curvature* curvature_out);

 private:
  bool in_cap(int v) const {
    return c_.si[v] >= o_.grow_si && c_.cv[v] >= 0.5 * o_.min_curvedness && c_.cv[v] <= 2 * o_.max_curvedness;
  }
  bool seed(int v) const { return c_.si[v] >= o_.seed_si && c_.cv[v] >= o_.min_curvedness && c_.cv[v] <= o_.max_curvedness; }
  std::vector<int> grow_cap(int v0);
  bool measure_cap(const std::vector<int>& cap, PolypCandidate& pc, V3& centre) const;
  void grow_footprint(const std::vector<int>& cap, PolypCandidate& pc);
  double elongation(const std::vector<int>& cap, const V3& centre, double cap_area) const;
  void size_and_score(PolypCandidate& pc) const;
  bool passes(const PolypCandidate& pc) const;
  bool solid(const std::vector<int>& cap, const PolypCandidate& pc) const;

  const TriangleList& s_;
  const std::vector<std::array<double, 3>>& normals_;  // out of the lumen
  const PolypOptions& o_;
  const VertexGraph g_;
  Curvature c_;  // after g_: computed on it
  const std::vector<double> area_;  // per vertex, a third of its triangles' area (mm^2)
  std::vector<int> region_;         // cap region of each vertex, -1 when none
  std::vector<int> footprint_stamp_;
  int regions_ = 0;
};

std::vector<PolypCandidate> PolypDetector::run(Curvature* curvature_out) {
  std::vector<PolypCandidate> out;
  for (int v0 = 0; v0 < int(s_.points.size()); ++v0) {
    if (region_[v0] >= 0 || !seed(v0)) continue;
    const std::vector<int> cap = grow_cap(v0);
    PolypCandidate pc;
    V3 centre;
    if (!measure_cap(cap, pc, centre)) continue;
    grow_footprint(cap, pc);
    pc.elongation = elongation(cap, centre, pc.cap_area_mm2);
    size_and_score(pc);
    if (passes(pc) && solid(cap, pc)) out.push_back(std::move(pc));
  }
  if (curvature_out) *curvature_out = std::move(c_);
  return out;
}

// The seed's cap region: connected vertices with cap-like shape index and curvedness in range.
std::vector<int> PolypDetector::grow_cap(int v0) {
  std::vector<int> cap{v0};
  region_[v0] = regions_;
  for (std::size_t k = 0; k < cap.size(); ++k)
    for (int q = g_.start[cap[k]]; q < g_.start[cap[k] + 1]; ++q) {
      const int w = g_.neighbours[q];
      if (region_[w] < 0 && in_cap(w)) region_[w] = regions_, cap.push_back(w);
    }
  ++regions_;
  return cap;
}

// Area-weighted means over the cap; the apex is the cap vertex nearest the cap's centroid.
// False for a cap without area.
bool PolypDetector::measure_cap(const std::vector<int>& cap, PolypCandidate& pc, V3& cen) const {
  cen = V3::Zero();
  double a = 0, si = 0, cv = 0;
  for (int v : cap) cen += area_[v] * P(s_, v), a += area_[v], si += area_[v] * c_.si[v], cv += area_[v] * c_.cv[v];
  if (a <= 0) return false;
  cen /= a;
  pc.cap_area_mm2 = a;
  pc.mean_si = si / a;
  pc.mean_cv = cv / a;
  int apex = cap[0];
  for (int v : cap)
    if ((P(s_, v) - cen).squaredNorm() < (P(s_, apex) - cen).squaredNorm()) apex = v;
  pc.vertex = apex;
  pc.center_lps_mm = s_.points[apex];
  return true;
}

// Footprint: the convex part around the cap, within max_radius of the apex.
void PolypDetector::grow_footprint(const std::vector<int>& cap, PolypCandidate& pc) {
  const V3 pa = P(s_, pc.vertex);
  std::vector<int> fp(cap);
  for (int v : fp) footprint_stamp_[v] = regions_;
  double fa = 0;
  for (std::size_t k = 0; k < fp.size(); ++k) {
    fa += area_[fp[k]];
    for (int q = g_.start[fp[k]]; q < g_.start[fp[k] + 1]; ++q) {
      const int w = g_.neighbours[q];
      if (footprint_stamp_[w] == regions_ || c_.si[w] < o_.footprint_si || (P(s_, w) - pa).norm() > o_.max_radius)
        continue;
      footprint_stamp_[w] = regions_;
      fp.push_back(w);
    }
  }
  pc.footprint_area_mm2 = fa;
  pc.footprint = std::move(fp);
}

// Elongation of the cap (fold tips are long, polyp heads round): spread of its vertices.
double PolypDetector::elongation(const std::vector<int>& cap, const V3& cen, double a) const {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int v : cap) {
    const V3 d = P(s_, v) - cen;
    cov += area_[v] * d * d.transpose();
  }
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov / a).eigenvalues();  // ascending
  return ev[1] > 1e-12 ? std::sqrt(ev[2] / ev[1]) : 99.0;
}

void PolypDetector::size_and_score(PolypCandidate& pc) const {
  // Size: diameter of the sphere with the cap's curvature (2 / CV); the cap of a polyp head is
  // close to a sphere, a fold is not a cap at all.
  pc.size_mm = 2.0 / std::max(1e-6, pc.mean_cv);
  // Score: how cap-like (mean SI), how much of the sphere the cap covers, how round it is.
  const double s_si = std::clamp((pc.mean_si - o_.grow_si) / (1 - o_.grow_si), 0.0, 1.0);
  const double s_area = std::clamp(pc.cap_area_mm2 * pc.mean_cv * pc.mean_cv / M_PI / 0.6, 0.0, 1.0);
  const double s_round = std::clamp((2.5 - pc.elongation) / 1.5, 0.0, 1.0);
  pc.score = 0.4 * s_si + 0.3 * s_area + 0.3 * s_round;
}

bool PolypDetector::passes(const PolypCandidate& pc) const {
  return !(pc.cap_area_mm2 < o_.min_cap_area || pc.size_mm < o_.min_size || pc.size_mm > o_.max_size ||
           pc.score < o_.min_score);
}

// The surface's triangles with a corner within `radius` of `centre`, in a cell locator (ray casts).
vtkSmartPointer<vtkStaticCellLocator> local_locator(const TriangleList& s, const V3& centre, double radius) {
  vtkNew<vtkPoints> points;
  vtkNew<vtkCellArray> cells;
  std::vector<vtkIdType> local(s.points.size(), -1);
  const double r2 = radius * radius;
  for (const auto& t : s.triangles) {
    if ((P(s, t[0]) - centre).squaredNorm() > r2 && (P(s, t[1]) - centre).squaredNorm() > r2 &&
        (P(s, t[2]) - centre).squaredNorm() > r2)
      continue;
    vtkIdType ids[3];
    for (int k = 0; k < 3; ++k) {
      if (local[t[k]] < 0) local[t[k]] = points->InsertNextPoint(s.points[t[k]].data());
      ids[k] = local[t[k]];
    }
    cells->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(points);
  pd->SetPolys(cells);
  auto locator = vtkSmartPointer<vtkStaticCellLocator>::New();
  locator->SetDataSet(pd);
  locator->BuildLocator();
  return locator;
}

// Whether the cap is the top of a solid body: the tissue behind it (median over its vertices, at
// most 64 of them evenly spread, of the distance along the outward normal to the next crossing of
// the surface) is at least min_thickness_ratio x its size. A polyp head of diameter d is tissue
// for about d behind its apex and at least d/2 behind most of its cap, then the wall; the partial-
// volume layer of a gas/tagged-fluid level left out of the lumen is a sheet about one voxel thick
// with lumen (the fluid) right behind it, and its rim is as curved as a polyp head.
bool PolypDetector::solid(const std::vector<int>& cap, const PolypCandidate& pc) const {
  const double reach = pc.size_mm, start = 1e-3 * reach;
  double extent = 0;
  for (int v : cap) extent = std::max(extent, (P(s_, v) - P(s_, pc.vertex)).norm());
  const auto locator = local_locator(s_, P(s_, pc.vertex), extent + reach);
  std::vector<double> thickness;
  const std::size_t step = std::max<std::size_t>(1, cap.size() / 64);
  for (std::size_t k = 0; k < cap.size(); k += step) {
    const V3 p = P(s_, cap[k]), n = V3(normals_[cap[k]][0], normals_[cap[k]][1], normals_[cap[k]][2]).normalized();
    V3 a = p + start * n, b = p + reach * n, hit;
    double t = 0, pcoords[3];
    int sub = 0;
    thickness.push_back(locator->IntersectWithLine(a.data(), b.data(), 0.0, t, hit.data(), pcoords, sub) ? (hit - p).norm()
                                                                                                     : reach);
  }
  std::nth_element(thickness.begin(), thickness.begin() + thickness.size() / 2, thickness.end());
  return thickness[thickness.size() / 2] >= o_.min_thickness_ratio * pc.size_mm;
}

// Merge candidates whose apexes are closer than the larger radius (one polyp, several caps);
// the best score wins; ids 1.. by decreasing score.
std::vector<PolypCandidate> merge_one_polyp_caps(std::vector<PolypCandidate> out) {
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  std::vector<PolypCandidate> kept;
  for (auto& p : out) {
    bool dup = false;
    for (const auto& k : kept) {
      const double d = (V3(p.center_lps_mm[0], p.center_lps_mm[1], p.center_lps_mm[2]) -
                        V3(k.center_lps_mm[0], k.center_lps_mm[1], k.center_lps_mm[2])).norm();
      if (d < 0.5 * std::max(p.size_mm, k.size_mm)) dup = true;
    }
    if (!dup) kept.push_back(std::move(p));
  }
  for (std::size_t i = 0; i < kept.size(); ++i) kept[i].id = int(i) + 1;
  return kept;
}

}  // namespace

std::vector<PolypCandidate> detect_polyps(const TriangleList& s, const std::vector<std::array<double, 3>>& normals,
                                          const PolypOptions& o, Curvature* curvature_out) {
  return merge_one_polyp_caps(PolypDetector(s, normals, o).run(curvature_out));
}

std::vector<KnownPolyp> known_polyps_from_json(const nlohmann::json& j0, const std::string& name) {
  const nlohmann::json& j = j0.is_object() && j0.contains("polyps") ? j0["polyps"] : j0;
  if (!j.is_array()) throw InputError(name, "known polyps must be a JSON list");
  std::vector<KnownPolyp> out;
  int next = 1;
  for (const auto& e : j) {
    KnownPolyp k;
    k.id = next++;
    const nlohmann::json* c = &e;
    if (e.is_object()) {
      for (const char* key : {"center_lps_mm", "center", "position", "position_lps_mm"})
        if (e.contains(key)) c = &e[key];
      if (e.contains("id") && e["id"].is_number_integer()) k.id = e["id"];
      k.diameter_mm = e.value("diameter_mm", 0.0);
      k.type = e.value("type", "");
    }
    if (!c->is_array() || c->size() != 3 || !(*c)[0].is_number() || !(*c)[1].is_number() || !(*c)[2].is_number())
      throw InputError(name, "known polyp " + std::to_string(out.size() + 1) + " has no [x, y, z] position (LPS mm)");
    k.center_lps_mm = {(*c)[0].get<double>(), (*c)[1].get<double>(), (*c)[2].get<double>()};
    out.push_back(k);
  }
  return out;
}

std::vector<KnownPolyp> read_known_polyps(const std::filesystem::path& path) {
  return known_polyps_from_json(read_json_file(path), path.string());
}

DetectionScore score_detections(const std::vector<PolypCandidate>& cands, const std::vector<KnownPolyp>& truth,
                                double min_diameter, double tol) {
  DetectionScore sc;
  auto dist = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  };
  auto hit = [&](const PolypCandidate& c, const KnownPolyp& k) {
    return dist(c.center_lps_mm, k.center_lps_mm) <= 0.5 * k.diameter_mm + tol;
  };
  for (const auto& k : truth) {
    if (k.diameter_mm < min_diameter) continue;
    ++sc.polyps;
    bool found = false;
    for (const auto& c : cands) found = found || hit(c, k);
    if (found) ++sc.polyps_detected;
    else sc.missed_ids.push_back(k.id);
  }
  for (const auto& c : cands) {
    bool any = false;
    for (const auto& k : truth) any = any || hit(c, k);
    if (!any) ++sc.false_positives;
  }
  sc.sensitivity = sc.polyps ? double(sc.polyps_detected) / sc.polyps : 1.0;
  return sc;
}

}  // namespace cf
