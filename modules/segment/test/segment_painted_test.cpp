// Segmentation of CTs painted around the real lumen mask (../shared/real/ctc_lumen_mask_a.nii.gz,
// downsampled 2 x 2 x 1 to 1.64 x 1.64 x 1.25 mm so the test stays fast): supine and prone, one
// without its PatientPosition header, each with a fully tagged stretch, dependent pools, small
// bowel with oral contrast and a bladder (colonflat phantom --from-mask). Skipped without the data.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

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

MaskSegmentationScore segment_painted(const std::string& position, bool header) {
  MaskPhantomOptions o;
  o.position = position;
  o.position_header = header;
  const MaskPhantom p = paint_phantom_from_mask(real_mask(), o);
  const MaskImage::Pointer seg = segment_colon(p.phantom.ct, {}, nullptr);
  const MaskSegmentationScore s = score_segmentation(seg, p.phantom);
  std::printf("painted real mask, %s%s: dice %.4f, colon fluid kept %.1f %% of %.1f mL, %.1f mL outside the colon "
              "(small bowel %.1f mL, bladder %.1f mL)\n", position.c_str(), header ? "" : " (no header)", s.dice,
              100 * s.fluid_kept, s.fluid_ml, s.outside_ml, s.small_bowel_ml, s.bladder_ml);
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

}  // namespace
}  // namespace cf
