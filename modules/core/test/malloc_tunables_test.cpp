// core/malloc_tunables: the GLIBC_TUNABLES value the executables run themselves with, and the
// release of held free memory.
#include <gtest/gtest.h>

#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "colonflat/core/malloc_tunables.h"
#include "colonflat/testing/resident_memory.h"

namespace cf {

namespace {
const std::string kOurs =
    "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=4294967296:glibc.malloc.trim_threshold=4294967296"
    ":glibc.malloc.arena_max=";

}  // namespace

// Unset or unrelated tunables get all four malloc settings added (arena_max = the cores, >= 1);
// the user's other tunables stay in front.
TEST(MallocTunables, SettingsAreAddedToWhatTheUserSet) {
  EXPECT_EQ(tunables_for_colonflat(nullptr, 2), kOurs + "2");
  EXPECT_EQ(tunables_for_colonflat("", 16), kOurs + "16");
  EXPECT_EQ(tunables_for_colonflat(nullptr, 0), kOurs + "1");
  EXPECT_EQ(tunables_for_colonflat("glibc.cpu.hwcaps=-AVX512F", 2), "glibc.cpu.hwcaps=-AVX512F:" + kOurs + "2");
}

// Any glibc.malloc setting already present (the user's, or the one of the re-run itself) is never
// changed, so the executable runs itself again at most once and a user can choose the allocator.
TEST(MallocTunables, ExistingMallocSettingIsObeyed) {
  EXPECT_EQ(tunables_for_colonflat("glibc.malloc.hugetlb=0", 2), "");
  EXPECT_EQ(tunables_for_colonflat("glibc.malloc.hugetlb=1", 2), "");
  EXPECT_EQ(tunables_for_colonflat("glibc.malloc.arena_max=4", 2), "");
  EXPECT_EQ(tunables_for_colonflat(tunables_for_colonflat(nullptr, 2).c_str(), 2), "");
}

// With the heap keeping freed blocks (the thresholds above, set here with mallopt), 64 MiB freed
// stay resident until release_free_memory() gives them back to the kernel.
TEST(MallocTunables, ReleaseGivesHeldFreeMemoryBack) {
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 1 << 30), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
  const std::size_t bytes = std::size_t(64) << 20;
  const double before = testing::resident_mib();
  char* block = static_cast<char*>(std::malloc(bytes));
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, bytes);
  __asm__ volatile("" : : "r"(block) : "memory");  // the writes happen (not optimised away)
  std::free(block);
  const double held = testing::resident_mib();
  release_free_memory();
  const double released = testing::resident_mib();
  mallopt(M_TRIM_THRESHOLD, 128 * 1024);  // glibc's defaults again (the adaptive threshold stays off)
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  EXPECT_GT(held - before, 48.0) << "the freed block was not held";
  EXPECT_LT(released - before, 16.0) << "held " << held - before << " MiB, after release " << released - before;
}

}  // namespace cf
