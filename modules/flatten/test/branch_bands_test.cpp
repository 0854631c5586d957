// Branch bands (branch_bands.cpp): a colon that reaches flatten in pieces (a whole colon stretch
// cut off as a side branch) is flattened as well as a whole one: the long branch gets the colon
// band's axis and band length, the branches are flattened side by side with the same bits.
#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "../src/branch_bands.h"
#include "colonflat/flatten/flatten.h"
#include "flatten_shapes.h"

namespace cf {
namespace {

// A tube whose conformal rectangle is much longer than its girth, with a centreline that agrees, is
// a colon stretch; a pouch (about as long as it is wide), a band of no girth and a band whose
// centreline disagrees with its conformal length (made up by the level sets) are not.
TEST(BranchBands, LongTubeIsAColonStretchAndAPouchIsNot) {
  EXPECT_TRUE(flat_detail::colon_stretch(400, 420, 100, 1000));
  EXPECT_TRUE(flat_detail::colon_stretch(150, 160, 80, 1000));
  EXPECT_FALSE(flat_detail::colon_stretch(110, 120, 135, 1000));  // a pouch
  EXPECT_FALSE(flat_detail::colon_stretch(50, 60, 0, 1000));
  EXPECT_FALSE(flat_detail::colon_stretch(624, 300, 72, 1000));  // a centreline the level sets made up
}

// A severed colon: a tube (radius 12 mm, 400 mm) with a blind limb of radius 10 mm and 180 mm from
// its middle (a colon stretch hanging off a contact, ~3 girths long; the tube's ends stay the
// farthest apart, so the tube is the colon band). The limb is cut off as a branch and, as a
// colon stretch, gets the colon band's band length (its centreline length within the band's 8 %
// slack, not the conformal length a pouch keeps); the whole map shows >= 99.5 % of the wall with
// area ratio p05 >= 0.2 (the floors of issue 26), nothing flipped, and 1 and 2 threads give the
// same map bit for bit (the branches are flattened side by side).
TEST(BranchBands, SeveredColonsLongBranchIsFlattenedAsABand) {
  const TriangleList mesh = test_shapes::tube_with_limb(10.0, 180.0, 400.0);
  const FlatMap f = test_shapes::flatten_with_threads(mesh, 2);
  ASSERT_GE(f.segments.size(), 2u);
  const FlatSegment& limb = f.segments[1];
  EXPECT_EQ(limb.kind, "branch");
  EXPECT_GT(limb.centreline_length, 120.0);
  EXPECT_NEAR(limb.length, limb.centreline_length, 0.08 * limb.centreline_length + 1e-9);
  EXPECT_GE(f.coverage.fraction, 0.995);
  EXPECT_GE(f.stats.area_p05, 0.2);
  EXPECT_EQ(f.stats.flipped, 0u);
  const FlatMap one = test_shapes::flatten_with_threads(mesh, 1);
  ASSERT_EQ(one.uv.size(), f.uv.size());
  EXPECT_EQ(test_shapes::uv_differences(one, f), 0u);
  EXPECT_EQ(one.triangles, f.triangles);
}

// A piece its band cannot flatten (the band throws) is left out, its area not counted as placed,
// and with COLONFLAT_FLATTEN_DEBUG set one line says which piece and why (a patch's slit that the
// band's boundary clean-up unzipped was lost this way without a word, session 32 "grown").
TEST(BranchBands, PieceThatCannotBeFlattenedIsLeftOutAndReported) {
  flat_detail::BranchPiece piece;
  piece.surface.p = {flat_detail::V3(0, 0, 0), flat_detail::V3(1, 0, 0), flat_detail::V3(0, 1, 0)};
  piece.surface.t = {{0, 1, 2}};
  piece.loops = 2;
  const flat_detail::FlattenBand band = [](const flat_detail::BranchPiece&) -> std::vector<flat_detail::SegmentWork> {
    throw std::runtime_error("not tube-like");
  };
  double placed = 0;
  ::setenv("COLONFLAT_FLATTEN_DEBUG", "1", 1);
  testing::internal::CaptureStderr();
  const auto works = flat_detail::flatten_branch_pieces({piece}, band, placed);
  const std::string err = testing::internal::GetCapturedStderr();
  ::unsetenv("COLONFLAT_FLATTEN_DEBUG");
  EXPECT_TRUE(works.empty());
  EXPECT_EQ(placed, 0.0);
  EXPECT_NE(err.find("branch of 1 faces (2 open ends) not flattened: not tube-like"), std::string::npos) << err;
}

// A slit patch (its unslit disk kept) whose band is a disk band places the disk's whole area (the
// faces its slit's rounded ends dropped included: the disk band shows them); a tube band places only
// the slit surface's area (those faces are wall not shown).
TEST(BranchBands, DiskBandPlacesTheUnslitDisksArea) {
  flat_detail::BranchPiece piece;
  piece.disk.p = {flat_detail::V3(0, 0, 0), flat_detail::V3(2, 0, 0), flat_detail::V3(0, 2, 0), flat_detail::V3(2, 2, 0)};
  piece.disk.t = {{0, 1, 2}, {1, 3, 2}};  // 4 mm2
  piece.surface.p = piece.disk.p;
  piece.surface.t = {{0, 1, 2}};  // 2 mm2
  piece.loops = 2;
  for (const char* map : {"disk", "area-balanced"}) {
    const flat_detail::FlattenBand band = [map](const flat_detail::BranchPiece&) {
      std::vector<flat_detail::SegmentWork> w(1);
      w[0].seg.map = map;
      return w;
    };
    double placed = 0;
    flat_detail::flatten_branch_pieces({piece}, band, placed);
    EXPECT_DOUBLE_EQ(placed, std::string(map) == "disk" ? 4.0 : 2.0) << map;
  }
}

}  // namespace
}  // namespace cf
