// Segmentation of CTs painted around the real lumen mask (../shared/real/ctc_lumen_mask_a.nii.gz,
// downsampled 2 x 2 x 1 to 1.64 x 1.64 x 1.25 mm so the test stays fast): supine and prone, one
// without its PatientPosition header, each with a fully tagged stretch, dependent pools, small
// bowel with oral contrast and a bladder (colonflat phantom --from-mask). Skipped without the data.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/segment/segment.h"

namespace cf {
namespace {

const MaskImage* real_mask() {
  static MaskImage::Pointer m = [] {
    const std::filesystem::path f = std::filesystem::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
    return std::filesystem::exists(f) ? downsample_mask(read_binary_mask(f), {2, 2, 1}) : MaskImage::Pointer();
  }();
  return m.GetPointer();
}

// Paints a case on the downsampled real mask, segments it and scores it; with a long stretch, also
// checks that the long stretch (beside other parts of the colon) is >= 95 % kept.
// `hard`: pools over the folds, small-bowel loops pressed against the colon, slices resampled to slice_mm;
// `pressed`: only the pressed loops (segment_bench's "bowel" case).
MaskSegmentationScore segment_painted(const std::string& position, bool header, double long_stretch_mm = 0, bool hard = false,
                                      double slice_mm = 1.0, std::uint64_t seed = 1, bool pressed = false) {
  MaskPhantomOptions o;
  o.seed = seed;
  o.position = position;
  o.position_header = header;
  o.long_stretch_mm = long_stretch_mm;
  o.deep_pools = hard;
  o.pressed_bowel = hard || pressed;
  const MaskPhantom p = paint_phantom_from_mask(hard ? resample_mask_slices(real_mask(), slice_mm).GetPointer() : real_mask(), o);
  const MaskImage::Pointer seg = segment_colon(p.phantom.ct, {}, nullptr);
  const MaskSegmentationScore s = score_segmentation(seg, p.phantom);
  std::printf("painted real mask%s, %s%s: dice %.4f, colon fluid kept %.1f %% of %.1f mL, %.1f mL outside the colon "
              "(small bowel %.1f mL, bladder %.1f mL)\n", long_stretch_mm > 0 ? " with a long stretch" : "", position.c_str(),
              header ? "" : " (no header)", s.dice, 100 * s.fluid_kept, s.fluid_ml, s.outside_ml, s.small_bowel_ml, s.bladder_ml);
  if (long_stretch_mm > 0) {  // the case is what it claims: a stretch of that length, filled completely
    EXPECT_EQ(p.bodies.at(0).kind, "stretch");
    EXPECT_NEAR(p.bodies.at(0).to_mm - p.bodies.at(0).from_mm, long_stretch_mm, 1e-6);
    const MaskBodyScore b = score_fluid_bodies(seg, p).at(0);
    std::printf("long stretch: %.1f mL, %.1f %% kept\n", b.ml, 100 * b.kept);
    EXPECT_GE(b.kept, 0.95) << b.ml << " mL";
  }
  return s;
}

// Issue 25's targets on real anatomy: Dice >= 0.97, >= 95 % of the colon fluid kept, <= 10 mL
// segmented outside the colon, supine and prone (the prone case without a position header).
// Main 0d7825b measured 0.9934 / 98.6 % / 0.5 mL on both: this painted case (pools under gas, one
// 60-120 mm stretch continuing gas at both ends) is easier than the issue's failing scans.
TEST(SegmentPainted, RealMaskSupineAndProneMeetIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  for (const auto& [pos, header] : {std::pair{"supine", true}, {"prone", false}}) {
    const MaskSegmentationScore s = segment_painted(pos, header);
    EXPECT_GE(s.dice, 0.97) << pos;
    EXPECT_GE(s.fluid_kept, 0.95) << pos;
    EXPECT_LE(s.outside_ml, 10.0) << pos;
  }
}

// The real failure of issue 25 on real anatomy: a 200 mm stretch completely filled with tagged fluid
// where the colon lies beside other parts of itself (gas segments at its ends and along its side),
// with the random 60-120 mm stretch, pools and small bowel; supine. Main d2102a7's linking
// kept 81.6 % of the fluid, Dice 0.951, 35.5 mL outside (34.7 mL small bowel): touching bodies are
// one lumen, which may turn at any angle, and the ends where they touch are used.
TEST(SegmentPainted, RealMaskFilledStretchBesideSegmentsMeetsIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  const MaskSegmentationScore s = segment_painted("supine", true, 200);
  EXPECT_GE(s.dice, 0.97);
  EXPECT_GE(s.fluid_kept, 0.95);
  EXPECT_LE(s.outside_ml, 10.0);
}

// The hard left-down case of segment_bench --painted (no header, 1 mm slices, 200 mm long stretch, deep
// pools, small-bowel loops pressed against the colon) meets issue 25's targets. Session 11 (before the
// fat rule and the open interfaces): a 66 mL loop linked across 19 mm of fat (49.7 mL outside the colon)
// and 230 mL of the random stretch lost along gas segments' sides (Dice 0.950, 84.1 % of the fluid).
TEST(SegmentPainted, RealMaskHardLeftDownMeetsIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  const MaskSegmentationScore s = segment_painted("left-down", false, 200, true);
  EXPECT_LE(s.outside_ml, 10.0);
  EXPECT_LE(s.small_bowel_ml, 1.0);
  EXPECT_GE(s.dice, 0.97);
  EXPECT_GE(s.fluid_kept, 0.95);
}

// The hard prone case (no header, 1.5 mm slices): its random stretch reaches through touching loops
// and meets gas segments along their sides with no wall between. Session 11 lost a 69 mL piece of it
// there (93.9 % of the fluid, Dice 0.983): the open-interface rule keeps it.
TEST(SegmentPainted, RealMaskHardProneMeetsIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  const MaskSegmentationScore s = segment_painted("prone", false, 200, true, 1.5);
  EXPECT_LE(s.outside_ml, 10.0);
  EXPECT_GE(s.dice, 0.97);
  EXPECT_GE(s.fluid_kept, 0.95);
}

// The hard supine case of segment_bench --painted for painter seed 2 (0.6 mm slices, header): a
// 145 mL piece of colon gas, refused as a segment (--min-segment-fraction / --max-segments), shares
// its lumen with two kept fluid bodies (no wall between over 84-98 % of their columns), and a 73 mL
// piece of that fluid was linked at gap 0 and so kept its own free "end", which a pressed small-bowel
// loop then took across 3.3 mm. Session 12 main: Dice 0.9587, 97.4 % of the fluid, 62.3 mL outside
// (62.0 mL small bowel); with open interfaces joined both ways and before the contacts: 0.9894 /
// 97.6 % / 0.4 mL.
TEST(SegmentPainted, RealMaskHardSupineSeed2MeetsIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  const MaskSegmentationScore s = segment_painted("supine", true, 200, true, 0.6, 2);
  EXPECT_LE(s.outside_ml, 10.0);
  EXPECT_LE(s.small_bowel_ml, 1.0);
  EXPECT_GE(s.dice, 0.97);
  EXPECT_GE(s.fluid_kept, 0.95);
}

// The bowel supine case of segment_bench --painted for painter seed 3 (pressed small-bowel loops, header):
// a 77.9 mL loop of constant calibre was linked across 5.3 mm of soft tissue to a colon end that narrows
// to a tip (fronts 82 / 227 / 369 cells). e375ce1: Dice 0.9810, 96.0 % of the fluid, 88.2 mL outside
// (87.4 mL small bowel); a collapsed neck narrows from both sides, so the blunt loop is not linked.
TEST(SegmentPainted, RealMaskBowelSupineSeed3MeetsIssue25Targets) {
  if (!real_mask()) GTEST_SKIP() << "no ../shared/real/ctc_lumen_mask_a.nii.gz";
  const MaskSegmentationScore s = segment_painted("supine", true, 0, false, 1.0, 3, true);
  EXPECT_LE(s.outside_ml, 10.0);
  EXPECT_LE(s.small_bowel_ml, 1.0);
  EXPECT_GE(s.dice, 0.97);
  EXPECT_GE(s.fluid_kept, 0.95);
}

}  // namespace
}  // namespace cf
