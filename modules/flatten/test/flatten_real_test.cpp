// Acceptance on real colons (ctest label `real`; skipped when ../shared/real is absent): a CT
// colonography lumen mask (reconstruct -> denoise -> flatten) and a segmented large-intestine
// surface (denoise -> flatten) meet the bounds with the default (area-balanced) map.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/tool.h"
#include "colonflat/denoise/denoise_stage.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/reconstruct/reconstruct_stage.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

const std::filesystem::path kReal = std::filesystem::path(COLONFLAT_SHARED_DIR) / "real";

void run_tool(std::unique_ptr<Stage> (*make)(), const std::vector<std::string>& args) {
  auto tool = make_stage_tool(make);
  std::ostringstream out, err;
  ASSERT_EQ(tool->run(args, out, err), 0) << err.str();
}

void expect_acceptance(const FlatMap& f) {
  EXPECT_EQ(f.stats.flipped, 0u);
  EXPECT_GE(f.coverage.fraction, 0.995) << "missing " << f.coverage.missing_area_mm2 << " mm2, compressed "
                                        << f.coverage.compressed_area_mm2 << " mm2";
  EXPECT_GE(f.stats.area_p05, 0.2);
  EXPECT_LE(f.stats.area_p95, 5.0);
  EXPECT_LE(f.stats.qc_mean, 1.5);
  for (const auto& s : f.segments) {
    EXPECT_EQ(s.crowded_faces, 0u) << "segment " << s.id;
    EXPECT_NEAR(s.length, s.centreline_length, 0.1 * s.centreline_length);
  }
}

// Real CTC lumen mask: every wall face in the map, coverage >= 99.5 %, area ratio in [0.2, 5].
TEST(FlattenReal, CtcLumenMask) {
  const auto mask = kReal / "ctc_lumen_mask_a.nii.gz";
  if (!std::filesystem::exists(mask)) GTEST_SKIP() << mask << " absent";
  testing::TempDir tmp;
  run_tool(make_reconstruct_stage, {mask.string(), "-o", tmp.str("surface.vtp"), "-q"});
  run_tool(make_denoise_stage, {tmp.str("surface.vtp"), "-o", tmp.str("denoised.vtp"), "-q"});
  expect_acceptance(flatten_colon(load_mesh(tmp / "denoised.vtp").mesh));
}

// Real segmented large intestine (100 k faces, genus 1 before denoise).
TEST(FlattenReal, GcaLargeIntestine) {
  const auto in = kReal / "gca_large_intestine_100k.vtk";
  if (!std::filesystem::exists(in)) GTEST_SKIP() << in << " absent";
  testing::TempDir tmp;
  run_tool(make_denoise_stage, {in.string(), "-o", tmp.str("denoised.vtp"), "-q"});
  expect_acceptance(flatten_colon(load_mesh(tmp / "denoised.vtp").mesh));
}

}  // namespace
}  // namespace cf
