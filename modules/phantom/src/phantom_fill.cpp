// Fluids and tubes painted after the colon: tagged-fluid pools (flood fill of the lumen below each
// level), fully tagged stretches, small-bowel loops (oral contrast with gas above a level) and the
// rectal tube (plastic wall, air lumen).
#include <algorithm>
#include <cmath>

#include "phantom_model.h"

namespace cf::phantom_detail {

// Fluid pools: flood fill of the gas below each level (along gravity) from its seed.
void PhantomPainter::fill_pools() {
  const Grid& g = md_.g;
  for (std::size_t pi = 0; pi < md_.pools.size(); ++pi) {
    Pool& pool = md_.pools[pi];
    int c[3];
    for (int d = 0; d < 3; ++d) c[d] = int(std::lround((pool.seed[d] - g.org[d]) / g.sp[d]));
    auto below = [&](int j) { return md_.gravity * (g.org[1] + j * g.sp[1] - pool.level_y) > 0; };
    std::vector<std::size_t> stack;
    // The seed voxel, or the nearest gas voxel below the level around it.
    for (int r = 0; r <= 3 && stack.empty(); ++r)
      for (int dk = -r; dk <= r && stack.empty(); ++dk)
        for (int dj = -r; dj <= r && stack.empty(); ++dj)
          for (int di = -r; di <= r && stack.empty(); ++di) {
            const int i = c[0] + di, j = c[1] + dj, k = c[2] + dk;
            if (i < 0 || j < 0 || k < 0 || i >= g.n[0] || j >= g.n[1] || k >= g.n[2]) continue;
            if (mat_[g.index(i, j, k)] == kColonGas && below(j)) stack.push_back(g.index(i, j, k));
          }
    const unsigned char fl = static_cast<unsigned char>(kFluid0 + pi);
    for (std::size_t q : stack) mat_[q] = fl;
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      ++pool.voxels;
      const int i = int(q % g.n[0]), j = int((q / g.n[0]) % g.n[1]), k = int(q / (std::size_t(g.n[0]) * g.n[1]));
      const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= g.n[0] || n[1] >= g.n[1] || n[2] >= g.n[2]) continue;
        const std::size_t r = g.index(n[0], n[1], n[2]);
        if (mat_[r] != kColonGas || !below(n[1])) continue;
        mat_[r] = fl;
        stack.push_back(r);
      }
    }
  }
}

// Fully tagged stretches: every lumen voxel whose nearest centreline point lies between the necks.
void PhantomPainter::fill_stretches() {
  if (md_.stretches.empty()) return;
  const Grid& g = md_.g;
  for (int k = blo_[2]; k < bhi_[2]; ++k)
    for (int j = blo_[1]; j < bhi_[1]; ++j)
      for (int i = blo_[0]; i < bhi_[0]; ++i) {
        unsigned char& m = mat_[g.index(i, j, k)];
        if (!is_lumen(m)) continue;
        const double s = best_s_[bidx(i, j, k)];
        for (std::size_t t = 0; t < md_.stretches.size(); ++t)
          if (s > md_.stretches[t].s0 && s < md_.stretches[t].s1) {
            m = static_cast<unsigned char>(kFluid0 + md_.pools.size() + t);
            ++md_.stretches[t].voxels;
          }
      }
}

// Small-bowel loops: contrast-filled tubes with a 2 mm wall; gas where the lumen is above the
// loop's gas level (non-dependent side).
void PhantomPainter::paint_small_bowel() {
  const Grid& g = md_.g;
  for (const BowelLoop& loop : md_.bowel) {
    V3 lo = loop.pts.front(), hi = lo;
    for (const V3& p : loop.pts) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, lo[d] - loop.r - 3, hi[d] + loop.r + 3, l[d], h[d]);
    parallel_for(h[2] - l[2], [&](int k0, int k1) {
      for (int k = l[2] + k0; k < l[2] + k1; ++k)
        for (int j = l[1]; j < h[1]; ++j)
          for (int i = l[0]; i < h[0]; ++i) {
            const V3 q = g.point(i, j, k);
            double d2 = 1e18;
            for (std::size_t t = 0; t + 1 < loop.pts.size(); ++t) d2 = std::min(d2, seg_point_dist2(q, loop.pts[t], loop.pts[t + 1]));
            const double d = std::sqrt(d2);
            unsigned char& m = mat_[g.index(i, j, k)];
            if (d <= loop.r) m = md_.gravity * q.y() < loop.gas_level ? kBowelGas : kBowelContrast;
            else if (d <= loop.r + 2 && m == kVisceralFat) m = kBowelWall;
          }
    });
  }
}

// Rectal tube: plastic wall (outer radius 3.5 mm) around an air lumen (2.3 mm), open at its tip.
void PhantomPainter::paint_rectal_tube() {
  const Grid& g = md_.g;
  constexpr double kInner = 2.3;
  for (const Capsule& c : md_.tube) {
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g.range(d, std::min(c.a[d], c.b[d]) - c.r - 1, std::max(c.a[d], c.b[d]) + c.r + 1, l[d], h[d]);
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          double t = 0;
          const double d = std::sqrt(seg_point_dist2(g.point(i, j, k), c.a, c.b, &t));
          if (&c == &md_.tube.back() && t >= 1) continue;  // the open tip
          unsigned char& m = mat_[g.index(i, j, k)];
          if (d <= kInner) m = kTubeAir;
          else if (d <= c.r && m != kTubeAir) m = kTubeWall;
        }
  }
}

}  // namespace cf::phantom_detail
