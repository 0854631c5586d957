#include "branch_order.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cf {
namespace {

constexpr size_t kMaxGroup = 6;  // 6! * 2^6 = 46 080 tours; larger groups keep their order

// The band's centre point at its own mm `mm` (clamped to the band).
Eigen::Vector3d band_point(const ColonPiece& band, double mm) {
  const double k = std::floor(mm / std::max(band.bin_mm, 1e-9));
  return band.centre[size_t(std::clamp(k, 0.0, double(band.centre.size() - 1)))];
}

// First and last centre point of a branch run in the direction `flip` gives (relative to flipped).
Eigen::Vector3d run_start(const ColonPiece& b, bool flip) { return (b.flipped != flip) ? b.centre.back() : b.centre.front(); }
Eigen::Vector3d run_end(const ColonPiece& b, bool flip) { return (b.flipped != flip) ? b.centre.front() : b.centre.back(); }

// Length of the tour enter -> each branch of `order` end to end (bit i of `flips` turns branch i) -> exit.
double tour_mm(const std::vector<ColonPiece*>& group, const std::vector<size_t>& order, unsigned flips,
               const Eigen::Vector3d& enter, const Eigen::Vector3d& exit) {
  double mm = 0;
  Eigen::Vector3d at = enter;
  for (size_t i : order) {
    const bool flip = (flips >> i) & 1u;
    mm += (run_start(*group[i], flip) - at).norm();
    at = run_end(*group[i], flip);
  }
  return mm + (exit - at).norm();
}

// Orders and orients one group of branches hanging at one neck of `band` (sorted by neck, then id).
void order_group(const ColonPiece& band, std::vector<ColonPiece*>& group, double same_neck_mm) {
  const Eigen::Vector3d enter = band_point(band, group.front()->attach_mm - 0.5 * same_neck_mm);
  const Eigen::Vector3d exit = band_point(band, group.back()->attach_mm + 0.5 * same_neck_mm);
  std::vector<size_t> order(group.size()), best_order;
  std::iota(order.begin(), order.end(), size_t(0));
  double best = INFINITY;
  unsigned best_flips = 0;
  do {
    for (unsigned flips = 0; flips < (1u << group.size()); ++flips)
      if (const double mm = tour_mm(group, order, flips, enter, exit); mm < best - 1e-6)
        best = mm, best_order = order, best_flips = flips;
  } while (std::next_permutation(order.begin(), order.end()));
  const double neck = group.front()->attach_mm;
  for (size_t rank = 0; rank < best_order.size(); ++rank) {
    ColonPiece& b = *group[best_order[rank]];
    b.flipped = b.flipped != bool((best_flips >> best_order[rank]) & 1u);
    b.neck_rank = int(rank), b.attach_mm = neck;
  }
}

}  // namespace

void order_branches_at_necks(std::vector<ColonPiece>& pieces, double same_neck_mm) {
  for (const ColonPiece& band : pieces) {
    if (band.branch || band.centre.empty()) continue;
    std::vector<ColonPiece*> hanging;
    for (ColonPiece& b : pieces)
      if (b.branch && b.on_band && b.parent == band.segment && !b.centre.empty()) hanging.push_back(&b);
    std::sort(hanging.begin(), hanging.end(), [](const ColonPiece* x, const ColonPiece* y) {
      return std::make_pair(x->attach_mm, x->segment) < std::make_pair(y->attach_mm, y->segment);
    });
    for (size_t i = 0; i < hanging.size();) {
      size_t j = i + 1;
      while (j < hanging.size() && hanging[j]->attach_mm - hanging[j - 1]->attach_mm <= same_neck_mm) ++j;
      std::vector<ColonPiece*> group(hanging.begin() + long(i), hanging.begin() + long(j));
      if (group.size() >= 2 && group.size() <= kMaxGroup) order_group(band, group, same_neck_mm);
      i = j;
    }
  }
}

}  // namespace cf
