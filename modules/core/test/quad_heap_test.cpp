// QuadHeap: pops the same sequence as std::priority_queue over (key, id) pairs.
#include <gtest/gtest.h>

#include <functional>
#include <queue>
#include <random>

#include "colonflat/core/quad_heap.h"

namespace cf {
namespace {

// Random interleaved pushes and pops (with duplicate keys and ids) pop exactly what a
// std::priority_queue min-heap pops, down to the tie order.
TEST(QuadHeap, PopsLikeAPriorityQueue) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> key(0, 40), id(0, 9), coin(0, 2);
  QuadHeap heap;
  std::priority_queue<QuadHeap::Item, std::vector<QuadHeap::Item>, std::greater<QuadHeap::Item>> reference;
  for (int step = 0; step < 20000; ++step) {
    if (coin(rng) > 0 || reference.empty()) {
      const double k = 0.5 * key(rng);
      const int i = id(rng);
      heap.push(k, i);
      reference.push({k, i});
    } else {
      ASSERT_EQ(heap.top(), reference.top()) << step;
      heap.pop();
      reference.pop();
    }
    ASSERT_EQ(heap.size(), reference.size());
  }
  while (!reference.empty()) {
    ASSERT_EQ(heap.top(), reference.top());
    heap.pop();
    reference.pop();
  }
  EXPECT_TRUE(heap.empty());
}

// clear() empties the heap; items() holds every entry pushed and not popped.
TEST(QuadHeap, ClearAndItems) {
  QuadHeap heap;
  for (int i = 5; i > 0; --i) heap.push(i, i);
  EXPECT_EQ(heap.items().size(), 5u);
  EXPECT_EQ(heap.top(), QuadHeap::Item(1.0, 1));
  heap.clear();
  EXPECT_TRUE(heap.empty());
}

}  // namespace
}  // namespace cf
