#pragma once
// A min-heap of (key, id) pairs with four children per node: half the depth of a binary heap,
// and the four children of a node share one cache line, so a pop (the hot step of Dijkstra's
// searches) moves fewer entries through fewer cache lines. Pairs are ordered as std::pair
// (key first, then id), so the pop order is fully determined by the contents.
#include <cstddef>
#include <utility>
#include <vector>

namespace cf {

class QuadHeap {
 public:
  using Item = std::pair<double, int>;
  bool empty() const { return items_.empty(); }
  std::size_t size() const { return items_.size(); }
  const Item& top() const { return items_.front(); }  // precondition: !empty()
  void clear() { items_.clear(); }
  void push(double key, int id) {
    std::size_t i = items_.size();
    items_.emplace_back(key, id);
    const Item x = items_[i];
    while (i > 0) {
      const std::size_t parent = (i - 1) / 4;
      if (!(x < items_[parent])) break;
      items_[i] = items_[parent];
      i = parent;
    }
    items_[i] = x;
  }
  void pop() {  // precondition: !empty()
    const Item x = items_.back();
    items_.pop_back();
    if (items_.empty()) return;
    const std::size_t n = items_.size();
    std::size_t i = 0;
    for (;;) {
      const std::size_t first = 4 * i + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t last = first + 4 < n ? first + 4 : n;
      for (std::size_t c = first + 1; c < last; ++c)
        if (items_[c] < items_[best]) best = c;
      if (!(items_[best] < x)) break;
      items_[i] = items_[best];
      i = best;
    }
    items_[i] = x;
  }
  // Every entry, in heap order (not sorted).
  const std::vector<Item>& items() const { return items_; }

 private:
  std::vector<Item> items_;
};

}  // namespace cf
