// Helpers of placing one colon piece against the reference (src/piece_split.h): which of a piece's
// per-bin projections are kept as running forward along the common axis; a piece laid along a branch.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "../src/piece_split.h"

namespace cf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kBin = 5.0;  // mm per bin

double own_mm(size_t k) { return (double(k) + 0.5) * kBin; }

// Common s of bin k from its offset (the convention of keep_forward_run's header).
double common_s(const std::vector<double>& offset, size_t k, bool flipped) {
  return flipped ? offset[k] - own_mm(k) : offset[k] + own_mm(k);
}

void expect_forward(const std::vector<double>& offset, bool flipped) {
  double last = flipped ? INFINITY : -INFINITY;
  for (size_t k = 0; k < offset.size(); ++k) {
    if (std::isnan(offset[k])) continue;
    const double s = common_s(offset, k, flipped);
    if (flipped) EXPECT_LE(s, last) << "bin " << k; else EXPECT_GE(s, last) << "bin " << k;
    last = s;
  }
}

// A piece lying along the reference (s = 100 mm + own mm) whose bins 10-12 project onto a
// neighbouring loop 800 mm further on: only those three lose their offset, bins without one stay so.
TEST(PieceSplit, ProjectionsOntoANeighbouringLoopAreDropped) {
  std::vector<double> offset(40, 100.0);
  for (size_t k : {10, 11, 12}) offset[k] = 900.0 - own_mm(k);
  offset[30] = kNaN;
  keep_forward_run(offset, false, kBin);
  for (size_t k = 0; k < offset.size(); ++k) {
    if (k == 10 || k == 11 || k == 12 || k == 30) EXPECT_TRUE(std::isnan(offset[k])) << "bin " << k;
    else EXPECT_DOUBLE_EQ(offset[k], 100.0) << "bin " << k;
  }
  expect_forward(offset, false);
}

// A flipped piece (it runs against the common axis, s = 500 mm - own mm) with two bins projected onto
// a loop at s = 900 mm: those two go, every other bin keeps its offset and s falls along the piece.
TEST(PieceSplit, FlippedPieceKeepsItsBackwardRun) {
  std::vector<double> offset(40, 500.0);
  for (size_t k : {20, 21}) offset[k] = 900.0 + own_mm(k);
  keep_forward_run(offset, true, kBin);
  for (size_t k = 0; k < offset.size(); ++k) {
    if (k == 20 || k == 21) EXPECT_TRUE(std::isnan(offset[k])) << "bin " << k;
    else EXPECT_DOUBLE_EQ(offset[k], 500.0) << "bin " << k;
  }
  expect_forward(offset, true);
}

// Projections that already run forward (with small wobbles that keep s non-decreasing) are all kept.
TEST(PieceSplit, ForwardProjectionsAreUntouched) {
  std::vector<double> offset(25);
  for (size_t k = 0; k < offset.size(); ++k) offset[k] = 30.0 + ((k % 3 == 0) ? 1.0 : 0.0);
  const std::vector<double> before = offset;
  keep_forward_run(offset, false, kBin);
  for (size_t k = 0; k < offset.size(); ++k) EXPECT_DOUBLE_EQ(offset[k], before[k]) << "bin " << k;
}

// A reference side branch of 208 mm (its own mm running towards its neck, seated at s 730) along a
// straight line, and a 182 mm piece of the other scan over the same stretch whose tip half bends 20 mm
// away (as two centre lines do into a tip's cap): every projection on the branch, its ends within reach
// of the branch's neck and tip, it is laid from s 730 to 938 in proportion (own 91 mm -> 834 mm); the same
// piece with its tip 60 mm beyond reach, or with one projection on another reference piece, is not.
TEST(PieceSplit, PieceAlongABranchIsLaidFromNeckToTip) {
  ColonPiece band, branch, piece;
  band.length_mm = 1000, band.centre.assign(500, Eigen::Vector3d(0, 0, 0));
  branch.branch = true, branch.flipped = true, branch.length_mm = 208, branch.start_mm = 730, branch.bin_mm = 2;
  for (int k = 0; k < 104; ++k) branch.centre.push_back({0, 208 - (k + 0.5) * 2, 0});  // neck at y = 0
  piece.length_mm = 182, piece.bin_mm = 2;
  for (int k = 0; k < 91; ++k) {
    const double y = (k + 0.5) * 2 * 208 / 182;
    piece.centre.push_back({y > 104 ? 20 * (y - 104) / 104 : 0, y, 0});
  }
  const std::vector<ColonPiece> ref = {band, branch};
  const std::vector<int> on_branch(91, 1);
  ColonPiece laid = piece;
  ASSERT_TRUE(lay_along_branch(laid, on_branch, ref, Eigen::Vector3d::Zero(), 50));
  ASSERT_EQ(laid.s_bin.size(), 91u);
  EXPECT_NEAR(laid.s_of(0), 730, 1.5);
  EXPECT_NEAR(laid.s_of(91), 730 + 91 * 208.0 / 182, 1e-6);
  EXPECT_NEAR(laid.s_of(182), 938, 1.5);
  ColonPiece far = piece;
  far.centre.back().x() += 60;
  EXPECT_FALSE(lay_along_branch(far, on_branch, ref, Eigen::Vector3d::Zero(), 50));
  std::vector<int> mixed = on_branch;
  mixed[40] = 0;
  EXPECT_FALSE(lay_along_branch(piece, mixed, ref, Eigen::Vector3d::Zero(), 50));
  EXPECT_TRUE(piece.s_bin.empty());
}

}  // namespace
}  // namespace cf
