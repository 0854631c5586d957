// Registration of pairs whose two segmentations differ (issue 27): a stretch collapsed in one scan,
// a fully tagged stretch left out of one scan, a colon split into several pieces, the rectum cut
// short by the catheter. Synthetic pairs (synthetic_pair.h) with stretches removed from one scan's
// map, so that each scan's colon is several bands with their own centreline_mm, as flatten writes
// them. Targets of the issue: >= 90 % of the polyps seen in both scans paired, 0 wrong pairs,
// median error <= 10 mm along the colon.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include <Eigen/Geometry>

#include "colonflat/register/pieces.h"
#include "colonflat/register/register.h"
#include "colonflat/testdata/phantom_pair.h"
#include "colonflat/testdata/synthetic_pair.h"

namespace cf {
namespace {

struct PairScore {
  int seen_in_both = 0, right = 0, wrong = 0;
  double along_median_mm = 0;  // mapped supine polyp vs the prone polyp, mm along the prone colon
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

PairScore score(const SyntheticPair& pair, const ColonRegistration& reg) {
  PairScore p;
  std::vector<double> along;
  for (const auto& q : pair.polyps) {
    if (!q.in_supine || !q.in_prone) continue;
    ++p.seen_in_both;
    const auto [s, t] = reg.locate(q.supine_lps, Direction::kSupineToProne);
    double s2, t2;
    reg.map_coordinates(Direction::kSupineToProne, s, t, s2, t2);
    along.push_back(std::abs(s2 - reg.locate(q.prone_lps, Direction::kProneToSupine).first));
  }
  for (const auto& m : reg.matching().pairs) {
    bool polyp = false;  // two one-scan-only extras paired by chance are not a polyp pair
    for (const auto& q : pair.polyps) polyp |= q.id == m.supine_id || q.id == m.prone_id;
    if (polyp) (m.supine_id == m.prone_id ? p.right : p.wrong) += 1;
  }
  p.along_median_mm = median(along);
  return p;
}

// Every polyp seen in both scans paired right, none wrong, median error along the colon <= 10 mm.
void expect_every_polyp_paired(const PairScore& p) {
  EXPECT_EQ(p.wrong, 0);
  EXPECT_EQ(p.right, p.seen_in_both) << p.right << " of " << p.seen_in_both;
  EXPECT_LE(p.along_median_mm, 10.0);
}


SyntheticPairOptions long_pair(std::uint64_t seed) {
  SyntheticPairOptions o;
  o.length_mm = 800;
  o.polyps = 10;
  o.spacing_mm = 2.0;
  o.seed = seed;
  return o;
}

// The registration of a pair, run (the pair must outlive it).
std::unique_ptr<ColonRegistration> registered(const SyntheticPair& pair) {
  auto reg = std::make_unique<ColonRegistration>(pair.supine, pair.prone);
  reg->run();
  return reg;
}

// The wall vertex of a scan nearest to material (sigma, phi) (mm along, angle; radius_mm turns the angle into mm).
size_t vertex_at_material(const std::vector<double>& sigma, const std::vector<double>& phi, double s, double f,
                          double radius_mm) {
  size_t best = 0;
  double best_d = INFINITY;
  for (size_t v = 0; v < sigma.size(); ++v)
    if (const double d = std::pow(sigma[v] - s, 2) + std::pow(radius_mm * std::remainder(phi[v] - f, 2 * M_PI), 2); d < best_d)
      best = v, best_d = d;
  return best;
}

// Runs the registration and checks the targets on the polyps seen in both scans.
void expect_targets(const SyntheticPairOptions& o, int expected_prone_pieces) {
  const SyntheticPair pair = make_synthetic_pair(o);
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  ASSERT_TRUE(reg.piecewise());
  EXPECT_EQ(int(reg.pieces().prone.size()), expected_prone_pieces);
  const PairScore p = score(pair, reg);
  ASSERT_GT(p.seen_in_both, 0);
  EXPECT_EQ(p.wrong, 0);
  EXPECT_GE(p.right, int(std::ceil(0.9 * p.seen_in_both))) << p.right << " of " << p.seen_in_both;
  EXPECT_LE(p.along_median_mm, 10.0);
}

// A 15 mm stretch collapsed in the prone scan only: two prone pieces against one supine colon.
TEST(RegisterPieces, CollapsedStretchInOneScan) {
  for (std::uint64_t seed : {1, 2}) {
    SyntheticPairOptions o = long_pair(seed);
    o.prone_removed = {{380, 395}};
    expect_targets(o, 2);
  }
}

// A fully tagged stretch (25 % of the colon, 200 mm) left out of the prone segmentation.
TEST(RegisterPieces, TaggedStretchDroppedInOneScan) {
  for (std::uint64_t seed : {1, 2}) {
    SyntheticPairOptions o = long_pair(seed);
    o.prone_removed = {{250, 450}};
    expect_targets(o, 2);
  }
}

// The prone colon split into 3 more pieces than the supine one, with flatten's band order wrong.
TEST(RegisterPieces, ColonSplitIntoThreeMorePieces) {
  SyntheticPairOptions o = long_pair(3);
  o.prone_removed = {{150, 160}, {350, 362}, {560, 570}};
  o.shuffle_pieces = true;
  expect_targets(o, 4);
}

// The rectum cut short by the catheter (first 60 mm missing) in the prone scan.
TEST(RegisterPieces, RectumCutShortInOneScan) {
  SyntheticPairOptions o = long_pair(4);
  o.prone_removed = {{0, 60}};
  expect_targets(o, 1);
}

// Both scans lack a different stretch (supine a collapse, prone a tagged stretch): the scan with
// fewer pieces is the reference and the other's pieces are placed on it.
TEST(RegisterPieces, EachScanMissesADifferentStretch) {
  SyntheticPairOptions o = long_pair(5);
  o.supine_removed = {{520, 540}};
  o.prone_removed = {{200, 300}, {600, 610}};
  expect_targets(o, 3);
}

// One scan keeps material [from, to) as a side-branch band hanging at `from` (flatten cut that
// stretch off behind a neck): its vertices get their own centreline_mm (from the neck, or with
// `towards_neck` from the tip) and the colon band's centreline_mm skips it, as the real CTC mask's
// supine colon does with a 204 mm stretch behind a 12 mm neck.
void make_side_branch(ColonScan& s, const std::vector<double>& sigma, double from, double to, bool towards_neck = false) {
  double at_from = 1e18, at_to = 1e18;
  Eigen::Vector3d neck = Eigen::Vector3d::Zero();  // the centre of the wall at the neck
  int at_neck = 0;
  for (size_t v = 0; v < s.lps.size(); ++v) {
    if (sigma[v] >= from && s.segment[v] == 0) at_from = std::min(at_from, s.centreline_mm[v]);
    if (sigma[v] >= to && s.segment[v] == 0) at_to = std::min(at_to, s.centreline_mm[v]);
    if (std::abs(sigma[v] - from) < 1) neck += s.lps[v], ++at_neck;
  }
  neck /= std::max(1, at_neck);
  const int id = int(s.segments.size()) + 10;
  for (size_t v = 0; v < s.lps.size(); ++v) {
    if (s.segment[v] != 0) continue;
    if (sigma[v] >= to) s.centreline_mm[v] -= at_to - at_from;
    else if (sigma[v] >= from)
      s.segment[v] = id, s.centreline_mm[v] = towards_neck ? at_to - s.centreline_mm[v] : s.centreline_mm[v] - at_from;
  }
  nlohmann::json branch = s.segments.at(0);
  branch["id"] = id, branch["order"] = id, branch["kind"] = "branch", branch["parent"] = 0, branch["attach_mm"] = at_from;
  branch["attach_lps_mm"] = {neck.x(), neck.y(), neck.z()};
  branch["x0_end"] = "neck", branch["x1_end"] = "tip";  // as flatten labels every branch, whichever way its mm runs
  s.segments.push_back(branch);
}

// The supine's common s of a vertex on material sigma (the supine is the reference from 0: s =
// sigma up to the gaps' straight-line shortening, none here before `sigma`).
double supine_s_error(const SyntheticPair& pair, const ColonRegistration& reg, double from, double to) {
  std::vector<double> err;
  const ScanCoordinates& sc = reg.supine_coordinates();
  for (size_t v = 0; v < sc.s.size(); v += 5)
    if (pair.supine_sigma[v] >= from && pair.supine_sigma[v] < to) err.push_back(std::abs(sc.s[v] - pair.supine_sigma[v]));
  return err.empty() ? INFINITY : median(err);
}

// The real-mask split +3 failure (docs/register.md): a 150 mm stretch the supine keeps as a side
// branch is colon inside a prone piece, the prone split into 3 more pieces. The branch is of colon
// length, so it is a piece: inserted into the supine's course at its neck (the band after it moves
// on by 150 mm) whichever way its own mm runs, the prone pieces placed on it. Every target of the
// issue on all polyps seen in both, the polyps on the branch included (before: held at the neck,
// never paired, 8 of 10), the branch's vertices within 10 mm of their material place along the
// colon, each prone piece's first wall (next to a cut, where the alignment has one side only) mapped
// within 15 mm (the pair's wall slide) of the supine wall of the same material.
TEST(RegisterPieces, StretchKeptAsSideBranchInOneScanIsLaidOutAlongTheColon) {
  for (const bool towards_neck : {false, true}) {
    SyntheticPairOptions o = long_pair(3);
    o.prone_removed = {{150, 160}, {420, 432}, {600, 610}};
    SyntheticPair pair = make_synthetic_pair(o);
    make_side_branch(pair.supine, pair.supine_sigma, 220, 370, towards_neck);
    ColonRegistration reg(pair.supine, pair.prone);
    reg.run();
    ASSERT_TRUE(reg.piecewise());
    ASSERT_EQ(reg.pieces().prone.size(), 4u);
    ASSERT_EQ(reg.pieces().supine.size(), 2u);  // the band and the branch
    int on_branch = 0;
    for (const auto& q : pair.polyps) on_branch += q.in_supine && q.in_prone && q.sigma_mm >= 220 && q.sigma_mm < 370;
    ASSERT_GT(on_branch, 0);
    const PairScore p = score(pair, reg);
    EXPECT_EQ(p.wrong, 0);
    EXPECT_GE(p.right, int(std::ceil(0.9 * p.seen_in_both))) << p.right << " of " << p.seen_in_both;
    EXPECT_LE(p.along_median_mm, 10.0);
    EXPECT_LT(supine_s_error(pair, reg, 230, 360), 10.0) << "towards neck " << towards_neck;
    const ScanCoordinates &sc = reg.supine_coordinates(), &pc = reg.prone_coordinates();
    for (const auto& piece : reg.pieces().prone) {  // each prone piece's first wall mapped to the supine
      double error = NAN;
      for (size_t v = 0; v < pair.prone.lps.size() && std::isnan(error); ++v)
        if (pair.prone.segment[v] == piece.segment && pair.prone.centreline_mm[v] < 2)
          for (size_t w = 0; w < pair.supine.lps.size(); ++w)
            if (std::abs(pair.supine_sigma[w] - pair.prone_sigma[v]) < 1) {  // the same material
              double s2, t2;
              reg.map_coordinates(Direction::kProneToSupine, pc.s[v], pc.theta[v], s2, t2);
              error = std::abs(s2 - sc.s[w]);
              break;
            }
      ASSERT_FALSE(std::isnan(error)) << "piece " << piece.segment;
      EXPECT_LT(error, 15.0) << "piece " << piece.segment << ", towards neck " << towards_neck;
    }
  }
}

// A band of colon length that flatten cut off around tissue (a strand stump, FlatSegments "holds":
// "tissue") is not inserted into the colon's course as a branch piece; the same band holding lumen is.
TEST(RegisterPieces, TissueBandOfColonLengthIsNoPieceOfTheCourse) {
  for (const char* holds : {"lumen", "tissue"}) {
    SyntheticPair pair = make_synthetic_pair(long_pair(3));
    make_side_branch(pair.supine, pair.supine_sigma, 220, 370, false);
    pair.supine.segments.back()["holds"] = holds;
    const std::vector<ColonPiece> pieces = colon_pieces(pair.supine, PieceOptions());
    const auto branches = std::count_if(pieces.begin(), pieces.end(), [](const ColonPiece& p) { return p.branch; });
    EXPECT_EQ(branches, std::string(holds) == "lumen" ? 1 : 0) << holds;
  }
}

// Both scans keep the same 150 mm stretch as a side branch (the real mask's uncut pair): the prone
// branch is placed on the supine one, branch to branch, and the band across the neck keeps both
// sides of the jump: every polyp seen in both paired right, the polyps on the branch included,
// median error <= 10 mm.
TEST(RegisterPieces, SideBranchInBothScansIsMappedBranchToBranch) {
  SyntheticPairOptions o = long_pair(3);
  SyntheticPair pair = make_synthetic_pair(o);
  make_side_branch(pair.supine, pair.supine_sigma, 220, 370);
  make_side_branch(pair.prone, pair.prone_sigma, 220, 370, true);
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  ASSERT_EQ(reg.pieces().prone.size(), 2u);
  const PairScore p = score(pair, reg);
  expect_every_polyp_paired(p);
  EXPECT_LT(supine_s_error(pair, reg, 230, 360), 10.0);
}

// The prone colon band runs from the rectum to material 400 mm, then on from the cecal end (800 mm)
// back to 400 mm (flatten's band passing from one stretch into another where their walls touch, as
// the painted supine's band does): one direction per piece held the whole second half at the turn
// (no polyp there paired). Cut where its projections turn, both halves are placed: every polyp seen
// in both paired right, median error <= 10 mm, the band laid out as two pieces.
TEST(RegisterPieces, BandTurningBackAlongTheColonIsCutInTwo) {
  SyntheticPairOptions o = long_pair(2);
  SyntheticPair pair = make_synthetic_pair(o);
  ColonScan& p = pair.prone;
  double turn = 1e18, end = 0;  // centreline mm at material 400 and at the band's end
  for (size_t v = 0; v < p.lps.size(); ++v) {
    if (pair.prone_sigma[v] >= 400) turn = std::min(turn, p.centreline_mm[v]);
    end = std::max(end, p.centreline_mm[v]);
  }
  for (size_t v = 0; v < p.lps.size(); ++v)
    if (pair.prone_sigma[v] >= 400) p.centreline_mm[v] = turn + (end - p.centreline_mm[v]);
  p.segments.at(0)["x1_end"] = "end B";  // the band's far end is no longer the cecum
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  EXPECT_EQ(reg.pieces().prone.size(), 2u);
  const PairScore s = score(pair, reg);
  expect_every_polyp_paired(s);
}

// The supine keeps material 220-290 and 290-370 mm as two side branches hanging at one neck (220),
// the second with the lower segment id (flatten's ids say nothing of the course), the prone split
// into 3 more pieces (the supine the reference): the colon runs out along the first branch and on
// along the second, so both are inserted in that order (branch_order.h): each branch's vertices
// within 10 mm of their material place, every polyp seen in both paired right, median <= 10 mm
// (e375ce1 inserted them by segment id: 290-370 first, each stretch 70-80 mm off).
TEST(RegisterPieces, TwoBranchesAtOneNeckAreInsertedInTheirCourse) {
  SyntheticPairOptions o = long_pair(3);
  o.prone_removed = {{150, 160}, {420, 432}, {600, 610}};
  SyntheticPair pair = make_synthetic_pair(o);
  ColonScan& s = pair.supine;
  make_side_branch(s, pair.supine_sigma, 290, 370);
  make_side_branch(s, pair.supine_sigma, 220, 290);
  const nlohmann::json neck = s.segments.back();  // both hang at the neck at material 220 (the second cut)
  for (auto& seg : s.segments)
    if (seg.value("kind", std::string()) == "branch") seg["attach_mm"] = neck["attach_mm"], seg["attach_lps_mm"] = neck["attach_lps_mm"];
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  ASSERT_EQ(reg.pieces().supine.size(), 3u);
  ASSERT_EQ(reg.pieces().prone.size(), 4u);
  EXPECT_LT(supine_s_error(pair, reg, 225, 285), 10.0);
  EXPECT_LT(supine_s_error(pair, reg, 295, 365), 10.0);
  expect_every_polyp_paired(score(pair, reg));
}

// Where the prone scan has no wall (a dropped stretch) the alignment is marked unsupported (80 %
// of the stretch), the supine polyps there are never paired, and only polyps of that stretch are
// listed as unaligned; elsewhere it is supported; the unpaired candidates are shown where the matching put them.
TEST(RegisterPieces, DroppedStretchIsUnsupportedAndNeverPaired) {
  SyntheticPairOptions o = long_pair(1);
  o.prone_removed = {{250, 450}};
  const SyntheticPair pair = make_synthetic_pair(o);
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  double covered = 0;  // supine s = material sigma (supine is the reference: one piece from 0)
  for (const auto& [a, b] : reg.support().unsupported) covered += std::max(0.0, std::min(b, 450.0) - std::max(a, 250.0));
  EXPECT_GT(covered, 0.8 * 200);
  EXPECT_GT(reg.support().supported_fraction, 0.6);
  EXPECT_LT(reg.support().supported_fraction, 0.85);
  EXPECT_GT(reg.support_gap_mm(true, 350), 50);
  EXPECT_LE(reg.support_gap_mm(true, 100), reg.options().max_unsupported_mm);
  int inside = 0;
  for (const auto& q : pair.polyps) {
    if (q.in_prone) continue;
    ++inside;
    for (const auto& m : reg.matching().pairs) EXPECT_NE(m.supine_id, q.id);
  }
  EXPECT_GT(inside, 0);
  // Each unpaired candidate's shown place is kept by the matching (no point query per call): the first of
  // its places (locations()) with support along, else its nearest; map_candidate maps that place.
  const CandidateMatching& m = reg.matching();
  ASSERT_EQ(m.supine_shown.size(), m.supine_only.size());
  for (const auto& c : pair.supine.candidates) {
    if (std::find(m.supine_only.begin(), m.supine_only.end(), c.id) == m.supine_only.end()) continue;
    const auto pl = reg.locations(c.lps, Direction::kSupineToProne, std::max(reg.options().min_place_reach_mm, c.size_mm / 2));
    auto want = pl.front();
    for (auto it = pl.rbegin(); it != pl.rend(); ++it)
      if (reg.support_gap_mm(true, it->first) <= reg.options().max_unsupported_mm) want = *it;
    const auto [s, theta] = reg.candidate_place(c.id, Direction::kSupineToProne);
    EXPECT_DOUBLE_EQ(s, want.first) << "candidate " << c.id;
    EXPECT_DOUBLE_EQ(theta, want.second) << "candidate " << c.id;
    EXPECT_EQ(reg.map_candidate(c.id, Direction::kSupineToProne), reg.map_place(m, c.id, Direction::kSupineToProne));
  }
  const auto& un = reg.matching().supine_unaligned;  // only polyps of the dropped stretch are unaligned
  EXPECT_FALSE(un.empty());
  for (const auto& q : pair.polyps) {
    if (q.in_prone) EXPECT_EQ(std::find(un.begin(), un.end(), q.id), un.end()) << "polyp " << q.id;
  }
  const nlohmann::json j = reg.summary();
  EXPECT_FALSE(j["support"]["unsupported_supine_mm"].empty());
  EXPECT_EQ(j["pieces"]["prone"].size(), 2u);
}

// Two findings 42 mm apart along the colon's wall (supine at material 600 mm, which the prone does not show;
// prone at 642 mm, which the supine does not show) that the prone wall's 20 mm slide back along the colon
// brings within match_along_mm on the common axis (the wall slides 1-2 cm between the positions) are not
// paired: the length map, which follows the wall's folds, puts them 42 mm apart. Session 16's rule (the
// smaller of the length map's and the common s's distance) paired them. The same supine finding is paired
// with a prone finding at its own material place.
TEST(RegisterPieces, FindingsApartOnTheWallAreNotPairedWhereTheWallSlid) {
  SyntheticPairOptions o = long_pair(1);
  o.slide_mm = 20;  // prone material sigma lies at sigma + 20 sin(2 pi sigma / 800): 20 mm back at 600 mm
  const SyntheticPair pair = make_synthetic_pair(o);
  const auto run = registered(pair);
  const ColonRegistration& reg = *run;
  auto at = [&](bool supine, double sigma, int id) {
    const size_t v = supine ? vertex_at_material(pair.supine_sigma, pair.supine_phi, sigma, 1.0, o.radius_mm)
                            : vertex_at_material(pair.prone_sigma, pair.prone_phi, sigma, 1.0, o.radius_mm);
    return ScanCandidate{id, supine ? pair.supine.lps[v] : pair.prone.lps[v], 8, 0.7};
  };
  const ScanCandidate a = at(true, 600, 300), b = at(false, 642, 301), c = at(false, 600, 302);
  const double sa = reg.locate(a.lps, Direction::kSupineToProne).first, sb = reg.locate(b.lps, Direction::kProneToSupine).first;
  double mapped, theta;
  reg.map_coordinates(Direction::kSupineToProne, sa, 1.0, mapped, theta);
  const double limit = reg.options().match_along_mm;
  ASSERT_LT(std::abs(sb - sa), limit) << "the slide must bring them within the limit on the common axis";
  ASSERT_GT(std::abs(sb - mapped), limit) << "the length map must follow the wall";
  EXPECT_TRUE(reg.match({a}, {b}).pairs.empty()) << "common s " << std::abs(sb - sa) << " mm, length map "
                                                  << std::abs(sb - mapped) << " mm";
  const CandidateMatching same = reg.match({a}, {c});
  ASSERT_EQ(same.pairs.size(), 1u);
  EXPECT_EQ(same.pairs[0].prone_id, 302);
}

// The pieces of a split prone colon are placed in the right order and direction on the supine
// axis even when flatten's order is wrong, each start within 25 mm of its true place (the prone
// centre line is longer than the supine one where its middle is shifted sideways; the length
// alignment then corrects that).
TEST(RegisterPieces, PiecesArePlacedInOrderAndDirection) {
  SyntheticPairOptions o = long_pair(2);
  o.prone_removed = {{150, 160}, {350, 362}, {560, 570}};
  o.shuffle_pieces = true;
  const SyntheticPair pair = make_synthetic_pair(o);
  const PieceLayout L = layout_pieces(pair.supine, pair.prone, PieceOptions{});
  ASSERT_EQ(L.prone.size(), 4u);
  EXPECT_TRUE(L.supine_is_reference);
  // material sigma of each piece's start, slid as the prone wall is (sigma + 15 sin(2 pi sigma / L))
  const double starts[] = {0, 160, 362, 570};
  for (size_t k = 0; k < 4; ++k) {
    const double slid = starts[k] + o.slide_mm * std::sin(2 * M_PI * starts[k] / o.length_mm);
    EXPECT_TRUE(L.prone[k].registered);
    EXPECT_FALSE(L.prone[k].flipped);
    EXPECT_EQ(L.prone[k].segment, int(k));
    EXPECT_NEAR(L.prone[k].start_mm, slid, 25.0) << "piece " << k;
  }
}

// A supine piece spanning a 200 mm stretch the prone scan lacks (prone the reference: 2 pieces
// against 3) lies on both sides of the prone gap at its own length: the gap is measured from it
// and the pieces of both scans placed within 5 mm of their material position (no slide, no shift:
// material mm = common s), although the supine centre points inside the gap project onto the
// prone pieces' ends.
TEST(RegisterPieces, PieceSpanningAGapIsPlacedAtItsLength) {
  SyntheticPairOptions o = long_pair(1);
  o.slide_mm = 0, o.shift_mm = 0;
  o.supine_removed = {{100, 115}, {650, 665}};
  o.prone_removed = {{300, 500}};
  const SyntheticPair pair = make_synthetic_pair(o);
  const PieceLayout L = layout_pieces(pair.supine, pair.prone, PieceOptions{});
  ASSERT_FALSE(L.supine_is_reference);
  ASSERT_EQ(L.prone.size(), 2u);
  ASSERT_EQ(L.supine.size(), 3u);
  const double p0 = L.prone[0].start_mm;  // material 0
  EXPECT_NEAR(L.prone[1].start_mm - p0, 500.0, 5.0);
  EXPECT_NEAR(L.supine[1].start_mm - p0, 115.0, 5.0);
  EXPECT_NEAR(L.supine[2].start_mm - p0, 665.0, 5.0);
}

// Moving the prone scan on the table (a rigid shift of 59 mm) moves the fitted shift by the same
// amount up to a slide along the colon's long axis (within 20 mm: a tube fits itself shifted
// along its length almost as well), also with a quarter of one colon missing, and the pairs stay right.
TEST(RegisterPieces, TableShiftIsRecovered) {
  SyntheticPairOptions o = long_pair(1);
  o.prone_removed = {{250, 450}};
  SyntheticPair pair = make_synthetic_pair(o);
  const Eigen::Vector3d before = layout_pieces(pair.supine, pair.prone, PieceOptions{}).prone_to_supine;
  const Eigen::Vector3d table(30, -20, 45);
  for (auto& p : pair.prone.lps) p += table;
  for (auto& c : pair.prone.candidates) c.lps += table;
  const PieceLayout L = layout_pieces(pair.supine, pair.prone, PieceOptions{});
  EXPECT_LT((L.prone_to_supine - (before - table)).norm(), 20.0);
  ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  int wrong = 0, right = 0;
  for (const auto& m : reg.matching().pairs) (m.supine_id == m.prone_id ? right : wrong) += 1;
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(right, 6);
}

// Each supine vertex's partner is the exact nearest prone vertex in the cylinder embedding (checked
// against all prone vertices), also where its image falls in the 200 mm the prone scan lacks,
// far along from every prone vertex (the slab search of along_slabs.h, not the bucket locator).
TEST(RegisterPieces, PartnerIsExactNearestAlsoAcrossAMissingStretch) {
  SyntheticPairOptions o = long_pair(1);
  o.prone_removed = {{300, 500}};
  const SyntheticPair pair = make_synthetic_pair(o);
  const auto run = registered(pair);
  const ColonRegistration& reg = *run;
  const ScanCoordinates &sc = reg.supine_coordinates(), &pc = reg.prone_coordinates();
  const double r = std::max(1.0, pc.mean_radius_mm);
  auto embed = [r](double s, double t) { return Eigen::Vector3d(s, r * std::cos(t), r * std::sin(t)); };
  int far = 0, checked = 0;
  for (size_t v = 0; v < sc.s.size(); v += 7) {
    if (std::isnan(sc.s[v])) continue;
    double s2, t2;
    reg.map_coordinates(Direction::kSupineToProne, sc.s[v], sc.theta[v], s2, t2);
    const Eigen::Vector3d q = embed(s2, t2);
    double best = INFINITY, along = INFINITY;
    for (size_t w = 0; w < pc.s.size(); ++w) {
      if (std::isnan(pc.s[w])) continue;
      best = std::min(best, (embed(pc.s[w], pc.theta[w]) - q).norm());
      along = std::min(along, std::abs(pc.s[w] - s2));
    }
    const int w = reg.supine_to_prone()[v];
    ASSERT_GE(w, 0);
    EXPECT_NEAR((embed(pc.s[size_t(w)], pc.theta[size_t(w)]) - q).norm(), best, 1e-9) << "vertex " << v;
    far += along > 10, ++checked;
  }
  EXPECT_GT(far, checked / 20) << "too few images in the missing stretch to test the far path";
}


// The patient lying turned on the table by 10 or 20 degrees about the superior axis (plus a 59 mm
// shift, a quarter of the prone colon missing): the translation-only table shift still pairs every
// polyp seen in both right (the centre-line term is soft, sigma 60 mm; points 150 mm from the turn's
// axis move 26-52 mm), median error <= 10 mm along, and the supported share stays above 60 %.
TEST(RegisterPieces, SmallTableRotationKeepsPairsRight) {
  for (double deg : {10.0, 20.0}) {
    SyntheticPairOptions o = long_pair(1);
    o.prone_removed = {{250, 450}};
    SyntheticPair pair = make_synthetic_pair(o);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : pair.prone.lps) c += p / double(pair.prone.lps.size());
    const Eigen::Matrix3d R = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    auto move = [&](Eigen::Vector3d& p) { p = R * (p - c) + c + Eigen::Vector3d(30, -20, 45); };
    for (auto& p : pair.prone.lps) move(p);
    for (auto& q : pair.prone.candidates) move(q.lps);
    for (auto& q : pair.polyps) move(q.prone_lps);
    const auto run = registered(pair);
    const ColonRegistration& reg = *run;
    const PairScore p = score(pair, reg);
    EXPECT_EQ(p.wrong, 0) << deg << " deg";
    EXPECT_EQ(p.right, p.seen_in_both) << deg << " deg";
    EXPECT_LE(p.along_median_mm, 10.0) << deg << " deg";
    EXPECT_GT(reg.support().supported_fraction, 0.6) << deg << " deg";
  }
}

// The polyps of one scan as candidates (score 1), as the benches give truth polyps.
std::vector<ScanCandidate> truth_list(const SyntheticPair& pair, bool supine) {
  std::vector<ScanCandidate> out;
  for (const auto& q : pair.polyps)
    if (supine ? q.in_supine : q.in_prone) out.push_back({q.id, supine ? q.supine_lps : q.prone_lps, q.size_mm, 1});
  return out;
}

// The prone's truth as a phantom's: its polyps and its centre line (wall centroid per 2 mm of material).
PhantomTruth prone_truth(const SyntheticPair& pair) {
  PhantomTruth t;
  std::vector<Eigen::Vector3d> sum;
  std::vector<int> n;
  for (size_t v = 0; v < pair.prone.lps.size(); ++v) {
    const size_t k = size_t(std::max(0.0, pair.prone_sigma[v] / 2));
    if (k >= sum.size()) sum.resize(k + 1, Eigen::Vector3d::Zero()), n.resize(k + 1, 0);
    sum[k] += pair.prone.lps[v], ++n[k];
  }
  for (size_t k = 0; k < sum.size(); ++k)
    if (n[k] > 0) t.centreline.points.push_back(sum[k] / n[k]), t.centreline.arc_mm.push_back(2.0 * double(k) + 1);
  return t;
}

// The start (material mm) of a 30 mm stretch 200 mm or more beyond material `after`, in the middle of
// the widest gap between two polyps there, so that no polyp lies within 10 mm of it; NaN when fewer
// than two polyps lie that far on or the gap is too narrow.
double free_stretch_beyond(const SyntheticPair& pair, double after) {
  std::vector<double> at;
  for (const auto& o : pair.polyps)
    if (o.sigma_mm > after + 200) at.push_back(o.sigma_mm);
  std::sort(at.begin(), at.end());
  if (at.size() < 2) return NAN;
  size_t widest = 1;
  for (size_t k = 2; k < at.size(); ++k)
    if (at[k] - at[k - 1] > at[widest] - at[widest - 1]) widest = k;
  const double from = (at[widest] + at[widest - 1]) / 2 - 15;
  for (const auto& o : pair.polyps)
    if (o.sigma_mm >= from - 10 && o.sigma_mm <= from + 40) return NAN;
  return from;
}

// The colon passes one polyp twice (walls of two loops touching): in the supine a 30 mm stretch of
// the colon 200 mm or more further on lies against the polyp, its wall half as far from the polyp's point as
// the polyp's own (so locate() puts the polyp on that stretch, which the prone has elsewhere: no
// support there). The polyp is still paired with itself at its other place on the course, every
// polyp seen in both is paired right (a84c05a: located on the stretch only, never paired), and the
// pair is shown and mapped at that place (s15 a0895e0: at the stretch, mapped 376 mm off), and scored
// there by the benches' score_truth_pair.
TEST(RegisterPieces, PolypWhereTheColonPassesTwiceIsPairedAtItsOtherPlace) {
  SyntheticPair pair = make_synthetic_pair(long_pair(1));
  const SyntheticPolyp& q = pair.polyps[2];
  const double from = free_stretch_beyond(pair, q.sigma_mm);
  ASSERT_TRUE(std::isfinite(from));
  double own = INFINITY;  // the polyp point's distance to its own wall
  size_t touch = 0;       // the stretch's vertex nearest to it
  for (size_t v = 0; v < pair.supine.lps.size(); ++v) {
    const double d = (pair.supine.lps[v] - q.supine_lps).norm(), sigma = pair.supine_sigma[v];
    if (sigma < from || sigma > from + 30) own = std::min(own, d);
    else if (d < (pair.supine.lps[touch] - q.supine_lps).norm() || pair.supine_sigma[touch] < from) touch = v;
  }
  ASSERT_GT(own, 0.05);
  const Eigen::Vector3d inward = (pair.supine.lps[touch] - q.supine_lps).normalized();
  const Eigen::Vector3d move = q.supine_lps + 0.5 * own * inward - pair.supine.lps[touch];
  for (size_t v = 0; v < pair.supine.lps.size(); ++v)
    if (pair.supine_sigma[v] >= from && pair.supine_sigma[v] <= from + 30) pair.supine.lps[v] += move;
  const auto run = registered(pair);
  const ColonRegistration& reg = *run;
  ASSERT_GT(reg.locate(q.supine_lps, Direction::kSupineToProne).first, from - 20);  // the first place is the stretch
  EXPECT_GE(reg.locations(q.supine_lps, Direction::kSupineToProne, 3).size(), 2u);
  expect_every_polyp_paired(score(pair, reg));
  // What is shown for the pair (check-here position, side-by-side marker) is at the polyp's own place:
  // mapped within 5 mm of the prone polyp (its first place, the stretch, maps far from it).
  const Eigen::Vector3d shown = reg.map_candidate(q.id, Direction::kSupineToProne);
  const Eigen::Vector3d nearest = reg.map_lps(q.supine_lps, Direction::kSupineToProne);
  EXPECT_LT((shown - q.prone_lps).norm(), 5.0) << "first place maps " << (nearest - q.prone_lps).norm() << " mm off";
  EXPECT_LT(std::abs(reg.candidate_place(q.id, Direction::kSupineToProne).first - q.sigma_mm), 5.0);
  // The benches score truth polyps at the same place (score_truth_pair, map_place): along error < 5 mm
  // on the prone's true centre line (8e52242 scored the first place: hundreds of mm).
  const std::vector<ScanCandidate> ts = truth_list(pair, true);
  const PairFigures f = score_truth_pair(reg, ts, truth_list(pair, false), prone_truth(pair));
  EXPECT_EQ(f.right, f.seen_in_both);
  ASSERT_EQ(f.along_mm.size(), ts.size());  // every polyp in both scans, in the supine list's order
  for (size_t k = 0; k < ts.size(); ++k)
    if (ts[k].id == q.id) EXPECT_LT(f.along_mm[k], 5.0);
}

// Moves the 30 mm stretch of material [from, from + 30) of one scan rigidly so that its wall vertex at material
// (from + 15, 0) lies `gap_mm` from the point p along that vertex's outward normal (the centre of its cross-section
// to it): the wall of another loop touching the finding at p, its nearest stretch vertex that one.
void press_stretch_against(ColonScan& scan, const std::vector<double>& sigma, const std::vector<double>& phi,
                           double from, const Eigen::Vector3d& p, double gap_mm) {
  const size_t touch = vertex_at_material(sigma, phi, from + 15, 0, 20);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int n = 0;
  for (size_t v = 0; v < sigma.size(); ++v)
    if (std::abs(sigma[v] - sigma[touch]) < 1) centre += scan.lps[v], ++n;
  const Eigen::Vector3d normal = (scan.lps[touch] - centre / std::max(1, n)).normalized();
  const Eigen::Vector3d move = p - gap_mm * normal - scan.lps[touch];
  for (size_t v = 0; v < sigma.size(); ++v)
    if (sigma[v] >= from && sigma[v] < from + 30) scan.lps[v] += move;
}

// Two loops touch at a polyp in both scans: in each, a 30 mm stretch of the colon 200 mm or more further on
// lies against the polyp, its wall 1.5 mm farther from the polyp's point than the polyp's own wall (within the
// places' reach: two places on the course in both scans), and the prone finding's point lies 10 mm further
// along its colon than the supine's (the wall slides 1-2 cm between the positions), so the other pass pairs
// cheaper along. The pair is made on the polyp's own wall (the nearest place in both scans) and mapped there;
// without the preference for the nearest places it was made at the other pass (real mask: mapped 225 mm off).
TEST(RegisterPieces, PolypWhereTwoLoopsTouchInBothScansIsPairedOnItsOwnWall) {
  SyntheticPair pair = make_synthetic_pair(long_pair(1));
  SyntheticPolyp& q = pair.polyps[2];
  const double from = free_stretch_beyond(pair, q.sigma_mm);
  ASSERT_TRUE(std::isfinite(from));
  const size_t a = vertex_at_material(pair.prone_sigma, pair.prone_phi, q.sigma_mm, q.phi_rad, 20);
  const size_t b = vertex_at_material(pair.prone_sigma, pair.prone_phi, q.sigma_mm + 10, q.phi_rad, 20);
  q.prone_lps += pair.prone.lps[b] - pair.prone.lps[a];
  for (auto& c : pair.prone.candidates)
    if (c.id == q.id) c.lps = q.prone_lps;
  for (const bool supine : {true, false}) {
    ColonScan& scan = supine ? pair.supine : pair.prone;
    const Eigen::Vector3d& p = supine ? q.supine_lps : q.prone_lps;
    double own = INFINITY;  // the polyp point's distance to its own wall
    for (const auto& v : scan.lps) own = std::min(own, (v - p).norm());
    press_stretch_against(scan, supine ? pair.supine_sigma : pair.prone_sigma, supine ? pair.supine_phi : pair.prone_phi,
                          from, p, own + 1.5);
  }
  const auto run = registered(pair);
  const ColonRegistration& reg = *run;
  const double own_s = reg.locate(q.prone_lps, Direction::kProneToSupine).first;
  for (const auto& [p, d] : {std::pair{q.supine_lps, Direction::kSupineToProne}, std::pair{q.prone_lps, Direction::kProneToSupine}}) {
    const auto places = reg.locations(p, d, 3);
    ASSERT_GE(places.size(), 2u);  // its own wall first, the touching stretch second
    EXPECT_LT(places[0].first, from - 100);
    EXPECT_GT(places[1].first, from - 40);
  }
  const CandidateMatch* m = nullptr;
  for (const auto& x : reg.matching().pairs)
    if (x.supine_id == q.id) m = &x;
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->prone_id, q.id);
  EXPECT_LT(std::abs(m->supine_s_mm - reg.locate(q.supine_lps, Direction::kSupineToProne).first), 1.0);
  EXPECT_LT(std::abs(m->prone_s_mm - own_s), 1.0);
  double s2, t2;  // mapped onto the prone's own wall: 10 mm (the finding's offset) from its place, not 250
  reg.map_coordinates(Direction::kSupineToProne, m->supine_s_mm, m->supine_theta, s2, t2);
  EXPECT_LT(std::abs(s2 - own_s), 20.0);
  EXPECT_LT((reg.map_candidate(q.id, Direction::kSupineToProne) - q.prone_lps).norm(), 25.0);
  expect_every_polyp_paired(score(pair, reg));
}

// The supine keeps the 50 mm of material from 1 mm after a polyp as a short side branch (shorter than a
// colon piece: all its wall laid at its neck's s) bent 200 mm away on the polyp's side, so the common
// profile's centre at the polyp leaves its lumen towards it; the prone keeps that stretch in its band.
// The polyp's angle is measured about its own piece's centre line: within 20 deg of the prone's after
// the map, and it is paired with itself (checked: about the common centre 182 deg apart, unpaired).
TEST(RegisterPieces, PolypWhereTheCommonCentreLeavesItsLumenIsMeasuredAboutItsOwnPiece) {
  SyntheticPair pair = make_synthetic_pair(long_pair(3));
  const SyntheticPolyp& q = pair.polyps[7];
  const double from = q.sigma_mm + 1, to = from + 50;
  for (const auto& o : pair.polyps) ASSERT_TRUE(o.id == q.id || o.sigma_mm < from - 40 || o.sigma_mm > to + 40);
  const size_t w = vertex_at_material(pair.supine_sigma, pair.supine_phi, q.sigma_mm, q.phi_rad, 20);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the polyp's cross-section
  int n = 0;
  for (size_t v = 0; v < pair.supine_sigma.size(); ++v)
    if (std::abs(pair.supine_sigma[v] - pair.supine_sigma[w]) < 1) centre += pair.supine.lps[v], ++n;
  const Eigen::Vector3d away = 200 * (pair.supine.lps[w] - centre / n).normalized();
  for (size_t v = 0; v < pair.supine_sigma.size(); ++v)
    if (pair.supine_sigma[v] >= from && pair.supine_sigma[v] < to) pair.supine.lps[v] += away;
  make_side_branch(pair.supine, pair.supine_sigma, from, to);
  const auto run = registered(pair);
  const ColonRegistration& reg = *run;
  const auto [s, t] = reg.locations(q.supine_lps, Direction::kSupineToProne, 3).front();
  const double pt = reg.locations(q.prone_lps, Direction::kProneToSupine, 3).front().second;
  double s2, t2;
  reg.map_coordinates(Direction::kSupineToProne, s, t, s2, t2);
  EXPECT_LT(std::abs(std::remainder(t2 - pt, 2 * M_PI)) * 180 / M_PI, 20.0);
  bool paired = false;
  for (const auto& m : reg.matching().pairs) paired |= m.supine_id == q.id && m.prone_id == q.id;
  EXPECT_TRUE(paired);
  EXPECT_EQ(score(pair, reg).wrong, 0);
}

}  // namespace
}  // namespace cf
