// A free-boundary map of a disk-shaped piece as one band (see disk_map.h).
#include "disk_map.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <cstdio>
#include <cstdlib>

#include "band_faces.h"
#include "whole_band_stop.h"

namespace cf::flat_detail {
namespace {

// The cotangent of the angle at corner k of face f (3D).
double corner_cot(const Surface& s, const Tri& t, int k) {
  const V3 a = s.p[std::size_t(t[(k + 1) % 3])] - s.p[std::size_t(t[k])];
  const V3 b = s.p[std::size_t(t[(k + 2) % 3])] - s.p[std::size_t(t[k])];
  const double c = a.cross(b).norm();
  return c > 0 ? a.dot(b) / c : 0.0;
}

// The conformal energy's matrix M (x^T M x = 2 x (Dirichlet energy - signed area)) over the unknowns
// u_i = 2 i, v_i = 2 i + 1, as triplets: the cotangent Laplacian in both coordinates and, per
// boundary edge a -> b in its face's order, the area term -(u_a v_b - u_b v_a). `clamp`: each half
// cotangent clamped to [0.01, 100] (corner_weights'; a positive weight only adds a positive
// semidefinite term, so M stays positive semidefinite).
std::vector<Eigen::Triplet<double>> conformal_triplets(const Surface& s, const Edges& E, const std::vector<char>& degenerate,
                                                       bool clamp) {
  std::vector<Eigen::Triplet<double>> tr;
  tr.reserve(s.t.size() * 24 + E.ev.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (degenerate[f]) continue;
    const Tri& t = s.t[f];
    for (int k = 0; k < 3; ++k) {
      const double w = clamp ? std::clamp(0.5 * corner_cot(s, t, k), 0.01, 100.0) : 0.5 * corner_cot(s, t, k);
      const int i = t[(k + 1) % 3], j = t[(k + 2) % 3];
      for (int c = 0; c < 2; ++c) {
        tr.emplace_back(2 * i + c, 2 * i + c, w), tr.emplace_back(2 * j + c, 2 * j + c, w);
        tr.emplace_back(2 * i + c, 2 * j + c, -w), tr.emplace_back(2 * j + c, 2 * i + c, -w);
      }
    }
  }
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    if (E.ef[e][1] >= 0) continue;
    const Tri& t = s.t[std::size_t(E.ef[e][0])];
    int a = E.ev[e][0], b = E.ev[e][1];
    for (int k = 0; k < 3; ++k)
      if (t[k] == b && t[(k + 1) % 3] == a) std::swap(a, b);  // a -> b as the face runs
    tr.emplace_back(2 * a, 2 * b + 1, -0.5), tr.emplace_back(2 * b + 1, 2 * a, -0.5);
    tr.emplace_back(2 * b, 2 * a + 1, 0.5), tr.emplace_back(2 * a + 1, 2 * b, 0.5);
  }
  return tr;
}

// Whether segments p0 p1 and q0 q1 cross (touching counts).
bool segments_cross(const V2& p0, const V2& p1, const V2& q0, const V2& q1) {
  auto orient = [](const V2& a, const V2& b, const V2& c) {
    const double d = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    return (d > 0) - (d < 0);
  };
  const int o1 = orient(p0, p1, q0), o2 = orient(p0, p1, q1), o3 = orient(q0, q1, p0), o4 = orient(q0, q1, p1);
  if (o1 != o2 && o3 != o4) return true;
  auto on = [](const V2& a, const V2& b, const V2& c) {  // c on segment a b, given collinear
    return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
           c.y() <= std::max(a.y(), b.y());
  };
  return (o1 == 0 && on(p0, p1, q0)) || (o2 == 0 && on(p0, p1, q1)) || (o3 == 0 && on(q0, q1, p0)) ||
         (o4 == 0 && on(q0, q1, p1));
}

// Whether two boundary edges that share no vertex cross: the edges swept in order of their lowest x.
bool boundary_crosses(const Edges& E, const Embedding& emb) {
  std::vector<int> be;
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (E.ef[e][1] < 0) be.push_back(int(e));
  auto lo = [&](int e) { return std::min(emb.pos[std::size_t(E.ev[e][0])].x(), emb.pos[std::size_t(E.ev[e][1])].x()); };
  auto hi = [&](int e) { return std::max(emb.pos[std::size_t(E.ev[e][0])].x(), emb.pos[std::size_t(E.ev[e][1])].x()); };
  std::stable_sort(be.begin(), be.end(), [&](int a, int b) { return lo(a) < lo(b); });
  for (std::size_t i = 0; i < be.size(); ++i) {
    const auto& a = E.ev[std::size_t(be[i])];
    for (std::size_t j = i + 1; j < be.size() && lo(be[j]) <= hi(be[i]); ++j) {
      const auto& b = E.ev[std::size_t(be[j])];
      if (a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]) continue;
      if (segments_cross(emb.pos[std::size_t(a[0])], emb.pos[std::size_t(a[1])], emb.pos[std::size_t(b[0])],
                         emb.pos[std::size_t(b[1])]))
        return true;
    }
  }
  return false;
}

// The share of the band's wall hidden (out of the map, or below min_ratio at the band's area scale)
// and the bounds statistics of the faces in the map.
struct DiskNeed {
  double hidden = 0;
  BoundStats st;
};
DiskNeed disk_need(const SegmentWork& w, const std::vector<char>& degenerate, double min_ratio) {
  const std::vector<FaceDistortion> fd = band_distortion(w, degenerate);
  double a2 = 0, a3 = 0, hidden = 0;
  for (const FaceDistortion& d : fd)
    if (!d.degenerate && !too_small_in_map(d.area2, d.area3)) a2 += d.area2;
  for (const FaceDistortion& d : fd) a3 += d.degenerate ? 0.0 : d.area3;
  const double scale = a2 > 0 ? a3 / a2 : 1.0;
  for (const FaceDistortion& d : fd)
    if (!d.degenerate && (too_small_in_map(d.area2, d.area3) || d.area2 * scale < min_ratio * d.area3)) hidden += d.area3;
  return {a3 > 0 ? hidden / a3 : 0.0, bound_stats_in_map(fd)};
}

// The LSCM map of w.ann scaled to the wall's area, corner offsets 0; false when the solve fails.
bool lscm_embedding(SegmentWork& w, const Edges& E, const std::vector<char>& degenerate, const std::array<int, 2>& pins,
                    bool clamp) {
  std::vector<V2> pos = lscm_positions(w.ann, E, degenerate, pins, clamp);
  if (pos.empty()) return false;
  w.emb = Embedding{std::move(pos), std::vector<std::array<double, 3>>(w.ann.t.size(), {0.0, 0.0, 0.0}), 1.0};
  double a2 = 0;
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) a2 += w.emb.area2(w.ann, int(f));
  if (!(a2 > 0)) return false;
  const double scale = std::sqrt(w.seg.area_3d / a2);
  for (V2& q : w.emb.pos) q *= scale;
  return true;
}

// The map turned so that its long axis (the vertices' principal direction) runs along x, then moved
// to its bounding box from (0, 0): the band's rectangle, x also its "along" (mm).
void place_in_box(SegmentWork& w) {
  V2 mean = V2::Zero();
  for (const V2& q : w.emb.pos) mean += q;
  mean /= double(std::max<std::size_t>(1, w.emb.pos.size()));
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const V2& q : w.emb.pos) cov += (q - mean) * (q - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  const V2 axis = eig.eigenvectors().col(1);  // the largest eigenvalue's
  for (V2& q : w.emb.pos) q = V2(axis.dot(q - mean), axis.x() * (q - mean).y() - axis.y() * (q - mean).x());
  V2 lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const V2& q : w.emb.pos) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  for (V2& q : w.emb.pos) q -= lo;
  const V2 box = hi - lo;
  w.seg.length = box.x();
  w.seg.period = w.emb.period = box.y() * (1 + 1e-9) + 1e-9;  // every face's centroid below it: no wrap
  w.along.resize(w.emb.pos.size());
  for (std::size_t v = 0; v < w.along.size(); ++v) w.along[v] = w.emb.pos[v].x();
}

// The area correction and balance of the disk map (pin held, boundary free): the whole band when its
// ratios are out of bounds or it hides wall, then the local passes, then the balance.
void correct_disk(SegmentWork& w, const std::vector<std::vector<int>>& vf, const std::vector<char>& held,
                  const std::vector<char>& degenerate, const FlattenOptions& o, DiskMapResult& res) {
  const DiskNeed need = disk_need(w, degenerate, o.coverage_min_ratio);
  const bool out = need.st.area_p05 < o.area_ratio_low || need.st.area_p95 > o.area_ratio_high;
  if (out || need.hidden > kHiddenWallTolerance)
    res.corrected_iterations =
        correct_area(w.ann, vf, w.emb, held, degenerate, false, o, false, whole_band_done(w, degenerate, o)).iterations;
  for (bool grow : {false, true}) {
    if (!(disk_need(w, degenerate, o.coverage_min_ratio).hidden > kHiddenWallTolerance)) break;
    const AreaCorrection c = correct_area(w.ann, vf, w.emb, held, degenerate, true, o, grow);
    res.corrected_iterations = std::max(res.corrected_iterations, c.iterations);
  }
  res.balanced_vertices = balance_area(w.ann, vf, w.emb, held, degenerate, o).vertices;
}

// The disk's conformal map (the cotangent LSCM; where it folds faces, the clamped one; folds left
// re-embedded by untangle with the boundary `rim` held); false when the map is not injective then.
bool conformal_disk(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                    const std::vector<char>& degenerate, const std::vector<char>& rim, const std::array<int, 2>& pins) {
  auto folded = [&] {
    std::size_t n = 0;
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) n += !degenerate[f] && w.emb.area2(w.ann, int(f)) < 0;
    return n;
  };
  if (!lscm_embedding(w, E, degenerate, pins, false)) return false;
  std::size_t folds = folded();
  if (folds > 0 && lscm_embedding(w, E, degenerate, pins, true)) folds = folded();
  if (folds > 0) untangle(w.ann, vf, w.emb, rim, degenerate);
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug disk map, %zu faces: %zu folded (clamped), %zu after untangle, boundary crosses %d\n",
                 w.ann.t.size(), folds, folded(), int(boundary_crosses(E, w.emb)));
  return injective_disk_map(w.ann, E, w.emb, degenerate);
}

}  // namespace

std::array<int, 2> far_boundary_pair(const Surface& s, const Edges& E) {
  const std::vector<std::vector<int>> loops = boundary_loops(s, E);
  if (loops.empty() || loops[0].empty()) return {-1, -1};
  auto farthest = [&](int from) {
    int best = from;
    double d = -1;
    for (const auto& l : loops)
      for (int v : l)
        if ((s.p[std::size_t(v)] - s.p[std::size_t(from)]).squaredNorm() > d)
          d = (s.p[std::size_t(v)] - s.p[std::size_t(from)]).squaredNorm(), best = v;
    return best;
  };
  const int a = farthest(loops[0][0]);
  return {a, farthest(a)};
}

std::vector<V2> lscm_positions(const Surface& s, const Edges& E, const std::vector<char>& degenerate,
                               const std::array<int, 2>& pins, bool clamp) {
  const int n = 2 * int(s.p.size());
  std::vector<double> fixed_value(std::size_t(n), 0.0);
  std::vector<int> index(std::size_t(n), 0);
  fixed_value[std::size_t(2 * pins[1])] = (s.p[std::size_t(pins[1])] - s.p[std::size_t(pins[0])]).norm();
  for (int p : pins) index[std::size_t(2 * p)] = index[std::size_t(2 * p + 1)] = -1;
  int m = 0;
  for (int& i : index) i = i < 0 ? -1 : m++;
  std::vector<Eigen::Triplet<double>> free_terms;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m);
  for (const auto& t : conformal_triplets(s, E, degenerate, clamp)) {
    const int r = index[std::size_t(t.row())], c = index[std::size_t(t.col())];
    if (r < 0) continue;
    if (c >= 0) free_terms.emplace_back(r, c, t.value());
    else b[r] -= t.value() * fixed_value[std::size_t(t.col())];
  }
  Eigen::SparseMatrix<double> M(m, m);
  M.setFromTriplets(free_terms.begin(), free_terms.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
  if (ldlt.info() != Eigen::Success) return {};
  const Eigen::VectorXd x = ldlt.solve(b);
  if (ldlt.info() != Eigen::Success || !x.allFinite()) return {};
  std::vector<V2> pos(s.p.size());
  auto value = [&](int k) { return index[std::size_t(k)] < 0 ? fixed_value[std::size_t(k)] : x[index[std::size_t(k)]]; };
  for (std::size_t v = 0; v < s.p.size(); ++v) pos[v] = V2(value(2 * int(v)), value(2 * int(v) + 1));
  return pos;
}

bool injective_disk_map(const Surface& s, const Edges& E, const Embedding& emb, const std::vector<char>& degenerate) {
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && emb.area2(s, int(f)) < 0) return false;
  return !boundary_crosses(E, emb);
}

DiskMapResult disk_band(SegmentWork& w, const Prepared& p, const FlattenOptions& o) {
  const Edges& E = p.E;
  const std::vector<std::vector<int>>& vf = p.vf;
  const std::vector<char>& degenerate = p.degenerate;
  DiskMapResult res;
  const std::array<int, 2> pins = far_boundary_pair(w.ann, E);
  if (pins[0] < 0 || pins[0] == pins[1]) return res.why = "no two boundary vertices", res;
  if (!conformal_disk(w, E, vf, degenerate, p.fixed, pins)) return res.why = "the conformal map overlaps itself", res;
  const Embedding conformal = w.emb;
  std::vector<char> held(w.ann.p.size(), 0);
  held[std::size_t(pins[0])] = 1;
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug disk map, %zu faces: conformal map hides %.4f\n", w.ann.t.size(),
                 disk_need(w, degenerate, o.coverage_min_ratio).hidden);
  if (o.map == "area-balanced") correct_disk(w, vf, held, degenerate, o, res);
  if (!injective_disk_map(w.ann, E, w.emb, degenerate)) w.emb = conformal, res.corrected_iterations = 0, res.balanced_vertices = 0;
  place_in_box(w);
  w.seg.map = "disk";
  w.seg.corrected_iterations = res.corrected_iterations;
  w.seg.balanced_vertices = res.balanced_vertices;
  const V3 a = w.ann.p[std::size_t(pins[0])], b = w.ann.p[std::size_t(pins[1])];
  w.seg.end_a = {a.x(), a.y(), a.z()};
  w.seg.end_b = {b.x(), b.y(), b.z()};
  res.ok = true;
  return res;
}

std::vector<SegmentWork> flatten_disk(const Surface& disk, int component, double lumen_sign, const FlattenOptions& o) {
  SegmentWork w;
  w.lumen_sign = lumen_sign;
  w.branch = true;
  w.seg.component = component;
  w.seg.input_kind = "one open end";
  w.seg.weights = "cotan";
  w.ann = disk;
  Prepared p{build_edges(disk.t), {}, {}, {}};
  prepare_faces(w, p);
  const DiskMapResult r = disk_band(w, p, o);
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG") && !r.ok)
    std::fprintf(stderr, "flatten debug disk map of %zu faces refused: %s\n", disk.t.size(), r.why);
  if (!r.ok) return {};
  w.seg.faces = w.ann.t.size();
  w.seg.vertices = w.ann.p.size();
  measure(w, p.E, p.degenerate, o);
  std::vector<SegmentWork> out;
  out.push_back(std::move(w));
  return out;
}

}  // namespace cf::flat_detail
