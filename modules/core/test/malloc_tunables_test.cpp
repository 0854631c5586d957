// core/malloc_tunables: the GLIBC_TUNABLES value the executables run themselves with.
#include <gtest/gtest.h>

#include "colonflat/core/malloc_tunables.h"

namespace cf {

// Unset or unrelated tunables get glibc.malloc.hugetlb=1 added; the user's other tunables stay.
TEST(MallocTunables, HugeTlbIsAddedToWhatTheUserSet) {
  EXPECT_EQ(tunables_with_huge_page_malloc(nullptr), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunables_with_huge_page_malloc(""), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(tunables_with_huge_page_malloc("glibc.malloc.arena_max=2"), "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
}

// A hugetlb setting already present (the user's, or the one of the re-run itself) is never
// changed, so the executable runs itself again at most once and a user can turn it off.
TEST(MallocTunables, ExistingHugeTlbSettingIsObeyed) {
  EXPECT_EQ(tunables_with_huge_page_malloc("glibc.malloc.hugetlb=0"), "");
  EXPECT_EQ(tunables_with_huge_page_malloc("glibc.malloc.hugetlb=1"), "");
  EXPECT_EQ(tunables_with_huge_page_malloc("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=0"), "");
}

}  // namespace cf
