// Painting of the placed phantom into a label volume: other gas, bladder and aorta, the colon
// (nearest centreline point per voxel, folds, bulges, collapsed necks), polyps, strands, fold holes,
// tagged-fluid pools (flood fill below each level), fully tagged stretches, small-bowel loops and
// the rectal tube.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phantom_model.h"

namespace cf::phantom_detail {

void PhantomPainter::run() {
  paint_other_gas();
  paint_vessels_and_bladder();
  nearest_centreline();
  paint_colon();
  paint_polyps();
  paint_capsules(md_.strands, kColonWall);
  paint_holes();
  fill_pools();
  fill_stretches();
  paint_small_bowel();
  paint_rectal_tube();
}

// Other gas bubbles (ellipsoids) with a 3 mm wall in the fat around them.
void PhantomPainter::paint_other_gas() {
  const Grid& g = md_.g;
  for (const auto& [c, r] : md_.gas) {
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) g.range(d, c[d] - r[d] - 3, c[d] + r[d] + 3, lo[d], hi[d]);
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const double e = (g.point(i, j, k) - c).cwiseQuotient(r).norm();
          unsigned char& m = mat_[g.index(i, j, k)];
          if (e <= 1) m = kOtherGas;
          else if (e <= 1 + 3.0 / r.minCoeff() && m == kVisceralFat) m = kColonWall;
        }
  }
}

// Bladder: 3 mm wall, excreted contrast in the dependent third, urine above; aorta: enhanced blood.
void PhantomPainter::paint_vessels_and_bladder() {
  const Grid& g = md_.g;
  if (md_.bladder) {
    const V3 c = md_.bladder_c, r = md_.bladder_r;
    const double level = c.y() + md_.gravity * 0.35 * r.y();  // contrast below this (along gravity)
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) g.range(d, c[d] - r[d] - 3, c[d] + r[d] + 3, lo[d], hi[d]);
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const V3 q = g.point(i, j, k);
          const double e = (q - c).cwiseQuotient(r).norm();
          unsigned char& m = mat_[g.index(i, j, k)];
          if (e <= 1) m = md_.gravity * (q.y() - level) > 0 ? kBladderContrast : kUrine;
          else if (e <= 1 + 3.0 / r.minCoeff() && m == kVisceralFat) m = kBladderWall;
        }
  }
  if (md_.aorta) {
    const Capsule& a = md_.aorta_seg;
    int lo[3], hi[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(a.a[d], a.b[d]) - a.r - 2, std::max(a.a[d], a.b[d]) + a.r + 2, lo[d], hi[d]);
    for (int k = lo[2]; k < hi[2]; ++k)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int i = lo[0]; i < hi[0]; ++i) {
          const double d = std::sqrt(seg_point_dist2(g.point(i, j, k), a.a, a.b));
          unsigned char& m = mat_[g.index(i, j, k)];
          if (d <= a.r) m = kAorta;
          else if (d <= a.r + 1.5 && m == kVisceralFat) m = kMuscle;
        }
  }
}

// For every voxel of the colon's box: arc length s of the nearest centreline point within reach.
void PhantomPainter::nearest_centreline() {
  const Grid& g = md_.g;
  const Path& P = md_.path;
  const std::size_t np = P.p.size();
  double rmax = 0;
  for (double r : P.r) rmax = std::max(rmax, r);
  for (const Bulge& b : md_.bulges) rmax = std::max(rmax, 30 + b.amp);
  const double reach = rmax + md_.wall + 2;
  V3 lo_mm = P.p[0], hi_mm = P.p[0];
  for (const V3& p : P.p) {
    lo_mm = lo_mm.cwiseMin(p);
    hi_mm = hi_mm.cwiseMax(p);
  }
  for (int d = 0; d < 3; ++d) g.range(d, lo_mm[d] - reach, hi_mm[d] + reach, blo_[d], bhi_[d]);
  for (int d = 0; d < 3; ++d) bn_[d] = bhi_[d] - blo_[d];
  const std::size_t bvox = std::size_t(bn_[0]) * bn_[1] * bn_[2];
  std::vector<float> best_d2(bvox, std::numeric_limits<float>::infinity());
  best_s_.assign(bvox, -1.f);
  std::vector<double> seg_reach(np);  // per path point: radius of influence
  for (std::size_t i = 0; i < np; ++i) {
    double r = P.r[i];
    for (const Bulge& b : md_.bulges)
      if (std::abs(P.s[i] - b.s) < 4 * b.sigma_s) r += b.amp;
    seg_reach[i] = r + md_.wall + 2;
  }
  parallel_for(bn_[2], [&](int k0, int k1) {
    const double z0 = g.org[2] + (blo_[2] + k0) * g.sp[2], z1 = g.org[2] + (blo_[2] + k1 - 1) * g.sp[2];
    for (std::size_t i = 0; i + 1 < np; ++i) {
      const V3 &a = P.p[i], &b = P.p[i + 1];
      const double rr = std::max(seg_reach[i], seg_reach[i + 1]);
      if (std::min(a.z(), b.z()) - rr > z1 || std::max(a.z(), b.z()) + rr < z0) continue;
      int lo[3], hi[3];
      for (int d = 0; d < 3; ++d) g.range(d, std::min(a[d], b[d]) - rr, std::max(a[d], b[d]) + rr, lo[d], hi[d]);
      lo[2] = std::max(lo[2], blo_[2] + k0);
      hi[2] = std::min(hi[2], blo_[2] + k1);
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
              best_s_[q] = float(P.s[i] + t * (P.s[i + 1] - P.s[i]));
            }
          }
    }
  });
}

// Geometry at a voxel of the colon box: nearest centreline point, radius, angle.
bool PhantomPainter::local_at(int ii, int j, int k, Local& L) const {
  const Path& P = md_.path;
  if (ii < blo_[0] || j < blo_[1] || k < blo_[2] || ii >= bhi_[0] || j >= bhi_[1] || k >= bhi_[2]) return false;
  const std::size_t q = bidx(ii, j, k);
  if (best_s_[q] < 0) return false;
  L.s = best_s_[q];
  L.i = std::min(P.p.size() - 2, std::size_t(L.s / 1.0));
  const double t = std::clamp(L.s - P.s[L.i], 0.0, 1.0);
  const V3 c = P.p[L.i] + t * (P.p[L.i + 1] - P.p[L.i]);
  const V3 v = md_.g.point(ii, j, k) - c;
  L.d = v.norm();
  L.u = L.d > 1e-9 ? V3(v / L.d) : P.N[L.i];
  const V3 N = (P.N[L.i] * (1 - t) + P.N[L.i + 1] * t);
  const V3 B = (P.B[L.i] * (1 - t) + P.B[L.i + 1] * t);
  L.theta = std::atan2(v.dot(B), v.dot(N));
  L.R = radius_at(md_, L.i, t);
  L.Reff = lumen_radius(md_, L.s, L.R, L.theta, L.u);
  // A collapsing colon's wall does not vanish: its cross-section area pi (2 ro w + w^2) (open radius
  // ro, wall w) stays around the narrowed lumen R, so a fully collapsed neck is a soft-tissue cord of
  // radius sqrt(2 ro w + w^2) (walls apposed), not a w-thin cord in fat. Where R = ro: R + w, as before.
  const double ro = open_radius_at(md_, L.i, t), w = md_.wall;
  L.outer = std::max(L.Reff, L.R) + w;
  if (L.R < ro) L.outer = std::max(L.outer, std::sqrt(L.R * L.R + 2 * ro * w + w * w));
  return true;
}

void PhantomPainter::paint_colon() {
  const Grid& g = md_.g;
  parallel_for(bn_[2], [&](int k0, int k1) {
    Local L;
    for (int k = blo_[2] + k0; k < blo_[2] + k1; ++k)
      for (int j = blo_[1]; j < bhi_[1]; ++j)
        for (int ii = blo_[0]; ii < bhi_[0]; ++ii) {
          if (!local_at(ii, j, k, L)) continue;
          unsigned char& m = mat_[g.index(ii, j, k)];
          if (m == kOutsideAir || m == kSubcutFat) continue;
          if (L.d < L.Reff) m = kColonGas;
          else if (L.d < L.outer) m = kColonWall;
        }
  });
}

// Polyps (tissue) inside the lumen: a sphere (head) and for pedunculated ones a stalk.
void PhantomPainter::paint_polyps() {
  const Grid& g = md_.g;
  for (const Polyp& p : md_.polyps) {
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
          unsigned char& m = mat_[g.index(i, j, k)];
          if (in && is_lumen(m)) m = kPolyp;
        }
  }
}

// Lumen voxels within a capsule become `to` (tissue strands across the lumen).
void PhantomPainter::paint_capsules(const std::vector<Capsule>& caps, unsigned char to) {
  const Grid& g = md_.g;
  for (const Capsule& st : caps) {
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(st.a[d], st.b[d]) - st.r - 1, std::max(st.a[d], st.b[d]) + st.r + 1, l[d], h[d]);
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          unsigned char& m = mat_[g.index(i, j, k)];
          if (is_lumen(m) && seg_point_dist2(g.point(i, j, k), st.a, st.b) <= st.r * st.r) m = to;
        }
  }
}

// Holes through fold ridges: wall voxels inside the nominal radius within the hole become gas.
void PhantomPainter::paint_holes() {
  const Grid& g = md_.g;
  for (const Capsule& ho : md_.holes) {
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(ho.a[d], ho.b[d]) - ho.r - 1, std::max(ho.a[d], ho.b[d]) + ho.r + 1, l[d], h[d]);
    Local L;
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          unsigned char& m = mat_[g.index(i, j, k)];
          if (m != kColonWall || !local_at(i, j, k, L) || L.d >= L.R) continue;  // only the fold ridge
          if (seg_point_dist2(g.point(i, j, k), ho.a, ho.b) <= ho.r * ho.r) m = kColonGas;
        }
  }
}

}  // namespace cf::phantom_detail
