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

// What the area-balanced map achieves on real colons today: no flipped triangle, colon band length =
// centreline length, area ratio of the mapped wall within [0.2, 5] for 90 % of it, coverage
// measured and consistent, ends labelled.
void expect_achieved(const FlatMap& f) {
  EXPECT_EQ(f.stats.flipped, 0u);
  EXPECT_GE(f.stats.area_p05, 0.2);
  EXPECT_LE(f.stats.area_p95, 5.0);
  const Coverage& c = f.coverage;
  EXPECT_NEAR(c.shown_area_mm2 + c.compressed_area_mm2 + c.missing_area_mm2, c.wall_area_mm2, 1e-6 * c.wall_area_mm2);
  for (const auto& s : f.segments) {
    // colon bands: length = centreline length within 10 %; a side branch's band takes its conformal
    // length (docs/flatten.md), its ticks still in centreline mm from the neck
    if (s.kind == "colon") EXPECT_NEAR(s.length, s.centreline_length, 0.1 * s.centreline_length);
    EXPECT_FALSE(s.x0_end.empty());
  }
}

// Issue 11's coverage and angle targets: at least 99.5 % of the wall shown, quasi-conformal mean <= 1.5.
void expect_coverage_and_angles(const FlatMap& f) {
  EXPECT_GE(f.coverage.fraction, 0.995) << "missing " << f.coverage.missing_area_mm2 << " mm2, compressed "
                                        << f.coverage.compressed_area_mm2 << " mm2";
  EXPECT_LE(f.stats.qc_mean, 1.5);
}

// Issue 11's full targets: the bounds and coverage above and every face of the wall in the map.
void expect_targets(const FlatMap& f) {
  expect_coverage_and_angles(f);
  for (const auto& s : f.segments) EXPECT_EQ(s.crowded_faces, 0u) << "segment " << s.id;
}

FlatMap ctc_flat() {
  const auto mask = kReal / "ctc_lumen_mask_a.nii.gz";
  testing::TempDir tmp;
  run_tool(make_reconstruct_stage, {mask.string(), "-o", tmp.str("surface.vtp"), "-q"});
  run_tool(make_denoise_stage, {tmp.str("surface.vtp"), "-o", tmp.str("denoised.vtp"), "-q"});
  return flatten_colon(load_mesh(tmp / "denoised.vtp").mesh);
}

FlatMap gca_flat() {
  const auto in = kReal / "gca_large_intestine_100k.vtk";
  testing::TempDir tmp;
  run_tool(make_denoise_stage, {in.string(), "-o", tmp.str("denoised.vtp"), "-q"});
  return flatten_colon(load_mesh(tmp / "denoised.vtp").mesh);
}

// Real CTC lumen mask (reconstruct -> denoise -> flatten): all of issue 11's targets, the whole
// wall shown (>= 99.5 %, its blind colon stretch behind a 12 mm neck as a band of its own), qc
// mean <= 1.5 and every face in the map (met since session 6: 163-208 faces of its large side
// branch were left out, folded by the cotangent weights; a branch now retries with clamped ones).
TEST(FlattenReal, CtcLumenMask) {
  if (!std::filesystem::exists(kReal / "ctc_lumen_mask_a.nii.gz")) GTEST_SKIP() << "../shared/real absent";
  const FlatMap f = ctc_flat();
  expect_achieved(f);
  expect_targets(f);
  EXPECT_GE(f.segments.size(), 2u);  // the colon band and its side branch
}

// Real segmented large intestine (100 k faces, genus 1 before denoise): all of issue 11's targets
// (met since the area correction of session 6: qc mean 1.97 -> 1.48, coverage 98.97 -> 100 %).
TEST(FlattenReal, GcaLargeIntestine) {
  if (!std::filesystem::exists(kReal / "gca_large_intestine_100k.vtk")) GTEST_SKIP() << "../shared/real absent";
  const FlatMap f = gca_flat();
  expect_achieved(f);
  expect_targets(f);
}


}  // namespace
}  // namespace cf
