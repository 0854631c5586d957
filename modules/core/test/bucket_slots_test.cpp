// Tests of BucketSlots (bucket_slots.h): the counting sort's slots against a stable sort.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "colonflat/core/bucket_slots.h"

namespace cf {
namespace {

// Items placed through the slots come out grouped by bucket in placing order: equal to a stable sort by bucket.
TEST(BucketSlots, PlacesItemsAsAStableSortByBucket) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> bucket(0, 40);
  std::vector<std::pair<int, int>> items;  // (bucket, id)
  for (int i = 0; i < 2000; ++i) items.push_back({bucket(rng), i});
  BucketSlots<int> slots(45);  // buckets 41..44 stay empty
  for (const auto& it : items) slots.count(std::size_t(it.first));
  slots.close();
  std::vector<int> out(std::size_t(slots.total()), -1);
  for (const auto& it : items) out[std::size_t(slots.place(std::size_t(it.first)))] = it.second;
  std::vector<std::pair<int, int>> sorted = items;
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  ASSERT_EQ(out.size(), sorted.size());
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], sorted[i].second) << i;
  for (int b = 0; b < 45; ++b) {
    const auto n = std::count_if(items.begin(), items.end(), [&](const auto& it) { return it.first == b; });
    EXPECT_EQ(slots.start(std::size_t(b) + 1) - slots.start(std::size_t(b)), n) << "bucket " << b;
  }
  EXPECT_EQ(slots.start(41), slots.total());
}

// Counts of several items at once and a 32-bit unsigned index give the offsets as prefix sums; take_starts moves them out.
TEST(BucketSlots, OffsetsArePrefixSumsOfTheCounts) {
  BucketSlots<std::uint32_t> slots(4);
  slots.count(2, 3);
  slots.count(0, 2);
  slots.count(2);
  slots.close();
  EXPECT_EQ(slots.buckets(), 4u);
  EXPECT_EQ(slots.total(), 6u);
  EXPECT_EQ(slots.place(2), 2u);
  EXPECT_EQ(slots.place(0), 0u);
  EXPECT_EQ(slots.place(2), 3u);
  const std::vector<std::uint32_t> starts = std::move(slots).take_starts();
  EXPECT_EQ(starts, (std::vector<std::uint32_t>{0, 2, 2, 6, 6}));
}

// No bucket and no item: the slots are empty and close() is harmless.
TEST(BucketSlots, EmptyHasNoSlots) {
  BucketSlots<int> slots(0);
  slots.close();
  EXPECT_EQ(slots.total(), 0);
  EXPECT_EQ(slots.buckets(), 0u);
}

}  // namespace
}  // namespace cf
