#include "along_slabs.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf {

AlongSlabs::AlongSlabs(const std::vector<Eigen::Vector3d>& points, double slab_mm)
    : slab_mm_(slab_mm), points_(points) {
  if (points.empty()) return;
  double lo = points[0].x(), hi = lo;
  for (const auto& p : points) lo = std::min(lo, p.x()), hi = std::max(hi, p.x());
  s0_ = lo;
  const int slabs = int(std::floor((hi - lo) / slab_mm_)) + 1;
  slabs_ = slabs;
  std::vector<int> count(size_t(slabs) + 1, 0);
  for (const auto& p : points) ++count[size_t(slab_of(p.x())) + 1];
  for (size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
  start_ = count;
  order_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) order_[size_t(count[size_t(slab_of(points[i].x()))]++)] = int(i);
  // Distance along to the nearest non-empty slab, two sweeps.
  const double inf = std::numeric_limits<double>::infinity();
  gap_.assign(size_t(slabs), inf);
  double last = inf;
  for (int k = 0; k < slabs; ++k) gap_[size_t(k)] = last = start_[size_t(k) + 1] > start_[size_t(k)] ? 0 : last + slab_mm_;
  last = inf;
  for (int k = slabs - 1; k >= 0; --k) {
    last = start_[size_t(k) + 1] > start_[size_t(k)] ? 0 : last + slab_mm_;
    gap_[size_t(k)] = std::min(gap_[size_t(k)], last);
  }
}

int AlongSlabs::slab_of(double s) const {
  return std::clamp(int(std::floor((s - s0_) / slab_mm_)), 0, std::max(0, slabs_ - 1));
}

double AlongSlabs::gap_mm(double s) const {
  if (gap_.empty()) return std::numeric_limits<double>::infinity();
  const int k = slab_of(s);
  const double outside = std::max({0.0, s0_ - s, s - (s0_ + double(gap_.size()) * slab_mm_)});
  return gap_[size_t(k)] + outside;
}

int AlongSlabs::nearest(const Eigen::Vector3d& q) const {
  if (order_.empty()) return -1;
  const int slabs = int(gap_.size()), home = slab_of(q.x());
  double best = std::numeric_limits<double>::infinity();
  int found = -1;
  auto bound = [&](int k) {  // smallest |s - q.s| of a point in slab k
    const double lo = s0_ + k * slab_mm_;
    return std::max({0.0, lo - q.x(), q.x() - (lo + slab_mm_)});
  };
  auto scan = [&](int k) {
    for (int i = start_[size_t(k)]; i < start_[size_t(k) + 1]; ++i) {
      const double d = (points_[size_t(order_[size_t(i)])] - q).squaredNorm();
      if (d < best) best = d, found = order_[size_t(i)];
    }
  };
  scan(home);
  for (int step = 1;; ++step) {
    const int below = home - step, above = home + step;
    const bool go_below = below >= 0 && std::pow(bound(below), 2) < best;
    const bool go_above = above < slabs && std::pow(bound(above), 2) < best;
    if (!go_below && !go_above) break;
    if (go_below) scan(below);
    if (go_above) scan(above);
  }
  return found;
}

}  // namespace cf
