#pragma once
// The slots of a counting sort (compressed rows): items are first counted per bucket, the counts
// become offsets, then each item is placed at its bucket's next free slot. A bucket keeps its items
// in the order they were placed (stable), so a caller that places in a fixed order gets a fixed
// numbering. O(buckets + items) time, two arrays of #buckets + 1 and #buckets.
//
//   BucketSlots<int> slots(n);
//   for (item) slots.count(bucket(item));
//   slots.close();
//   for (item) out[slots.place(bucket(item))] = item;   // bucket b: out[start(b) .. start(b + 1))
#include <cstddef>
#include <utility>
#include <vector>

namespace cf {

template <class Index = int>
class BucketSlots {
 public:
  explicit BucketSlots(std::size_t buckets) : start_(buckets + 1, Index(0)) {}

  // Counting: bucket b (< buckets()) gets `items` more slots. Pre: close() not called yet.
  void count(std::size_t b, Index items = 1) { start_[b + 1] += items; }

  // Ends the counting: start(b) .. start(b + 1) are bucket b's slots, total() their number.
  void close() {
    for (std::size_t b = 0; b + 1 < start_.size(); ++b) start_[b + 1] += start_[b];
    cursor_.assign(start_.begin(), start_.end() - 1);
  }

  // Placing: the next free slot of bucket b. Pre: close() called, and fewer calls for b than counted.
  Index place(std::size_t b) { return cursor_[b]++; }

  Index start(std::size_t b) const { return start_[b]; }
  Index total() const { return start_.back(); }
  std::size_t buckets() const { return start_.size() - 1; }
  // The offsets (#buckets + 1 entries), e.g. as a compressed graph's row starts.
  const std::vector<Index>& starts() const { return start_; }
  std::vector<Index> take_starts() && { return std::move(start_); }

 private:
  std::vector<Index> start_, cursor_;
};

}  // namespace cf
