#include "colonflat/phantom/phantom.h"

#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <thread>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/tool.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

using V3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------------
// Deterministic random numbers (independent of the standard library's distributions).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) { next(); }
  std::uint64_t next() {  // splitmix64
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double normal() {
    double u1 = uniform(), u2 = uniform();
    if (u1 < 1e-300) u1 = 1e-300;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * kPi * u2);
  }

 private:
  std::uint64_t s_;
};

// Materials of the label volume.
enum Material : unsigned char {
  kOutsideAir = 0,
  kSubcutFat,
  kMuscle,
  kVisceralFat,
  kLiver,
  kKidney,
  kSpineCancellous,
  kSpineCortex,
  kLung,
  kColonWall,
  kColonGas,
  kOtherGas,
  kPolyp,
  kFluid0  // kFluid0 + pool index
};

struct Segment {
  const char* name;
};

struct ControlPoint {
  V3 p;
  double r;
  int seg;  // index into kSegmentNames
};

const char* kSegmentNames[] = {"rectum", "sigmoid", "descending", "transverse", "ascending", "cecum"};

// The colon path from the rectum to the cecum (LPS mm: +x left, +y posterior, +z superior), with
// nominal radii. Supine patient: posterior (+y) is down.
std::vector<ControlPoint> base_path() {
  return {
      {{2, 36, -178}, 20, 0},    {{0, 36, -158}, 24, 0},    {{2, 34, -134}, 25, 0},    {{6, 30, -114}, 20, 0},
      {{18, 22, -102}, 15, 1},   {{38, 8, -106}, 14, 1},    {{56, -18, -98}, 14, 1},   {{52, -46, -82}, 14, 1},
      {{26, -58, -72}, 14, 1},   {{-6, -52, -64}, 14, 1},   {{-26, -30, -56}, 14, 1},  {{-20, -4, -46}, 14, 1},
      {{6, 8, -40}, 14, 1},      {{20, -18, -24}, 14, 1},   {{46, -30, -14}, 15, 1},   {{68, -8, -30}, 15, 1},
      {{66, 16, -60}, 16, 1},    {{84, 28, -50}, 17, 2},
      {{96, 32, -16}, 17, 2},    {{100, 34, 24}, 18, 2},    {{100, 30, 64}, 19, 2},    {{96, 16, 98}, 20, 3},
      {{82, -8, 112}, 21, 3},    {{62, -36, 96}, 22, 3},    {{42, -52, 58}, 22, 3},    {{18, -60, 8}, 22, 3},
      {{-10, -60, -2}, 22, 3},   {{-38, -54, 30}, 22, 3},   {{-58, -42, 66}, 23, 3},   {{-76, -14, 96}, 24, 3},
      {{-86, 16, 82}, 25, 4},    {{-86, 28, 50}, 26, 4},    {{-82, 30, 14}, 27, 4},    {{-78, 28, -22}, 28, 4},
      {{-74, 22, -54}, 30, 5},   {{-68, 14, -84}, 30, 5},
  };
}

V3 catmull_rom(const V3& p0, const V3& p1, const V3& p2, const V3& p3, double t) {
  const double t2 = t * t, t3 = t2 * t;
  return 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2 + (-p0 + 3 * p1 - 3 * p2 + p3) * t3);
}

struct Path {
  std::vector<V3> p, T, N, B;
  std::vector<double> s, r;
  std::vector<int> seg;
  double length = 0;
};

// Resamples the spline through the control points every `step` mm; rotation-minimising frames.
Path make_path(const std::vector<ControlPoint>& cps, double step) {
  std::vector<V3> dense;
  std::vector<double> dr;
  std::vector<int> dseg;
  const int n = int(cps.size());
  for (int i = 0; i + 1 < n; ++i) {
    const V3& p0 = cps[std::max(i - 1, 0)].p;
    const V3& p1 = cps[i].p;
    const V3& p2 = cps[i + 1].p;
    const V3& p3 = cps[std::min(i + 2, n - 1)].p;
    for (int k = 0; k < 200; ++k) {
      const double t = k / 200.0;
      dense.push_back(catmull_rom(p0, p1, p2, p3, t));
      const double ts = t * t * (3 - 2 * t);
      dr.push_back(cps[i].r * (1 - ts) + cps[i + 1].r * ts);
      dseg.push_back(t < 0.5 ? cps[i].seg : cps[i + 1].seg);
    }
  }
  dense.push_back(cps.back().p);
  dr.push_back(cps.back().r);
  dseg.push_back(cps.back().seg);
  std::vector<double> acc(dense.size(), 0.0);
  for (std::size_t i = 1; i < dense.size(); ++i) acc[i] = acc[i - 1] + (dense[i] - dense[i - 1]).norm();
  Path P;
  P.length = acc.back();
  const int m = int(std::floor(P.length / step));
  std::size_t j = 0;
  for (int k = 0; k <= m + 1; ++k) {
    const double s = std::min(k * step, P.length);
    while (j + 2 < acc.size() && acc[j + 1] < s) ++j;
    const double f = (acc[j + 1] > acc[j]) ? (s - acc[j]) / (acc[j + 1] - acc[j]) : 0.0;
    P.p.push_back(dense[j] + f * (dense[j + 1] - dense[j]));
    P.r.push_back(dr[j] + f * (dr[j + 1] - dr[j]));
    P.seg.push_back(dseg[j]);
    P.s.push_back(s);
    if (s >= P.length) break;
  }
  const std::size_t q = P.p.size();
  P.T.resize(q);
  for (std::size_t i = 0; i < q; ++i) {
    const V3 d = P.p[std::min(i + 1, q - 1)] - P.p[i == 0 ? 0 : i - 1];
    P.T[i] = d.normalized();
  }
  P.N.resize(q);
  P.B.resize(q);
  V3 n0 = P.T[0].cross(V3(0, 0, 1));
  if (n0.norm() < 1e-3) n0 = P.T[0].cross(V3(1, 0, 0));
  P.N[0] = n0.normalized();
  for (std::size_t i = 1; i < q; ++i) {
    V3 nn = P.N[i - 1] - P.N[i - 1].dot(P.T[i]) * P.T[i];
    if (nn.norm() < 1e-6) nn = P.T[i].unitOrthogonal();
    P.N[i] = nn.normalized();
  }
  for (std::size_t i = 0; i < q; ++i) P.B[i] = P.T[i].cross(P.N[i]);
  return P;
}

// ---------------------------------------------------------------------------------------------

struct Grid {
  std::array<int, 3> n;
  std::array<double, 3> sp, org;
  V3 point(int i, int j, int k) const { return {org[0] + i * sp[0], org[1] + j * sp[1], org[2] + k * sp[2]}; }
  std::size_t index(int i, int j, int k) const { return (std::size_t(k) * n[1] + j) * n[0] + i; }
  std::size_t voxels() const { return std::size_t(n[0]) * n[1] * n[2]; }
  // Index range [lo, hi) covering [a, b] mm along axis d.
  void range(int d, double a, double b, int& lo, int& hi) const {
    lo = std::max(0, int(std::ceil((a - org[d]) / sp[d])));
    hi = std::min(n[d], int(std::floor((b - org[d]) / sp[d])) + 1);
  }
};

struct Fold {
  double s, depth, width, theta0;  // arclength, depth fraction of radius, half-width mm, crescent phase
};
struct Pool {
  double s0, s1;  // arclength range of the segment it lies in (kept free of polyps and strands)
  double level_y, hu;
  V3 seed;        // a point below the level in the lumen: the pool is the lumen below the level connected to it
  std::size_t voxels = 0;
};
struct Bulge {
  double s, amp, sigma_s;
  V3 toward;  // unit direction the bulge points to
};
struct Polyp {
  PhantomPolyp gt;
  V3 center, base, axis;  // head centre, wall attachment point, axis (wall -> lumen)
  double stalk_r = 0;
};
struct Strand {
  V3 a, b;
  double r;
};
struct Hole {
  V3 a, b;
  double r;
  double s;
};

struct Model {
  Grid g;
  Path path;
  std::vector<Fold> folds;
  std::vector<Pool> pools;
  std::vector<Bulge> bulges;
  std::vector<Polyp> polyps;
  std::vector<Strand> strands;
  std::vector<Hole> holes;
  double collapse_s = -1, collapse_len = 0;
  double wall = 3.0;
  std::vector<std::pair<V3, V3>> gas;  // other gas: centre, radii
};

// Nominal radius at arclength s, with the collapsed stretch.
double radius_at(const Model& m, std::size_t i, double t) {
  const Path& P = m.path;
  const std::size_t j = std::min(i + 1, P.r.size() - 1);
  double r = P.r[i] * (1 - t) + P.r[j] * t;
  if (m.collapse_s >= 0) {
    const double s = P.s[i] * (1 - t) + P.s[j] * t;
    const double u = std::abs(s - m.collapse_s) / (0.5 * m.collapse_len);
    if (u < 1) r *= std::clamp((u - 0.35) / 0.65, 0.0, 1.0);  // zero over the middle 35 %
  }
  return r;
}

// Effective lumen radius at (s, direction u from the centreline): folds narrow it, bulges widen it.
double lumen_radius(const Model& m, double s, double r, double theta, const V3& u) {
  double f = 0;
  for (const Fold& fd : m.folds) {
    const double ds = (s - fd.s) / fd.width;
    if (std::abs(ds) > 3) continue;
    // Three crescents between the taeniae: depth varies with the angle.
    const double w = 0.5 + 0.5 * std::cos(3 * (theta - fd.theta0));
    f = std::max(f, fd.depth * std::exp(-ds * ds) * std::sqrt(w));
  }
  double R = r * (1 - f);
  for (const Bulge& b : m.bulges) {
    const double ds = (s - b.s) / b.sigma_s;
    if (std::abs(ds) > 3) continue;
    const double c = std::max(0.0, u.dot(b.toward));
    R += b.amp * std::exp(-0.5 * ds * ds) * c * c * c * c;
  }
  return R;
}

double seg_point_dist2(const V3& p, const V3& a, const V3& b, double* tout = nullptr) {
  const V3 d = b - a;
  const double l2 = d.squaredNorm();
  double t = l2 > 0 ? (p - a).dot(d) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  if (tout) *tout = t;
  return (a + t * d - p).squaredNorm();
}

void parallel_for(int n, const std::function<void(int, int)>& body) {
  const int threads = std::max(1, std::min<int>(2, int(std::thread::hardware_concurrency())));
  std::vector<std::thread> ts;
  for (int t = 0; t < threads; ++t) {
    const int lo = n * t / threads, hi = n * (t + 1) / threads;
    ts.emplace_back([&, lo, hi] { body(lo, hi); });
  }
  for (auto& t : ts) t.join();
}

// Body, fat, muscle, organs, spine, lungs: materials of every voxel before the colon.
void paint_body(const Grid& g, std::vector<unsigned char>& mat) {
  parallel_for(g.n[2], [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k) {
      const double z = g.org[2] + k * g.sp[2];
      const double ax = 165 - 10 * (z / 200) * (z / 200), ay = 125 - 6 * (z / 200) * (z / 200), cy = 5;
      for (int j = 0; j < g.n[1]; ++j) {
        const double y = g.org[1] + j * g.sp[1];
        for (int i = 0; i < g.n[0]; ++i) {
          const double x = g.org[0] + i * g.sp[0];
          unsigned char m = kOutsideAir;
          auto ell = [&](double a, double b) { return (x / a) * (x / a) + ((y - cy) / b) * ((y - cy) / b); };
          if (ell(ax, ay) <= 1) {
            m = kSubcutFat;
            if (ell(ax - 16, ay - 16) <= 1) m = kMuscle;
            if (ell(ax - 26, ay - 26) <= 1) {
              m = kVisceralFat;
              auto in_ell = [&](double cx, double cyy, double cz, double rx, double ry, double rz) {
                const double a = (x - cx) / rx, b = (y - cyy) / ry, c = (z - cz) / rz;
                return a * a + b * b + c * c <= 1;
              };
              if (in_ell(-70, 5, 150, 75, 85, 60)) m = kLiver;
              if (in_ell(-72, 62, 55, 28, 22, 50) || in_ell(72, 62, 65, 28, 22, 50)) m = kKidney;
              const double psx = std::abs(x) - 42, psy = y - 72;
              if (z < 60 && psx * psx + psy * psy < 20 * 20) m = kMuscle;  // psoas
              const double sx = x, sy = y - 94, sr2 = sx * sx + sy * sy;
              if (sr2 < 17 * 17) m = sr2 > 14 * 14 ? kSpineCortex : kSpineCancellous;
              // Lung bases above the diaphragm domes.
              const double lx = std::abs(x) - 85, ly = y - 10;
              if (std::abs(x) > 28 && z > 132 + 0.004 * (lx * lx + ly * ly)) m = kLung;
            }
          }
          mat[g.index(i, j, k)] = m;
        }
      }
    }
  });
}

double hu_of(unsigned char m, const Model& md) {
  switch (m) {
    case kOutsideAir: return -1000;
    case kSubcutFat: return -100;
    case kMuscle: return 50;
    case kVisceralFat: return -90;
    case kLiver: return 60;
    case kKidney: return 35;
    case kSpineCancellous: return 350;
    case kSpineCortex: return 900;
    case kLung: return -860;
    case kColonWall: return 40;
    case kColonGas: return -1000;
    case kOtherGas: return -1000;
    case kPolyp: return 45;
    default: return md.pools.at(m - kFluid0).hu;
  }
}

bool is_lumen(unsigned char m) { return m == kColonGas || m >= kFluid0; }

}  // namespace

// ---------------------------------------------------------------------------------------------

Phantom generate_phantom(const PhantomOptions& o) {
  if (o.size != "small" && o.size != "full") throw UsageError("--size must be small or full (got '" + o.size + "')");
  if (!(o.noise_hu >= 0 && o.noise_hu <= 500)) throw UsageError("--noise must be in [0, 500] HU");
  if (!(o.blur_mm >= 0 && o.blur_mm <= 5)) throw UsageError("--blur must be in [0, 5] mm");
  const bool full = o.size == "full";
  Model md;
  Grid& g = md.g;
  if (full) g = {{512, 512, 400}, {0.7, 0.7, 1.0}, {-178.85, -178.85, -199.5}};
  else g = {{128, 128, 128}, {2.8, 2.8, 3.125}, {-177.8, -177.8, -198.4375}};
  const double hmax = std::max({g.sp[0], g.sp[1], g.sp[2]});
  Rng rng(o.seed);

  // Path: perturbed control points and radii.
  std::vector<ControlPoint> cps = base_path();
  for (std::size_t i = 1; i + 1 < cps.size(); ++i) {
    cps[i].p += V3(rng.uniform(-5, 5), rng.uniform(-4, 4), rng.uniform(-5, 5));
    cps[i].r *= rng.uniform(0.9, 1.08);
  }
  md.path = make_path(cps, 1.0);
  Path& P = md.path;
  const std::size_t np = P.p.size();
  auto seg_range = [&](int seg, double& a, double& b) {
    a = P.length;
    b = 0;
    for (std::size_t i = 0; i < np; ++i)
      if (P.seg[i] == seg) {
        a = std::min(a, P.s[i]);
        b = std::max(b, P.s[i]);
      }
  };
  auto index_at = [&](double s) { return std::min(np - 1, std::size_t(std::max(0.0, std::round(s / 1.0)))); };

  // Haustral folds: none in the rectum, sparse in the sigmoid, every ~28-40 mm elsewhere.
  const double fold_w = std::max(1.4, 0.8 * hmax);
  {
    double a, b;
    seg_range(0, a, b);
    double s = b + 20;
    while (s < P.length - 25) {
      const int seg = P.seg[index_at(s)];
      md.folds.push_back({s, rng.uniform(0.28, 0.42), fold_w, rng.uniform(0, 2 * kPi / 3)});
      s += seg == 1 ? rng.uniform(45, 60) : rng.uniform(28, 40);
    }
  }
  // Collapsed stretch in the descending colon.
  {
    double a, b;
    seg_range(2, a, b);
    if (o.collapsed_segment) {
      md.collapse_s = a + (b - a) * rng.uniform(0.4, 0.6);
      md.collapse_len = 36;
      md.folds.erase(std::remove_if(md.folds.begin(), md.folds.end(),
                                    [&](const Fold& f) { return std::abs(f.s - md.collapse_s) < 30; }),
                     md.folds.end());
    }
  }
  auto nearest_fold_gap = [&](double s) {
    double d = 1e9;
    for (const Fold& f : md.folds) d = std::min(d, std::abs(f.s - s));
    return d;
  };
  const V3 up(0, -1, 0);  // anterior: away from gravity for a supine patient
  // Direction in the cross-section at path index i closest to `want`.
  auto cross_dir = [&](std::size_t i, const V3& want) {
    V3 u = want - want.dot(P.T[i]) * P.T[i];
    if (u.norm() < 1e-6) u = P.N[i];
    return V3(u.normalized());
  };
  auto theta_of = [&](std::size_t i, const V3& u) { return std::atan2(u.dot(P.B[i]), u.dot(P.N[i])); };

  // Near-touching segments: the closest approach between distant parts, bulged to a thin gap.
  std::vector<NoiseSite> sites;
  const double touch_gap = std::max(0.8, 0.9 * hmax);
  if (o.topological_noise) {
    double best = 1e9;
    std::size_t bi = 0, bj = 0;
    for (std::size_t i = 0; i < np; i += 2)
      for (std::size_t j = i + 200; j < np; j += 2) {
        const double gap = (P.p[i] - P.p[j]).norm() - P.r[i] - P.r[j];
        if (gap < best && (P.seg[i] == 1 || P.seg[i] == 3) && (P.seg[j] == 1 || P.seg[j] == 3) && nearest_fold_gap(P.s[i]) > 8 && nearest_fold_gap(P.s[j]) > 8 &&
            (md.collapse_s < 0 || (std::abs(P.s[i] - md.collapse_s) > 40 && std::abs(P.s[j] - md.collapse_s) > 40))) {
          best = gap;
          bi = i;
          bj = j;
        }
      }
    if (best < 60) {
      const double need = best - touch_gap;  // total bulge so that the lumens are touch_gap apart
      const V3 dir = (P.p[bj] - P.p[bi]).normalized();
      md.bulges.push_back({P.s[bi], need / 2, 8, cross_dir(bi, dir)});
      md.bulges.push_back({P.s[bj], need / 2, 8, cross_dir(bj, -dir)});
      const V3 mid = P.p[bi] + dir * (P.r[bi] + need / 2 + touch_gap / 2);
      sites.push_back({0, "near_touch", {mid.x(), mid.y(), mid.z()}, touch_gap, "possible_handle"});
      md.folds.erase(std::remove_if(md.folds.begin(), md.folds.end(),
                                    [&](const Fold& f) {
                                      return std::abs(f.s - P.s[bi]) < 20 || std::abs(f.s - P.s[bj]) < 20;
                                    }),
                     md.folds.end());
    }
  }

  // Tagged-fluid pools in dependent parts: rectum, descending, ascending + cecum. Each has one
  // horizontal level (constant LPS y) at its lowest point and fills the lumen below that level
  // connected to it (communicating vessels), so its surface is flat everywhere.
  if (o.tagged_fluid) {
    const int pool_segs[] = {0, 2, 4};
    for (int ps : pool_segs) {
      double a, b;
      seg_range(ps, a, b);
      if (ps == 4) b = P.length;  // ascending + cecum
      std::size_t low = index_at(a + 10);
      for (std::size_t i = index_at(a + 10); i <= index_at(b - 5); ++i)
        if (P.p[i].y() > P.p[low].y()) low = i;
      // Fluid surface: between 20 % and 55 % of the diameter from the dependent side.
      const double level = P.p[low].y() + P.r[low] * rng.uniform(-0.1, 0.6);
      const V3 seed = P.p[low] + V3(0, 1, 0) * (0.5 * (level - P.p[low].y()) + 0.5 * P.r[low]);
      md.pools.push_back({a, b, level, std::round(rng.uniform(320, 580)), seed});
    }
  }

  // Polyps: sizes 4-15 mm, sessile and pedunculated, on non-dependent walls between folds.
  std::vector<std::pair<double, std::string>> polyp_list = {{5, "sessile"}, {6, "pedunculated"}, {8, "sessile"},
                                                            {10, "pedunculated"}, {12, "sessile"}, {15, "pedunculated"},
                                                            {4, "sessile"}};
  auto in_pool_s = [&](double s) {
    for (const Pool& p : md.pools)
      if (s > p.s0 - 10 && s < p.s1 + 10) return true;
    return false;
  };
  std::vector<double> used_s;
  for (const Bulge& b : md.bulges) used_s.push_back(b.s);
  if (md.collapse_s >= 0) used_s.push_back(md.collapse_s);
  auto free_s = [&](double s, double clearance) {
    for (double u : used_s)
      if (std::abs(u - s) < clearance) return false;
    return true;
  };
  if (o.polyps) {
    int id = 1;
    for (const auto& [d, type] : polyp_list) {
      for (int attempt = 0; attempt < 400; ++attempt) {
        const double s = rng.uniform(40, P.length - 40);
        const std::size_t i = index_at(s);
        const double r = P.r[i];
        const bool ped = type == "pedunculated";
        if (ped && r < 19) continue;
        if (r < d + 6 || nearest_fold_gap(s) < 0.5 * d + 5 || !free_s(s, d + 25)) continue;
        V3 u = cross_dir(i, up);
        const double rot = rng.uniform(-0.9, 0.9);
        u = (std::cos(rot) * u + std::sin(rot) * P.T[i].cross(u)).normalized();
        if (in_pool_s(s) && u.dot(up) < 0.5) continue;
        Polyp p;
        const double R = radius_at(md, i, 0);
        p.axis = -u;  // from the wall towards the centreline
        p.base = P.p[i] + u * R;
        if (ped) {
          const double stalk = std::clamp(0.6 * d, 5.0, 8.0);
          p.center = p.base + p.axis * (stalk + 0.5 * d);
          p.stalk_r = std::max(1.2, std::max(0.18 * d, 0.7 * hmax));
        } else {
          p.center = p.base + p.axis * (0.5 * d - 0.25 * d);  // a dome three quarters of a sphere high
        }
        p.gt = {id++, {p.center.x(), p.center.y(), p.center.z()}, d, type, kSegmentNames[P.seg[i]], s};
        md.polyps.push_back(p);
        used_s.push_back(s);
        break;
      }
    }
  }

  // Strands across the lumen and holes through folds.
  if (o.topological_noise) {
    const double strand_r = std::max(0.8, 0.7 * hmax);
    for (int n = 0, attempt = 0; n < 3 && attempt < 500; ++attempt) {
      const double s = rng.uniform(60, P.length - 60);
      const std::size_t i = index_at(s);
      if (in_pool_s(s) || !free_s(s, 30) || nearest_fold_gap(s) < 6 || radius_at(md, i, 0) < 14) continue;
      const double ang = rng.uniform(0, 2 * kPi);
      const V3 u = (std::cos(ang) * P.N[i] + std::sin(ang) * P.B[i]).normalized();
      const double R = radius_at(md, i, 0);
      md.strands.push_back({P.p[i] - u * (R + 1.5), P.p[i] + u * (R + 1.5), strand_r});
      sites.push_back({0, "strand", {P.p[i].x(), P.p[i].y(), P.p[i].z()}, 2 * strand_r, "handle"});
      used_s.push_back(s);
      ++n;
    }
    const double hole_r = std::max(0.9, 0.75 * hmax);
    int made = 0;
    for (std::size_t f = 2; f < md.folds.size() && made < 3; f += std::max<std::size_t>(1, md.folds.size() / 4)) {
      Fold& fd = md.folds[f];
      if (in_pool_s(fd.s) || !free_s(fd.s, 15)) continue;
      fd.depth = std::max(fd.depth, 0.42);
      fd.width = std::max(fd.width, hole_r * 1.6 + 0.6 * hmax);
      const std::size_t i = index_at(fd.s);
      // The crescent peak: theta = theta0 (cos(3(theta - theta0)) = 1).
      const double th = fd.theta0;
      const V3 u = (std::cos(th) * P.N[i] + std::sin(th) * P.B[i]).normalized();
      const double R = radius_at(md, i, 0);
      const V3 c = P.p[i] + u * (R * (1 - 0.5 * fd.depth));
      md.holes.push_back({c - P.T[i] * (3 * fd.width), c + P.T[i] * (3 * fd.width), hole_r, fd.s});
      sites.push_back({0, "fold_hole", {c.x(), c.y(), c.z()}, 2 * hole_r, "handle"});
      used_s.push_back(fd.s);
      ++made;
    }
  }
  for (std::size_t k = 0; k < sites.size(); ++k) sites[k].id = int(k + 1);

  // Other gas (stomach bubble, small-bowel gas) away from the colon.
  {
    const std::vector<std::pair<V3, V3>> cand = {{{40, -55, 128}, {22, 12, 10}},
                                                 {{-20, -70, -10}, {8, 6, 6}},
                                                 {{30, -70, 10}, {7, 6, 6}},
                                                 {{-40, -60, 20}, {6, 5, 5}}};
    for (const auto& [c, r] : cand) {
      double dmin = 1e9;
      for (std::size_t i = 0; i < np; ++i) dmin = std::min(dmin, (P.p[i] - c).norm() - P.r[i] - r.maxCoeff());
      if (dmin > 12) md.gas.push_back({c, r});
    }
  }

  // ---- Materials.
  std::vector<unsigned char> mat(g.voxels());
  paint_body(g, mat);
  for (const auto& [c, r] : md.gas) {
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) g.range(d, c[d] - r[d] - 3, c[d] + r[d] + 3, lo[d], hi[d]);
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const V3 q = (g.point(i, j, k) - c).cwiseQuotient(r);
          const double e = q.norm();
          if (e <= 1) mat[g.index(i, j, k)] = kOtherGas;
          else if (e <= 1 + 3.0 / r.minCoeff() && mat[g.index(i, j, k)] == kVisceralFat)
            mat[g.index(i, j, k)] = kColonWall;
        }
  }

  // Colon: nearest centreline point per voxel near the path.
  double rmax = 0;
  for (double r : P.r) rmax = std::max(rmax, r);
  for (const Bulge& b : md.bulges) rmax = std::max(rmax, 30 + b.amp);
  const double reach = rmax + md.wall + 2;
  V3 lo_mm = P.p[0], hi_mm = P.p[0];
  for (const V3& p : P.p) {
    lo_mm = lo_mm.cwiseMin(p);
    hi_mm = hi_mm.cwiseMax(p);
  }
  int blo[3], bhi[3];
  for (int d = 0; d < 3; ++d) g.range(d, lo_mm[d] - reach, hi_mm[d] + reach, blo[d], bhi[d]);
  const int bn[3] = {bhi[0] - blo[0], bhi[1] - blo[1], bhi[2] - blo[2]};
  const std::size_t bvox = std::size_t(bn[0]) * bn[1] * bn[2];
  std::vector<float> best_d2(bvox, std::numeric_limits<float>::infinity());
  std::vector<float> best_s(bvox, -1.f);
  auto bidx = [&](int i, int j, int k) { return (std::size_t(k - blo[2]) * bn[1] + (j - blo[1])) * bn[0] + (i - blo[0]); };
  // Per path segment radius of influence.
  std::vector<double> seg_reach(np);
  for (std::size_t i = 0; i < np; ++i) {
    double r = P.r[i];
    for (const Bulge& b : md.bulges)
      if (std::abs(P.s[i] - b.s) < 4 * b.sigma_s) r += b.amp;
    seg_reach[i] = r + md.wall + 2;
  }
  parallel_for(bn[2], [&](int k0, int k1) {
    const double z0 = g.org[2] + (blo[2] + k0) * g.sp[2], z1 = g.org[2] + (blo[2] + k1 - 1) * g.sp[2];
    for (std::size_t i = 0; i + 1 < np; ++i) {
      const V3 &a = P.p[i], &b = P.p[i + 1];
      const double rr = std::max(seg_reach[i], seg_reach[i + 1]);
      if (std::min(a.z(), b.z()) - rr > z1 || std::max(a.z(), b.z()) + rr < z0) continue;
      int lo[3], hi[3];
      for (int d = 0; d < 3; ++d) g.range(d, std::min(a[d], b[d]) - rr, std::max(a[d], b[d]) + rr, lo[d], hi[d]);
      lo[2] = std::max(lo[2], blo[2] + k0);
      hi[2] = std::min(hi[2], blo[2] + k1);
      const float rr2 = float(rr * rr);
      for (int k = lo[2]; k < hi[2]; ++k)
        for (int j = lo[1]; j < hi[1]; ++j)
          for (int ii = lo[0]; ii < hi[0]; ++ii) {
            double t;
            const float d2 = float(seg_point_dist2(g.point(ii, j, k), a, b, &t));
            if (d2 > rr2) continue;
            const std::size_t q = bidx(ii, j, k);
            if (d2 < best_d2[q]) {
              best_d2[q] = d2;
              best_s[q] = float(P.s[i] + t * (P.s[i + 1] - P.s[i]));
            }
          }
    }
  });

  // Geometry at a voxel of the colon box: nearest centreline point, radius, angle.
  struct Local {
    double s, d, R, Reff, theta;
    std::size_t i;
    V3 u;
  };
  auto local_at = [&](int ii, int j, int k, Local& L) -> bool {
    const std::size_t q = bidx(ii, j, k);
    if (best_s[q] < 0) return false;
    L.s = best_s[q];
    L.i = std::min(np - 2, std::size_t(L.s / 1.0));
    const double t = std::clamp(L.s - P.s[L.i], 0.0, 1.0);
    const V3 c = P.p[L.i] + t * (P.p[L.i + 1] - P.p[L.i]);
    const V3 v = g.point(ii, j, k) - c;
    L.d = v.norm();
    L.u = L.d > 1e-9 ? V3(v / L.d) : P.N[L.i];
    const V3 N = (P.N[L.i] * (1 - t) + P.N[L.i + 1] * t);
    const V3 B = (P.B[L.i] * (1 - t) + P.B[L.i + 1] * t);
    L.theta = std::atan2(v.dot(B), v.dot(N));
    L.R = radius_at(md, L.i, t);
    L.Reff = lumen_radius(md, L.s, L.R, L.theta, L.u);
    return true;
  };
  parallel_for(bn[2], [&](int k0, int k1) {
    Local L;
    for (int k = blo[2] + k0; k < blo[2] + k1; ++k)
      for (int j = blo[1]; j < bhi[1]; ++j)
        for (int ii = blo[0]; ii < bhi[0]; ++ii) {
          if (!local_at(ii, j, k, L)) continue;
          unsigned char& m = mat[g.index(ii, j, k)];
          if (m == kOutsideAir || m == kSubcutFat) continue;
          if (L.d < L.Reff) {
            m = kColonGas;
          } else if (L.d < std::max(L.Reff, L.R) + md.wall) {
            m = kColonWall;
          }
        }
  });
  // Polyps (tissue) inside the lumen.
  for (const Polyp& p : md.polyps) {
    const double rad = 0.5 * p.gt.diameter_mm;
    const V3 lo = p.center.cwiseMin(p.base) - V3::Constant(rad + 2), hi = p.center.cwiseMax(p.base) + V3::Constant(rad + 2);
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, lo[d], hi[d], l[d], h[d]);
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          const V3 q = g.point(i, j, k);
          bool in = (q - p.center).norm() <= rad;
          if (p.stalk_r > 0) in = in || seg_point_dist2(q, p.base - p.axis * 2.0, p.center) <= p.stalk_r * p.stalk_r;
          unsigned char& m = mat[g.index(i, j, k)];
          if (in && is_lumen(m)) m = kPolyp;
        }
  }
  for (const Strand& st : md.strands) {
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(st.a[d], st.b[d]) - st.r - 1, std::max(st.a[d], st.b[d]) + st.r + 1, l[d], h[d]);
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          unsigned char& m = mat[g.index(i, j, k)];
          if (is_lumen(m) && seg_point_dist2(g.point(i, j, k), st.a, st.b) <= st.r * st.r) m = kColonWall;
        }
  }
  for (const Hole& ho : md.holes) {
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(ho.a[d], ho.b[d]) - ho.r - 1, std::max(ho.a[d], ho.b[d]) + ho.r + 1, l[d], h[d]);
    Local L;
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          unsigned char& m = mat[g.index(i, j, k)];
          if (m != kColonWall || !local_at(i, j, k, L) || L.d >= L.R) continue;  // only the fold ridge
          if (seg_point_dist2(g.point(i, j, k), ho.a, ho.b) <= ho.r * ho.r) m = kColonGas;
        }
  }

  // Fluid pools: flood fill of the gas below each level from its seed.
  for (std::size_t pi = 0; pi < md.pools.size(); ++pi) {
    Pool& pool = md.pools[pi];
    int c[3];
    for (int d = 0; d < 3; ++d) c[d] = int(std::lround((pool.seed[d] - g.org[d]) / g.sp[d]));
    auto below = [&](int j) { return g.org[1] + j * g.sp[1] > pool.level_y; };
    std::vector<std::size_t> stack;
    // The seed voxel, or the nearest gas voxel below the level around it.
    for (int r = 0; r <= 3 && stack.empty(); ++r)
      for (int dk = -r; dk <= r && stack.empty(); ++dk)
        for (int dj = -r; dj <= r && stack.empty(); ++dj)
          for (int di = -r; di <= r && stack.empty(); ++di) {
            const int i = c[0] + di, j = c[1] + dj, k = c[2] + dk;
            if (i < 0 || j < 0 || k < 0 || i >= g.n[0] || j >= g.n[1] || k >= g.n[2]) continue;
            if (mat[g.index(i, j, k)] == kColonGas && below(j)) stack.push_back(g.index(i, j, k));
          }
    const unsigned char fl = static_cast<unsigned char>(kFluid0 + pi);
    for (std::size_t q : stack) mat[q] = fl;
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      ++pool.voxels;
      const int i = int(q % g.n[0]), j = int((q / g.n[0]) % g.n[1]), k = int(q / (std::size_t(g.n[0]) * g.n[1]));
      const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= g.n[0] || n[1] >= g.n[1] || n[2] >= g.n[2]) continue;
        const std::size_t r = g.index(n[0], n[1], n[2]);
        if (mat[r] != kColonGas || !below(n[1])) continue;
        mat[r] = fl;
        stack.push_back(r);
      }
    }
  }

  // ---- Images.
  Phantom out;
  auto make_ct = [&]() {
    auto im = CtImage::New();
    CtImage::SizeType sz{{std::size_t(g.n[0]), std::size_t(g.n[1]), std::size_t(g.n[2])}};
    im->SetRegions(sz);
    const double sp[3] = {g.sp[0], g.sp[1], g.sp[2]};
    const double org[3] = {g.org[0], g.org[1], g.org[2]};
    im->SetSpacing(sp);
    im->SetOrigin(org);
    im->Allocate();
    return im;
  };
  out.lumen = MaskImage::New();
  {
    MaskImage::SizeType sz{{std::size_t(g.n[0]), std::size_t(g.n[1]), std::size_t(g.n[2])}};
    out.lumen->SetRegions(sz);
    const double sp[3] = {g.sp[0], g.sp[1], g.sp[2]};
    const double org[3] = {g.org[0], g.org[1], g.org[2]};
    out.lumen->SetSpacing(sp);
    out.lumen->SetOrigin(org);
    out.lumen->Allocate();
  }
  std::size_t lumen_vox = 0, fluid_vox = 0;
  {
    CtImage::Pointer sharp = make_ct();
    float* hu = sharp->GetBufferPointer();
    unsigned char* lm = out.lumen->GetBufferPointer();
    for (std::size_t q = 0; q < mat.size(); ++q) {
      hu[q] = float(hu_of(mat[q], md));
      lm[q] = is_lumen(mat[q]) ? 1 : 0;
      lumen_vox += lm[q];
      fluid_vox += mat[q] >= kFluid0;
    }
    std::vector<unsigned char>().swap(mat);
    std::vector<float>().swap(best_d2);
    std::vector<float>().swap(best_s);
    const double blur = o.blur_mm > 0 ? o.blur_mm : std::max(0.45, 0.6 * std::min(g.sp[0], g.sp[1]));
    using Smooth = itk::SmoothingRecursiveGaussianImageFilter<CtImage, CtImage>;
    auto sm = Smooth::New();
    sm->SetInput(sharp);
    sm->SetSigma(blur);
    sm->SetNumberOfWorkUnits(2);
    sm->Update();
    out.ct = sm->GetOutput();
    out.ct->DisconnectPipeline();
  }
  {
    float* hu = out.ct->GetBufferPointer();
    const std::size_t slice = std::size_t(g.n[0]) * g.n[1];
    parallel_for(g.n[2], [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k) {
        Rng r(o.seed * 1000003ull + std::uint64_t(k) * 7919ull + 17);
        for (std::size_t q = std::size_t(k) * slice; q < std::size_t(k + 1) * slice; ++q) {
          const double v = hu[q] + (o.noise_hu > 0 ? o.noise_hu * r.normal() : 0.0);
          hu[q] = float(std::clamp(std::nearbyint(v), -1024.0, 3071.0)) + 0.0f;  // no -0
        }
      }
    });
  }

  // ---- Ground truth and description.
  const double voxel_ml = g.sp[0] * g.sp[1] * g.sp[2] / 1000.0;
  for (const Polyp& p : md.polyps) out.polyps.push_back(p.gt);
  for (std::size_t i = 0; i < np; i += 2)
    out.centerline.push_back({{P.p[i].x(), P.p[i].y(), P.p[i].z()}, radius_at(md, i, 0), P.s[i], kSegmentNames[P.seg[i]]});
  out.noise_sites = sites;
  nlohmann::json segs = nlohmann::json::array();
  for (int sgi = 0; sgi < 6; ++sgi) {
    double a, b;
    seg_range(sgi, a, b);
    segs.push_back({{"name", kSegmentNames[sgi]}, {"start_mm", a}, {"end_mm", b}});
  }
  nlohmann::json pools = nlohmann::json::array();
  for (const Pool& p : md.pools)
    pools.push_back({{"segment_start_mm", p.s0},
                     {"segment_end_mm", p.s1},
                     {"level_y_lps_mm", p.level_y},
                     {"seed_lps_mm", {p.seed.x(), p.seed.y(), p.seed.z()}},
                     {"hu", p.hu},
                     {"volume_ml", double(p.voxels) * g.sp[0] * g.sp[1] * g.sp[2] / 1000.0}});
  nlohmann::json gas = nlohmann::json::array();
  for (const auto& [c, r] : md.gas)
    gas.push_back({{"center_lps_mm", {c.x(), c.y(), c.z()}}, {"radii_mm", {r.x(), r.y(), r.z()}}});
  out.description = {
      {"generator", "colonflat phantom"},
      {"version", colonflat_version()},
      {"seed", o.seed},
      {"size", o.size},
      {"units", "mm"},
      {"coordinate_system", "LPS"},
      {"patient_position", "supine (posterior, +y, is gravity-dependent)"},
      {"volume",
       {{"dimensions", {g.n[0], g.n[1], g.n[2]}},
        {"spacing_mm", {g.sp[0], g.sp[1], g.sp[2]}},
        {"origin_lps_mm", {g.org[0], g.org[1], g.org[2]}},
        {"direction", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}}},
      {"options",
       {{"collapsed_segment", o.collapsed_segment},
        {"tagged_fluid", o.tagged_fluid},
        {"polyps", o.polyps},
        {"topological_noise", o.topological_noise},
        {"noise_hu", o.noise_hu},
        {"blur_mm", o.blur_mm > 0 ? o.blur_mm : std::max(0.45, 0.6 * std::min(g.sp[0], g.sp[1]))}}},
      {"colon",
       {{"length_mm", P.length},
        {"segments", segs},
        {"radius_range_mm", {*std::min_element(P.r.begin(), P.r.end()), *std::max_element(P.r.begin(), P.r.end())}},
        {"folds", md.folds.size()},
        {"wall_thickness_mm", md.wall},
        {"lumen_volume_ml", double(lumen_vox) * voxel_ml},
        {"fluid_volume_ml", double(fluid_vox) * voxel_ml},
        {"collapsed", md.collapse_s >= 0 ? nlohmann::json({{"center_mm", md.collapse_s}, {"length_mm", md.collapse_len}})
                                         : nlohmann::json(nullptr)},
        {"fluid_pools", pools}}},
      {"other_gas", gas},
      {"hu",
       {{"air", -1000}, {"lung", -860}, {"fat", -100}, {"visceral_fat", -90}, {"muscle", 50}, {"colon_wall", 40},
        {"polyp", 45}, {"liver", 60}, {"kidney", 35}, {"spine", 350}, {"cortical_bone", 900}}},
      {"files",
       {{"ct", "ct.nrrd (or dicom/ with --format dicom)"},
        {"lumen_mask", "lumen_mask.nrrd"},
        {"polyps", "polyps.json"},
        {"centerline", "centerline.json"},
        {"noise_sites", "noise_sites.json"}}}};
  return out;
}

nlohmann::json polyps_json(const Phantom& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& q : p.polyps)
    a.push_back({{"id", q.id},
                 {"center_lps_mm", q.center_lps_mm},
                 {"diameter_mm", q.diameter_mm},
                 {"type", q.type},
                 {"segment", q.segment},
                 {"arclength_mm", q.arclength_mm}});
  return a;
}

nlohmann::json centerline_json(const Phantom& p) {
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& c : p.centerline)
    pts.push_back({{"p_lps_mm", c.p_lps_mm}, {"radius_mm", c.radius_mm}, {"arclength_mm", c.arclength_mm}, {"segment", c.segment}});
  return {{"units", "mm"}, {"coordinate_system", "LPS"}, {"from", "rectum"}, {"to", "cecum"}, {"points", pts}};
}

nlohmann::json noise_sites_json(const Phantom& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& s : p.noise_sites)
    a.push_back({{"id", s.id}, {"type", s.type}, {"center_lps_mm", s.center_lps_mm}, {"size_mm", s.size_mm}, {"effect", s.effect}});
  return a;
}

void write_phantom(const Phantom& p, const fs::path& dir, const std::string& format) {
  if (format != "nrrd" && format != "dicom") throw UsageError("--format must be nrrd or dicom (got '" + format + "')");
  if (!p.ct || !p.lumen) throw Error("write_phantom: empty phantom");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  OutputTransaction tx;
  if (format == "nrrd") {
    volume_artifact().write(std::any(p.ct), tx.stage(dir / "ct.nrrd"), dir / "ct.nrrd");
  }
  mask_artifact().write(std::any(p.lumen), tx.stage(dir / "lumen_mask.nrrd"), dir / "lumen_mask.nrrd");
  auto put_json = [&](const char* name, const nlohmann::json& j) {
    std::ofstream f(tx.stage(dir / name));
    f << j.dump(2) << "\n";
    if (!f) throw Error((dir / name).string() + ": cannot write");
  };
  put_json("polyps.json", polyps_json(p));
  put_json("centerline.json", centerline_json(p));
  put_json("noise_sites.json", noise_sites_json(p));
  nlohmann::json d = p.description;
  d["files"]["ct"] = format == "nrrd" ? "ct.nrrd" : "dicom/";
  put_json("phantom.json", d);
  if (format == "dicom") {
    const fs::path dd = dir / "dicom";
    if (fs::exists(dd)) fs::remove_all(dd, ec);
    DicomWriteOptions w;
    w.uid_seed = p.description.value("seed", std::uint64_t(1));
    write_dicom_series(p.ct.GetPointer(), dd, w);
  }
  tx.commit();
}

}  // namespace cf
