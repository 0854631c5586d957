// Stages chained in one bag against the same stage on its input alone: what one stage hands on
// to the next (denoise's topology of "denoised") changes no bit of the result.
#include <gtest/gtest.h>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/denoise_stage.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/flatten_stage.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/testdata/synthetic_colon.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

// A closed synthetic colon (genus 0, so denoise cuts nothing and hands its mesh on as it is).
TriangleList small_colon() {
  synthetic::ColonOptions o = synthetic::colon_options(120, 10, 2.0, {});
  return synthetic::colon(o).mesh;
}

// flatten's map of the bag's "denoised".
FlatMap flatten_bag(ArtifactBag& bag) {
  RunContext ctx;
  make_flatten_stage()->run(bag, ctx);
  return bag.get<FlatMap>("flat");
}

// Denoise then flatten in one bag (as `colonflat run`: flatten uses denoise's topology of its
// output instead of analysing it, and leaves it for render) gives the map bit for bit of flatten on denoised.vtp read back
// alone (as `colonflat flatten`: analysed afresh), at 1 and 2 threads.
TEST(StageChain, FlattenAfterDenoiseInOneBagEqualsFlattenOfTheFile) {
  testing::TempDir tmp;
  for (int threads : {1, 2}) {
    set_thread_count(threads);
    ArtifactBag run;
    run.put("surface", synthetic::to_mesh(small_colon()));
    RunContext ctx;
    make_denoise_stage()->run(run, ctx);
    ASSERT_TRUE(run.has(topology_entry("denoised")));
    mesh_artifact().write(run.raw("denoised"), tmp / "denoised.vtp", tmp / "denoised.vtp");
    const FlatMap chained = flatten_bag(run);
    EXPECT_TRUE(run.has(topology_entry("denoised")));  // it stays, for render's snapshot
    ArtifactBag alone;
    alone.put("denoised", mesh_artifact().read(tmp / "denoised.vtp"));
    const FlatMap from_file = flatten_bag(alone);
    ASSERT_GT(chained.uv.size(), 0u);
    EXPECT_EQ(chained.uv, from_file.uv) << threads << " threads";
    EXPECT_EQ(chained.triangles, from_file.triangles);
    EXPECT_EQ(chained.stats.area_p05, from_file.stats.area_p05);
  }
  set_thread_count(0);
}

}  // namespace
}  // namespace cf
