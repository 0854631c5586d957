// Registration of supine/prone pairs cut from the real CT colonography lumen mask (issue 27; skipped
// when ../shared/real is absent): the real anatomy where the phantom pairs have a synthetic colon.
// The mask at twice its voxel size (1.5 mm: the pipeline runs in ~15 s of CPU per scan; the lumen's
// shape, loops and touching walls remain), 10 synthetic polyps carved into its wall (mask_pair.h),
// the supine scan run uncut; its flat map's centre line (the colon band with its side branches of
// colon length at their necks, flatten's own course of the colon) is the truth along the colon; the
// prone scan is the same mask moved on the table by (15, -30, 40) mm and cut along that centre line
// (lumen_cut.h) the way the kinds differ: a quarter of the colon dropped, and the colon split
// into 3 more pieces. The targets on each pair: 0 wrong pairs, median error <= 10 mm along
// the colon, >= 90 % of the polyps >= 6 mm seen in both paired.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "colonflat/register/register.h"
#include "colonflat/register/scan.h"
#include "colonflat/testdata/mask_pair.h"
#include "colonflat/testdata/phantom_pair.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

const fs::path kMask = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
const Eigen::Vector3d kTable(15, -30, 40);  // prone table shift, LPS mm (register_bench --real-mask's)
constexpr double kMinBranchPiece = 60;       // mm; PieceOptions::min_branch_piece_mm

Eigen::Vector3d point(const nlohmann::json& p) { return {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()}; }

// `colonflat run MASK --from reconstruct --to flatten`.
void run_mask(const fs::path& mask, const fs::path& run) {
  const auto r = testing::run_colonflat({"run", mask.string(), "--from", "reconstruct", "--to", "flatten", "-o", run.string(), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
}

// The colon's course in a flat map: its first colon band's centre line from the rectum, each side
// branch of colon length inserted at the band point nearest its neck, from its neck end.
PhantomCentreline flat_course(const ColonScan& scan) {
  std::vector<Eigen::Vector3d> band, neck;
  std::vector<std::vector<Eigen::Vector3d>> branches;
  for (const auto& seg : scan.segments) {
    if (!seg.contains("centreline_lps_mm")) continue;
    std::vector<Eigen::Vector3d> line;
    for (const auto& p : seg["centreline_lps_mm"]) line.push_back(point(p));
    if (seg.value("kind", std::string("colon")) == "colon" && band.empty()) band = line;
    if (seg.value("kind", std::string()) != "branch" || seg.value("centreline_length_mm", 0.0) < kMinBranchPiece) continue;
    const Eigen::Vector3d at = point(seg["attach_lps_mm"]);
    if ((line.back() - at).norm() < (line.front() - at).norm()) std::reverse(line.begin(), line.end());
    branches.push_back(line), neck.push_back(at);
  }
  std::vector<std::vector<Eigen::Vector3d>> after(band.size());  // branches inserted after band point k
  for (size_t b = 0; b < branches.size(); ++b) {
    size_t k = 0;
    for (size_t i = 0; i < band.size(); ++i)
      if ((band[i] - neck[b]).norm() < (band[k] - neck[b]).norm()) k = i;
    after[k].insert(after[k].end(), branches[b].begin(), branches[b].end());
  }
  PhantomCentreline c;
  for (size_t i = 0; i < band.size(); ++i) {
    c.points.push_back(band[i]);
    c.points.insert(c.points.end(), after[i].begin(), after[i].end());
  }
  for (size_t i = 0; i < c.points.size(); ++i)
    c.arc_mm.push_back(i == 0 ? 0.0 : c.arc_mm.back() + (c.points[i] - c.points[i - 1]).norm());
  return c;
}

// The polyps placed on the mask as the truth of a scan moved by `shift`.
PhantomTruth truth(const std::vector<MaskPolyp>& polyps, const PhantomCentreline& course, const Eigen::Vector3d& shift) {
  PhantomTruth t;
  t.centreline = course;
  for (auto& p : t.centreline.points) p += shift;
  for (const auto& q : polyps) {
    PhantomTruthPolyp p{q.id, q.lps + shift, q.diameter_mm, 0};
    size_t k = 0;
    for (size_t i = 0; i < t.centreline.points.size(); ++i)
      if ((t.centreline.points[i] - p.lps).norm() < (t.centreline.points[k] - p.lps).norm()) k = i;
    p.arc_mm = t.centreline.arc_mm[k];
    t.polyps.push_back(p);
  }
  return t;
}

// The quarter dropped and the split +3 kinds of segmentation_cut_cases on the real colon: 0 wrong,
// median <= 10 mm and >= 90 % paired on each pair (split +3 missed 1 of 10 before a band turning back
// along the colon was cut in two, piece_split.h; the quarter dropped 8 of 9 on a84c05a: a polyp at a
// neck where the course passes twice, paired at its other place since session 15).
TEST(RealMaskPairs, QuarterDroppedAndSplitIntoThreeMoreMeetTheTargets) {
  if (!fs::exists(kMask)) GTEST_SKIP() << "../shared/real absent";
  testing::TempDir dir;
  MaskCourse course(downsample_mask(read_mask(kMask), 2));
  const std::vector<MaskPolyp> polyps = course.place_polyps(10, 1);
  write_mask(course.cut_and_move({}, Eigen::Vector3d::Zero()), dir / "supine.nrrd");
  write_mask(course.cut_and_move({}, kTable), dir / "prone.nrrd");
  run_mask(dir / "supine.nrrd", dir / "supine_run");
  const ColonScan sup = read_run_dir(dir / "supine_run");
  const PhantomCentreline line = flat_course(sup);
  ASSERT_GT(line.arc_mm.back(), 1000.0);  // the real colon's course, about 2 m
  const PhantomTruth ts = truth(polyps, line, Eigen::Vector3d::Zero()), tp = truth(polyps, line, kTable);
  int checked = 0;
  for (const CutCase& c : segmentation_cut_cases(line.arc_mm.back())) {
    if (!c.within_targets || (c.name.find("25 %") == std::string::npos && c.name.find("split") == std::string::npos)) continue;
    SCOPED_TRACE(c.name);
    const fs::path mask = dir / ("prone_" + std::to_string(checked) + ".nrrd"), run = dir / ("prone_run" + std::to_string(checked));
    ASSERT_GT(cut_lumen_mask(dir / "prone.nrrd", tp.centreline, c.prone, mask), 0);
    run_mask(mask, run);
    const ColonScan pro = read_run_dir(run);
    ColonRegistration reg(sup, pro);
    reg.run();
    const PairFigures f = score_truth_pair(reg, truth_candidates(ts, c.supine), truth_candidates(tp, c.prone), tp);
    std::printf("real mask %-24s pieces %zu/%zu polyps %d right %d wrong %d along median %.1f max %.1f mm\n", c.name.c_str(),
                reg.pieces().supine.size(), reg.pieces().prone.size(), f.seen_in_both, f.right, f.wrong, f.along_median_mm(),
                f.along_max_mm());
    ASSERT_GE(f.seen_in_both, 5);
    EXPECT_EQ(f.wrong, 0);
    EXPECT_LE(f.along_median_mm(), 10.0);
    EXPECT_GE(f.right, int(std::ceil(0.9 * f.seen_in_both))) << f.right << " of " << f.seen_in_both;
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

}  // namespace
}  // namespace cf
