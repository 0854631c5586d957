// Fluid bodies split at narrow necks (docs/segment.md step 4): bowel loops pressed together merge
// in the bright mask across their walls (the 3 x 3 x 3 mean bridges a wall of a voxel or two), so
// one bright component can hold colon fluid, small bowel with oral contrast and bone. A ball of
// kCoreRadiusMm fits inside every lumen that holds tagged fluid but not through such a bridge: the
// bright voxels where the ball fits (the cores) are labelled, and every bright voxel joins the core
// nearest along paths inside the bright mask (a geodesic Voronoi partition), so each piece is one
// lumen. Bright components without a core (thin layers) keep their own label.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr double kCoreRadiusMm = 3.0;
constexpr double kMinCoreVoxels = 1.5;  // the ball must span this many voxels along every axis
}

// Erosion of `m` (0/1) by the ball of radius r_mm (an ellipsoid in voxels): voxels outside the
// volume count as set. The box inside the ball (half-width r / sqrt 3) gives the voxels that may
// pass, the box around it those that pass for sure; only the shell between is checked voxel by voxel.
Bytes erode_ball(const Bytes& m, const Dims& d, double r_mm) {
  int rin[3], rout[3];
  for (int a = 0; a < 3; ++a) {
    rout[a] = int(std::floor(r_mm / d.sp[a] + 1e-9));
    rin[a] = int(std::floor(r_mm / std::sqrt(3.0) / d.sp[a] + 1e-9));
  }
  Bytes sure = m, maybe = m;
  erode_box(sure, d, rout);
  erode_box(maybe, d, rin);
  std::vector<std::array<int, 3>> ball;
  for (int k = -rout[2]; k <= rout[2]; ++k)
    for (int j = -rout[1]; j <= rout[1]; ++j)
      for (int i = -rout[0]; i <= rout[0]; ++i) {
        const double x = i * d.sp[0], y = j * d.sp[1], z = k * d.sp[2];
        if (x * x + y * y + z * z <= r_mm * r_mm + 1e-9) ball.push_back({i, j, k});
      }
  parallel_for(d.n[2], [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k)
      for (std::size_t j = 0; j < d.n[1]; ++j)
        for (std::size_t i = 0; i < d.n[0]; ++i) {
          const std::size_t q = d.idx(i, j, k);
          if (!maybe[q] || sure[q]) continue;
          bool all = true;
          for (std::size_t t = 0; t < ball.size() && all; ++t) {
            const long x = long(i) + ball[t][0], y = long(j) + ball[t][1], z = long(k) + ball[t][2];
            if (x < 0 || y < 0 || z < 0 || x >= long(d.n[0]) || y >= long(d.n[1]) || z >= long(d.n[2])) continue;
            all = m[d.idx(std::size_t(x), std::size_t(y), std::size_t(z))] != 0;
          }
          sure[q] = all;
        }
  });
  return sure;
}

// fluid_label_: the pieces of the bright mask (cores grown along paths inside the mask, then the
// coreless components); fluid_count_ their number.
void ColonSegmenter::split_fluid_bodies(const Bytes& bright) {
  fluid_label_.assign(d_.total, 0);
  std::vector<std::size_t> queue;
  // Voxels coarser than the ball can resolve (radius < 1.5 voxels: the 3 x 3 x 3 mean alone spreads
  // a voxel): no cores, every bright component is one piece.
  const bool resolved = kCoreRadiusMm >= kMinCoreVoxels * std::max({d_.sp[0], d_.sp[1], d_.sp[2]});
  if (resolved) {
    const Bytes core = erode_ball(bright, d_, kCoreRadiusMm);
    const RunLabels cl = component_runs(core.data(), d_);
    fluid_count_ = cl.count();
    for (std::uint32_t l = 1; l <= fluid_count_; ++l)
      for (const Run* r = cl.begin(l); r != cl.end(l); ++r) {
        std::fill_n(fluid_label_.data() + r->start, r->length, l);
        for (std::size_t q = r->start; q < r->start + r->length; ++q) queue.push_back(q);
      }
  } else {
    fluid_count_ = 0;
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {  // breadth-first: the nearest core along the mask
    const std::size_t q = queue[head];
    for_face_neighbours(d_, q, [&](std::size_t r) {
      if (!bright[r] || fluid_label_[r]) return;
      fluid_label_[r] = fluid_label_[q];
      queue.push_back(r);
    });
  }
  std::vector<std::size_t>().swap(queue);
  Bytes rest(d_.total);
  for (std::size_t q = 0; q < d_.total; ++q) rest[q] = bright[q] && !fluid_label_[q];
  const RunLabels thin = component_runs(rest.data(), d_);
  for (std::uint32_t l = 1; l <= thin.count(); ++l)
    for (const Run* r = thin.begin(l); r != thin.end(l); ++r) std::fill_n(fluid_label_.data() + r->start, r->length, fluid_count_ + l);
  fluid_count_ += thin.count();
}

}  // namespace cf::segment_detail
