// Open interfaces (segment_open.cpp, issue 25): tagged fluid that meets a colon segment's gas along
// its side with no wall between is the same lumen and is kept; the same fluid behind a 3 mm wall
// (two bowels pressed together) is not; likewise gas meeting a kept stretch's fluid (session 13).
// Tiny synthetic volumes, 1 mm voxels, supine.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "colonflat/core/threads.h"
#include "colonflat/segment/segment.h"
#include "segment_volumes.h"

namespace cf {
namespace {

// A lumen of stadium cross-section (two 9 mm tubes 18 mm apart in z, joined) along x: gas in the
// half z < 44 over x 10..85, tagged fluid (`fluid_hu`) in the half z >= 44 + wall over x 20..75, so
// the fluid lies along the gas segment's side and meets it across a vertical surface (no level),
// as where a fully tagged stretch is cut beside a segment; `wall_mm` of soft tissue between them.
CtImage::Pointer side_fluid_volume(double wall_mm, double fluid_hu) {
  return make_volume(96, [=](double x, double y, double z) {
    const double dy = y - 40;
    const bool lumen = std::abs(dy) < 9 && (z >= 36 ? (z <= 54 || dy * dy + (z - 54) * (z - 54) < 81) : dy * dy + (z - 36) * (z - 36) < 81);
    if (!lumen) return kKeep;
    if (z < 44 && x >= 10 && x <= 85) return -1000.0;
    if (z >= 44 + wall_mm && x >= 20 && x <= 75) return fluid_hu;
    return kKeep;
  }, 0.6, 10);
}

// Fluid voxels of the side body (away from its edges) and how many of them the mask holds.
std::pair<std::size_t, std::size_t> side_fluid_kept(const MaskImage* m, double wall_mm) {
  std::size_t n = 0, kept = 0;
  for (int x = 24; x <= 71; ++x)
    for (int y = 33; y <= 47; ++y)
      for (int z = int(std::ceil(47 + wall_mm)); z <= 58; ++z) ++n, kept += at(m, x, y, z);
  return {n, kept};
}

SegmentOptions open_options() {
  SegmentOptions o = small_volume_options();
  o.min_tagged_volume = 1;
  o.position = "supine";  // gravity +y: the vertical interface is no level (the levels alone would take +z)
  return o;
}

// Fluid along the gas segment's side with no wall between is kept whole, with its reason, for oral-
// contrast and tagging densities; the linking rules alone reject it (its contact is the segment's side).
TEST(SegmentOpen, FluidMeetingGasSideWithoutWallKept) {
  for (double hu : {300.0, 700.0}) {
    SCOPED_TRACE(hu);
    SegmentStats st;
    auto m = segment_colon(side_fluid_volume(0, hu), open_options(), &st);
    const auto f = side_fluid_kept(m, 0);
    EXPECT_GT(f.first, 5000u);
    EXPECT_EQ(f.second, f.first) << st.to_json()["decisions"].dump(1);
    EXPECT_TRUE(has_reason(st, "kept", "no wall between")) << st.to_json()["decisions"].dump(1);
    EXPECT_TRUE(at(m, 48, 40, 36));  // the gas segment
  }
}

// The same fluid behind a 3 mm soft-tissue wall (a loop pressed against the colon) is not kept.
TEST(SegmentOpen, FluidBehindWallRejected) {
  for (double hu : {300.0, 700.0}) {
    SCOPED_TRACE(hu);
    SegmentStats st;
    auto m = segment_colon(side_fluid_volume(3, hu), open_options(), &st);
    const auto f = side_fluid_kept(m, 3);
    EXPECT_GT(f.first, 4000u);
    EXPECT_EQ(f.second, 0u) << st.to_json()["decisions"].dump(1);
    EXPECT_FALSE(has_reason(st, "kept", "no wall between"));
    EXPECT_TRUE(at(m, 48, 40, 36));
  }
}

// Gas meeting a kept fully tagged stretch along its side (session 13): a gas tube (radius 8 mm, x
// 8..38) continued across a 7 mm tissue neck by a tube completely filled with tagged fluid (600 HU,
// x 45..90: a fully tagged stretch, kept by the linking rules), and a small gas body (a tube of
// radius 7 mm, x 66..82, 13 mm above the stretch's axis) lying along the stretch's side, `wall_mm`
// of soft tissue between them (0: the gas meets the fluid directly).
CtImage::Pointer gas_beside_stretch_volume(double wall_mm) {
  const auto tube = [](double y, double z, double cz) { return std::hypot(y - 50, z - cz); };
  return make_volume(100, [=](double x, double y, double z) {
    if (tube(y, z, 50) < 8) return x >= 8 && x <= 38 ? -1000.0 : (x >= 45 && x <= 90 ? 600.0 : kKeep);
    if (x >= 66 && x <= 82 && tube(y, z, 63) < 7 && tube(y, z, 50) >= 8 + wall_mm) return -1000.0;
    return kKeep;
  }, 0.6, 10);
}

// The gas tube is the only segment (the small gas body, about 2.5 mL, is below --min-segment-fraction
// of it, so it is a candidate, as a collapsed piece of colon gas refused there would be).
SegmentOptions gas_beside_stretch_options() {
  SegmentOptions o = open_options();
  o.min_segment_fraction = 0.9;
  return o;
}

// Gas voxels of the small gas body (away from its edges) and how many of them the mask holds.
std::pair<std::size_t, std::size_t> side_gas_kept(const MaskImage* m) {
  std::size_t n = 0, kept = 0;
  for (int x = 69; x <= 79; ++x)
    for (int y = 47; y <= 53; ++y)
      for (int z = 62; z <= 67; ++z) ++n, kept += at(m, x, y, z);
  return {n, kept};
}

// Gas meeting a kept stretch's fluid with no wall between is that lumen's gas (the open interface is
// one lumen whichever side was kept first) and is kept with its reason; without the rule it is "too
// small near the link" (its contact is the stretch's side) and none of it is kept.
TEST(SegmentOpen, GasMeetingKeptStretchWithoutWallKept) {
  SegmentStats st;
  auto m = segment_colon(gas_beside_stretch_volume(0), gas_beside_stretch_options(), &st);
  EXPECT_TRUE(at(m, 60, 50, 50)) << st.to_json()["decisions"].dump(1);  // the stretch
  EXPECT_TRUE(at(m, 20, 50, 50));                                      // the gas tube
  const auto g = side_gas_kept(m);
  EXPECT_EQ(g.second, g.first) << st.to_json()["decisions"].dump(1);
  EXPECT_TRUE(has_reason(st, "kept", "colon gas: meets a colon body's fluid with no wall between"));
}

// The same gas behind a 3 mm soft-tissue wall (another bowel pressed against the stretch) is not kept.
TEST(SegmentOpen, GasBehindWallFromKeptStretchRejected) {
  SegmentStats st;
  auto m = segment_colon(gas_beside_stretch_volume(3), gas_beside_stretch_options(), &st);
  EXPECT_TRUE(at(m, 60, 50, 50)) << st.to_json()["decisions"].dump(1);
  EXPECT_EQ(side_gas_kept(m).second, 0u) << st.to_json()["decisions"].dump(1);
  EXPECT_FALSE(has_reason(st, "kept", "colon gas"));
}

// The open-interface scan runs one chunk of lines per thread: the same mask for 1 and 2 threads.
TEST(SegmentOpen, SameMaskForOneAndTwoThreads) {
  const CtImage::Pointer ct = side_fluid_volume(0, 500);
  std::vector<MaskImage::Pointer> masks;
  for (int t : {1, 2}) {
    set_thread_count(t);
    masks.push_back(segment_colon(ct, open_options(), nullptr));
  }
  set_thread_count(0);
  const std::size_t n = masks[0]->GetLargestPossibleRegion().GetNumberOfPixels();
  EXPECT_EQ(0, std::memcmp(masks[0]->GetBufferPointer(), masks[1]->GetBufferPointer(), n));
  EXPECT_GT(count(masks[0]), 10000u);
}

}  // namespace
}  // namespace cf
