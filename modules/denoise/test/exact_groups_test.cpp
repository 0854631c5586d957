// Group searches of the exact method (exact_groups.cpp): the spare group searched beside a batch
// of one group keeps every loop exact and the result the same for any thread count.
#include <gtest/gtest.h>

#include <cmath>

#include "brute_force.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/denoise.h"

namespace cf {
namespace {

using namespace synthetic;

DenoiseResult denoise_on(const Mesh& m, int threads) {
  set_thread_count(threads);
  DenoiseResult r = denoise(m, DenoiseOptions{});
  set_thread_count(0);
  return r;
}

long long stat(const DenoiseResult& r, const char* key) { return r.report["search"][key].get<long long>(); }

// Two thin tori in a chain (meridians 4.4 mm, every source along a tube certified against them):
// batches of one group get the far-first order's next source near the group as a spare, whose
// result is used when its seed is still pending after the group (the search made beside the
// group when its roots are unchanged); 1 and 2 threads give the same counts, settled vertices,
// loops and mesh; the first loop is the brute-force shortest.
TEST(DenoiseGroups, SpareGroupBesideABatchOfOneIsUsedOnlyWhenStillNeeded) {
  const Mesh m = to_mesh(torus_chain(2, 6, 0.7, 90, 12, 15));
  const DenoiseResult a = denoise_on(m, 1), b = denoise_on(m, 2);
  EXPECT_EQ(a.report["genus_after"], 0);
  ASSERT_EQ(a.loops.size(), 2u);
  EXPECT_GT(stat(a, "spare_groups_used"), 0);
  EXPECT_LE(stat(a, "spare_groups_used"), stat(a, "spare_groups"));
  EXPECT_GT(stat(a, "spare_groups_same_roots"), 0);
  EXPECT_LE(stat(a, "spare_groups_same_roots"), stat(a, "spare_groups_used"));
  for (const char* key : {"spare_groups", "spare_groups_used", "spare_groups_same_roots", "settled_vertices"})
    EXPECT_EQ(stat(a, key), stat(b, key)) << key;
  const double ref = testing::brute_force_shortest_nonseparating(m, a.loops[0].length * (1 + 1e-9) + 1e-12);
  EXPECT_NEAR(a.loops[0].length, ref, 1e-9 * (1 + ref));
  ASSERT_EQ(a.loops.size(), b.loops.size());
  for (std::size_t i = 0; i < a.loops.size(); ++i) {
    EXPECT_EQ(a.loops[i].vertex_ids, b.loops[i].vertex_ids) << i;
    EXPECT_EQ(a.loops[i].length, b.loops[i].length) << i;
  }
  ASSERT_EQ(a.mesh.n_vertices(), b.mesh.n_vertices());
  for (auto v : a.mesh.vertices()) ASSERT_EQ(a.mesh.point(v), b.mesh.point(v)) << v.idx();
}

}  // namespace
}  // namespace cf
