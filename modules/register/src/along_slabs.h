#pragma once
// Exact nearest point of a point set for queries far along its first coordinate from every point.
//
// The registration finds, for every vertex of one scan, the nearest vertex of the other in the
// cylinder embedding (s, R cos theta, R sin theta). Where the other scan has no wall (a stretch
// left out of its segmentation, or the part of one colon beyond the other's end) the query lies
// up to hundreds of mm along s from every point. A bucket locator searches outward shell by
// shell, and each shell costs the cube of its level: with buckets of a few mm this took 70 s for
// the 1.5 m pair with 25 % dropped (docs/register.md, "Benchmark"). Here the points are sorted
// into slabs along s and searched outward slab by slab, stopping when the nearest possible point
// of the next slab is farther than the best found: empty slabs cost one comparison each.
#include <vector>

#include <Eigen/Core>

namespace cf {

class AlongSlabs {
 public:
  AlongSlabs(const std::vector<Eigen::Vector3d>& points, double slab_mm);
  // mm along s from s to the nearest slab holding a point (0 when s's own slab holds one).
  double gap_mm(double s) const;
  // Index of the point nearest to q (Euclidean, exact; -1 when there are no points).
  int nearest(const Eigen::Vector3d& q) const;

 private:
  int slab_of(double s) const;
  double s0_ = 0, slab_mm_ = 1;
  int slabs_ = 0;
  std::vector<int> start_;          // points of slab k: order_[start_[k] .. start_[k + 1])
  std::vector<int> order_;          // point indices sorted by slab
  std::vector<double> gap_;         // per slab: mm along to the nearest non-empty slab
  const std::vector<Eigen::Vector3d>& points_;
};

}  // namespace cf
