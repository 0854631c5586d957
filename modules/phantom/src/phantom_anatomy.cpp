// The phantom's fixed anatomy: the colon path (control points, Catmull-Rom spline, frames), the
// colon radius with folds, bulges and collapsed stretches, the body (fat, muscle, organs, spine,
// lungs) and the HU value and ground-truth label of every material.
#include <algorithm>
#include <cmath>
#include <thread>

#include "phantom_model.h"

namespace cf::phantom_detail {

const char* const kSegmentNames[6] = {"rectum", "sigmoid", "descending", "transverse", "ascending", "cecum"};

// The colon path from the rectum to the cecum (LPS mm: +x left, +y posterior, +z superior), with
// nominal radii.
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

namespace {
V3 catmull_rom(const V3& p0, const V3& p1, const V3& p2, const V3& p3, double t) {
  const double t2 = t * t, t3 = t2 * t;
  return 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2 + (-p0 + 3 * p1 - 3 * p2 + p3) * t3);
}
}  // namespace

// Resamples the spline through the control points every `step` mm; rotation-minimising frames.
Path make_path(const std::vector<ControlPoint>& cps, double step) {
  std::vector<V3> dense;
  std::vector<double> dr;
  std::vector<int> dseg;
  const int n = int(cps.size());
  for (int i = 0; i + 1 < n; ++i) {
    const V3& p0 = cps[std::max(i - 1, 0)].p;
    const V3& p3 = cps[std::min(i + 2, n - 1)].p;
    for (int k = 0; k < 200; ++k) {
      const double t = k / 200.0;
      dense.push_back(catmull_rom(p0, cps[i].p, cps[i + 1].p, p3, t));
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
  compute_frames(P);
  P.arc = P.s;  // the spline's own arc length
  return P;
}

void compute_frames(Path& P) {
  const std::size_t q = P.p.size();
  P.T.resize(q);
  for (std::size_t i = 0; i < q; ++i) P.T[i] = (P.p[std::min(i + 1, q - 1)] - P.p[i == 0 ? 0 : i - 1]).normalized();
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
  P.arc.assign(q, 0.0);
  for (std::size_t i = 1; i < q; ++i) P.arc[i] = P.arc[i - 1] + (P.p[i] - P.p[i - 1]).norm();
}

// Radius at path index i (+ fraction t) before any collapse.
double open_radius_at(const Model& m, std::size_t i, double t) {
  const Path& P = m.path;
  const std::size_t j = std::min(i + 1, P.r.size() - 1);
  return P.r[i] * (1 - t) + P.r[j] * t;
}

// Nominal radius at path index i (+ fraction t), narrowed to zero in collapsed stretches.
double radius_at(const Model& m, std::size_t i, double t) {
  const Path& P = m.path;
  const std::size_t j = std::min(i + 1, P.r.size() - 1);
  double r = open_radius_at(m, i, t);
  const double s = P.s[i] * (1 - t) + P.s[j] * t;
  for (const Collapse& c : m.collapses) {
    const double u = std::abs(s - c.s) / (0.5 * c.len);
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
    const double w = 0.5 + 0.5 * std::cos(3 * (theta - fd.theta0));  // three crescents between the taeniae
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

double seg_point_dist2(const V3& p, const V3& a, const V3& b, double* tout) {
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

// Material of the body at (x, y, z) before the colon.
unsigned char body_material(double x, double y, double z) {
  const double ax = 165 - 10 * (z / 200) * (z / 200), ay = 125 - 6 * (z / 200) * (z / 200), cy = 5;
  auto ell = [&](double a, double b) { return (x / a) * (x / a) + ((y - cy) / b) * ((y - cy) / b); };
  if (ell(ax, ay) > 1) return kOutsideAir;
  if (ell(ax - 16, ay - 16) > 1) return kSubcutFat;
  if (ell(ax - 26, ay - 26) > 1) return kMuscle;
  auto in_ell = [&](double cx, double cyy, double cz, double rx, double ry, double rz) {
    const double a = (x - cx) / rx, b = (y - cyy) / ry, c = (z - cz) / rz;
    return a * a + b * b + c * c <= 1;
  };
  unsigned char m = kVisceralFat;
  if (in_ell(-70, 5, 150, 75, 85, 60)) m = kLiver;
  if (in_ell(-72, 62, 55, 28, 22, 50) || in_ell(72, 62, 65, 28, 22, 50)) m = kKidney;
  const double psx = std::abs(x) - 42, psy = y - 72;
  if (z < 60 && psx * psx + psy * psy < 20 * 20) m = kMuscle;  // psoas
  const double sy = y - 94, sr2 = x * x + sy * sy;
  if (sr2 < 17 * 17) m = sr2 > 14 * 14 ? kSpineCortex : kSpineCancellous;
  const double lx = std::abs(x) - 85, ly = y - 10;  // lung bases above the diaphragm domes
  if (std::abs(x) > 28 && z > 132 + 0.004 * (lx * lx + ly * ly)) m = kLung;
  return m;
}

// Body, fat, muscle, organs, spine, lungs: materials of every voxel before the colon.
void paint_body(const Grid& g, std::vector<unsigned char>& mat) {
  parallel_for(g.n[2], [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const V3 p = g.point(i, j, k);
          mat[g.index(i, j, k)] = body_material(p.x(), p.y(), p.z());
        }
  });
}

double hu_of(unsigned char m, const Model& md) {
  switch (m) {
    case kOutsideAir: case kColonGas: case kOtherGas: case kBowelGas: case kTubeAir: return -1000;
    case kSubcutFat: return -100;
    case kMuscle: case kBladderWall: return 50;
    case kVisceralFat: return -90;
    case kLiver: return 60;
    case kKidney: return 35;
    case kSpineCancellous: return 350;
    case kSpineCortex: return 900;
    case kLung: return -860;
    case kColonWall: case kBowelWall: return 40;
    case kPolyp: return 45;
    case kUrine: return 10;
    case kBladderContrast: return 900;
    case kTubeWall: return 150;
    case kAorta: return 260;
    case kBowelContrast: return md.bowel.empty() ? 400 : md.bowel.front().hu;
    default: {
      const std::size_t k = std::size_t(m - kFluid0);
      return k < md.pools.size() ? md.pools[k].hu : md.stretches.at(k - md.pools.size()).hu;
    }
  }
}

bool is_lumen(unsigned char m) { return m == kColonGas || m >= kFluid0; }

TruthLabel truth_of(unsigned char m) {
  switch (m) {
    case kColonGas: return kTruthColonGas;
    case kBowelContrast: return kTruthBowelContrast;
    case kBowelGas: return kTruthBowelGas;
    case kUrine: case kBladderContrast: return kTruthBladder;
    case kTubeWall: case kTubeAir: return kTruthTube;
    case kOtherGas: return kTruthOtherGas;
    case kAorta: return kTruthVessel;
    default: return m >= kFluid0 ? kTruthColonFluid : kTruthOther;
  }
}

}  // namespace cf::phantom_detail
