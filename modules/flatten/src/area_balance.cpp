// Local area balancing of the embedding: the symmetric Dirichlet energy (Smith & Schaefer 2015)
// minimised on the regions whose 2D/3D area ratio is out of bounds, grown until the region has
// room in 2D, its boundary fixed. Directions come from the cotangent Laplacian (the energy's
// quadratic proxy, as in SLIM / AQP, factorised once per region); each step is limited so that no
// face reaches zero area and the energy (infinite for a fold) decreases, so the map stays locally
// injective inside and, with the fixed boundary, bijective.
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

#include "face_blocks.h"
#include "flatten_internal.h"
#include "proxy_descent.h"
#include "symmetric_dirichlet_energy.h"

namespace cf::flat_detail {
namespace {

struct Region {
  std::vector<int> faces;          // faces with a free vertex
  std::vector<char> free_vertex;
};

constexpr double kMaxAnisotropy = 3.0;  // quasi-conformal ratio that also seeds a region

// Quasi-conformal ratio sigma1 / sigma2 of a face's 3D -> 2D map.
double anisotropy(const Surface& s, const Embedding& emb, int f) {
  const Tri& t = s.t[f];
  const auto c = emb.corners(s, f);
  const FaceDistortion d = face_distortion(s.p[t[0]], s.p[t[1]], s.p[t[2]], c[0], c[1], c[2]);
  return std::isfinite(d.qc) ? d.qc : 1e9;
}

double ratio_of(const Surface& s, const Embedding& emb, const std::vector<double>& area3, int f) {
  return area3[f] > 0 ? emb.area2(s, f) / area3[f] : 1.0;
}

// A face seeds the balancing region when its area ratio is out of [lo, hi] or its quasi-conformal
// ratio above kMaxAnisotropy. `faces` (optional): only these faces are tested again, the others keep
// their flag (a face none of whose corners moved has the same ratio and anisotropy to the bit: after
// a pass only the faces with a free vertex of its region moved; on the real CT colon band 0.7 M of 2 M).
void mark_seeds(const Surface& s, const Embedding& emb, const std::vector<double>& area3,
                const std::vector<char>& degenerate, double lo, double hi, const std::vector<int>* faces,
                std::vector<char>& seed) {
  for_each_block(faces ? faces->size() : s.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {  // each face's own test, any thread
      const int f = faces ? (*faces)[i] : int(i);
      const double q = ratio_of(s, emb, area3, f);
      seed[f] = !degenerate[f] && (q < lo || q > hi || anisotropy(s, emb, f) > kMaxAnisotropy);
    }
  });
}

// The region: the seeds (mark_seeds()) grown by vertex rings (2, 4, 8, ... 64) until the region's
// 2D area is within [0.6, 1.6] x its 3D area, or it holds half of the faces. Its faces are listed by
// index, not in the order they were reached: a pass whose seeds differ from the last pass's but grow
// into the same faces gets the same list, and reuses the last pass's system (the real CT colon band:
// 704 434 faces both times, factorised twice when listed as grown, issue 26 session 32).
Region select_region(const Surface& s, const std::vector<std::vector<int>>& vf, const Embedding& emb,
                     const std::vector<double>& area3, const std::vector<char>& fixed, const std::vector<char>& seed) {
  Region r;
  std::vector<char> in = seed;
  std::vector<int> faces;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (in[f]) faces.push_back(int(f));
  if (faces.empty()) return r;
  std::size_t done = 0;
  for (int rings = 2; rings <= 64; rings *= 2) {
    for (int k = 0; k < rings / 2 + (rings == 2); ++k) {
      const std::size_t n0 = faces.size();
      for (std::size_t i = done; i < n0; ++i)
        for (int v : s.t[faces[i]])
          for (int g : vf[v])
            if (!in[g]) in[g] = 1, faces.push_back(g);
      done = n0;
    }
    double a2 = 0, a3 = 0;
    for (int f : faces) a2 += emb.area2(s, f), a3 += area3[f];
    if ((a2 >= 0.6 * a3 && a2 <= 1.6 * a3) || faces.size() * 2 > s.t.size()) break;
  }
  r.free_vertex.assign(s.p.size(), 0);
  for (int f : faces)
    for (int v : s.t[f]) r.free_vertex[v] = !fixed[v];
  for (std::size_t v = 0; v < s.p.size(); ++v)  // vertices on the region's rim stay fixed
    if (r.free_vertex[v])
      for (int g : vf[v])
        if (!in[g]) r.free_vertex[v] = 0;
  for (int f : faces)
    for (int v : s.t[f])
      if (r.free_vertex[v]) {
        r.faces.push_back(f);
        break;
      }
  std::sort(r.faces.begin(), r.faces.end());
  return r;
}

// What the balancing exists to lower, measured on the region's faces (3D-area weighted sums):
// `out_of_bounds`, per face (log of how far its area ratio lies outside [lo, hi] + log of how far
// its quasi-conformal ratio lies above kMaxAnisotropy)^2, zero exactly for a face that would not
// seed a region; `angle`, per face its quasi-conformal ratio - 1 (the angle distortion the
// symmetric Dirichlet energy also lowers, reported as the qc mean).
struct BalanceMeasure {
  double out_of_bounds = 0, angle = 0;
};
BalanceMeasure measure_region(const Surface& s, const Embedding& emb, const std::vector<int>& faces,
                              const std::vector<double>& area3, double lo, double hi) {
  const std::size_t nb = face_blocks(faces.size());
  std::vector<BalanceMeasure> part(nb);
  for_each_block(faces.size(), [&](std::size_t begin, std::size_t end) {
    BalanceMeasure& m = part[begin / kFaceBlock];
    for (std::size_t i = begin; i < end; ++i) {
      const int f = faces[i];
      const double q = std::max(ratio_of(s, emb, area3, f), 1e-300), qc = anisotropy(s, emb, f);
      const double e = std::max({0.0, std::log(lo / q), std::log(q / hi)}) + std::max(0.0, std::log(qc / kMaxAnisotropy));
      m.out_of_bounds += area3[f] * e * e;
      m.angle += area3[f] * (qc - 1);
    }
  });
  BalanceMeasure sum;  // block order: the same for any thread count
  for (const BalanceMeasure& m : part) sum.out_of_bounds += m.out_of_bounds, sum.angle += m.angle;
  return sum;
}

// A step that lowers the region's out-of-bounds measure by less than kMinOutOfBoundsGain and its
// angle measure by less than kMinAngleGain (relative) ends the descent. The out-of-bounds measure
// is a sum of squared log distances to the bounds, so 1 % of it is ~0.5 % of the out-of-bounds
// faces' (rms) log distance: a face at area ratio 0.2 moves by less than 0.001 towards 0.4. At
// 0.1 % per step of the angle measure the whole step budget (30) lowers the region's mean qc - 1 by
// less than 3 %, where the early steps lower it by several percent each. The symmetric Dirichlet
// energy keeps falling (by more than its 1e-4 convergence gain) long after both: on the real CT
// colon band 54 steps on 695 k faces changed no reported statistic (qc mean 1.739, area p05 0.2713
// before and after).
constexpr double kMinOutOfBoundsGain = 0.01, kMinAngleGain = 0.001;

// Minimises the symmetric Dirichlet energy on one region (proxy_descent.h: the cotangent
// Laplacian of the 3D triangles as the energy's quadratic proxy, fold-free Armijo steps), until
// the energy converges or a step no longer lowers measure_region() (kMinOutOfBoundsGain, kMinAngleGain).
int minimise_region(const Surface& s, Embedding& emb, const Region& r, const RegionSystem& sys, int iterations,
                    const std::vector<double>& area3, double lo, double hi) {
  std::vector<int> unfolded;  // folded faces (left by untangle) are not judged
  for (int f : r.faces)
    if (emb.area2(s, f) > 0) unfolded.push_back(f);
  const SymmetricDirichlet sd = make_energy(s, emb, unfolded);
  auto settled = [&, last = measure_region(s, emb, unfolded, area3, lo, hi)]() mutable {
    const BalanceMeasure now = measure_region(s, emb, unfolded, area3, lo, hi);
    const bool done = !(now.out_of_bounds < (1 - kMinOutOfBoundsGain) * last.out_of_bounds) &&
                      !(now.angle < (1 - kMinAngleGain) * last.angle);
    last = now;
    return done;
  };
  return proxy_descent(s, emb, sd, sys, unfolded, area3, iterations, 1e-4, settled).steps;
}

}  // namespace

std::vector<std::array<double, 3>> corner_weights(const Surface& s, const std::vector<int>& faces) {
  std::vector<std::array<double, 3>> w(faces.size());
  for_each_block(faces.size(), [&](std::size_t begin, std::size_t end) {  // each face its own weights
    for (std::size_t i = begin; i < end; ++i) {
      const Tri& t = s.t[faces[i]];
      for (int k = 0; k < 3; ++k) {
        const V3 e1 = s.p[t[(k + 1) % 3]] - s.p[t[k]], e2 = s.p[t[(k + 2) % 3]] - s.p[t[k]];
        w[i][k] = std::clamp(0.5 * e1.dot(e2) / std::max(e1.cross(e2).norm(), 1e-12), 0.01, 100.0);
      }
    }
  });
  return w;
}

namespace {

double cross2(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

// A face's area a0 + B t + C t^2 over t in [0, 1] is at least a0 + min(B, 0) + min(C, 0); when that
// bound exceeds this fraction of |a0| + |B| + |C| (far above the rounding of its three terms) the
// face keeps a positive area up to t = 1 and its roots are not computed (issue 26, session 36
// "wholeband": most faces of a step, ~15 % of the grown CT mask row's CPU in these limits).
constexpr double kClearOfRounding = 1e-12;

// face_step_limit() of a face with edges e1, e2 (corner 0 to corners 1 and 2), A = cross2(e1, e2) > 0
// and moves g1, g2 of corners 1 and 2 relative to corner 0.
double step_limit(const V2& e1, const V2& e2, double A, const V2& g1, const V2& g2, double keep) {
  const double B = cross2(e1, g2) + cross2(g1, e2), C = cross2(g1, g2);
  // smallest t > 0 with C t^2 + B t + (1 - keep) A = 0 (twice the areas)
  const double a0 = (1 - std::clamp(keep, 0.0, 1.0)) * A;
  const double low = a0 + std::min(B, 0.0) + std::min(C, 0.0);
  if (low > kClearOfRounding * (std::abs(a0) + std::abs(B) + std::abs(C))) return 1e300;  // no root in (0, 1]
  double root = 1e300;
  if (std::abs(C) < 1e-300) {
    if (B < 0) root = -a0 / B;
  } else {
    const double disc = B * B - 4 * a0 * C;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      for (double r : {(-B - sq) / (2 * C), (-B + sq) / (2 * C)})
        if (r > 0) root = std::min(root, r);
    }
  }
  return root;
}

// The moves of corners 1 and 2 of face t relative to corner 0.
std::array<V2, 2> relative_moves(const Tri& t, const Embedding& emb, const std::vector<V2>& next) {
  const V2 m0 = next[t[0]] - emb.pos[t[0]];
  return {V2((next[t[1]] - emb.pos[t[1]]) - m0), V2((next[t[2]] - emb.pos[t[2]]) - m0)};
}

}  // namespace

double face_step_limit(const Surface& s, const Embedding& emb, const std::vector<V2>& next, int f, double keep) {
  const auto c = emb.corners(s, f);
  const V2 e1 = c[1] - c[0], e2 = c[2] - c[0];
  const double A = cross2(e1, e2);
  if (A <= 0) return 1e300;  // degenerate or already folded: not judged
  const auto g = relative_moves(s.t[f], emb, next);
  return step_limit(e1, e2, A, g[0], g[1], keep);
}

// Largest t in (0, 1] such that along pos + t (next - pos) every face keeps at least
// min(half its current area, `floor_ratio` x its 3D area): no face can collapse (a barrier in
// place of the one ARAP lacks), and none that is readable now can become unreadable. Each face's
// corners are read once (its 2D area, 0.5 A, is emb.area2()'s value to the bit).
double max_area_step(const Surface& s, const Embedding& emb, const std::vector<V2>& next, const std::vector<int>& faces,
                     const std::vector<double>& area3, double floor_ratio) {
  const double tmax = block_min(faces.size(), 1.0, [&](std::size_t begin, std::size_t end) {
    double t = 1.0;
    for (std::size_t i = begin; i < end; ++i) {
      const int f = faces[i];
      const auto c = emb.corners(s, f);
      const V2 e1 = c[1] - c[0], e2 = c[2] - c[0];
      const double A = cross2(e1, e2), a = 0.5 * A;
      if (a <= 0) continue;
      const auto g = relative_moves(s.t[f], emb, next);
      const double keep = floor_ratio > 0 ? std::min(0.5, floor_ratio * area3[f] / a) : 0.0;  // (the descents' 0)
      t = std::min(t, step_limit(e1, e2, A, g[0], g[1], keep));
    }
    return t;
  });
  return std::max(0.0, tmax);
}

BalanceResult balance_area(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                           const std::vector<char>& fixed, const std::vector<char>& degenerate,
                           const FlattenOptions& o, const std::vector<int>* vertex_order) {
  BalanceResult res;
  std::vector<double> area3(s.t.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) area3[f] = face_area_3d(s, int(f));
  std::vector<char> moved(s.p.size(), 0);
  Region built;  // the region whose system `sys` is
  RegionSystem sys;
  bool usable = false;
  std::vector<char> seed(s.t.size(), 0);
  mark_seeds(s, emb, area3, degenerate, o.area_ratio_low, o.area_ratio_high, nullptr, seed);
  for (int pass = 0; pass < 2; ++pass) {
    if (pass > 0) mark_seeds(s, emb, area3, degenerate, o.area_ratio_low, o.area_ratio_high, &built.faces, seed);
    Region r = select_region(s, vf, emb, area3, fixed, seed);
    if (r.faces.empty()) break;
    // The system depends only on the region (its faces, free vertices, the 3D weights and the
    // order): the second pass's region is often the first's (the real CT colon band: 740 905 faces
    // both times), and then its factorisation is the same bits.
    if (pass == 0 || r.faces != built.faces || r.free_vertex != built.free_vertex) {
      usable = sys.build(s, r.free_vertex, r.faces, corner_weights(s, r.faces), vertex_order);
      built = std::move(r);
      ++res.systems_built;
    }
    const Region& region = built;
    if (usable)
      res.iterations += std::size_t(minimise_region(s, emb, region, sys, o.balance_iterations, area3, o.area_ratio_low, o.area_ratio_high));
    res.faces = std::max(res.faces, region.faces.size());
    for (std::size_t v = 0; v < s.p.size(); ++v) moved[v] = moved[v] || region.free_vertex[v];
  }
  res.vertices = std::size_t(std::count(moved.begin(), moved.end(), 1));
  return res;
}

}  // namespace cf::flat_detail
