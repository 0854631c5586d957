// Scratch arrays on transparent huge pages: the helpers keep std::vector's contents and sizes.
#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <numeric>
#include <vector>

#include "colonflat/core/huge_pages.h"

namespace cf {
namespace {

// reserve_huge keeps what the vector held, assign_huge / resize_huge give the asked size and
// values, for blocks above and below the huge-page threshold.
TEST(HugePages, HelpersKeepVectorSemantics) {
  for (std::size_t n : {std::size_t(1000), kHugePageMinBytes / sizeof(std::uint32_t) * 3}) {
    std::vector<std::uint32_t> v(10);
    std::iota(v.begin(), v.end(), 7u);
    reserve_huge(v, n);
    ASSERT_EQ(v.size(), 10u);
    EXPECT_GE(v.capacity(), n);
    for (std::uint32_t i = 0; i < 10; ++i) EXPECT_EQ(v[i], 7 + i);
    resize_huge(v, n);
    ASSERT_EQ(v.size(), n);
    EXPECT_EQ(v[9], 16u);
    EXPECT_EQ(v[n - 1], 0u);
    assign_huge(v, n + 5, 3u);
    ASSERT_EQ(v.size(), n + 5);
    EXPECT_EQ(std::count(v.begin(), v.end(), 3u), static_cast<std::ptrdiff_t>(n + 5));
  }
}

}  // namespace
}  // namespace cf
