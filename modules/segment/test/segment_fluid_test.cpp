// Tagged fluid that belongs to the colon wherever it touches it (issue 25): fluid bodies are split at
// the narrow partial-volume bridges where bowel loops touch, and a fluid body is a pool when it meets
// one gas body along one level (a fluid body may meet several gas pockets at different heights).
// Tiny synthetic volumes, 1 mm voxels, no PatientPosition (gravity from the levels: +y).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "colonflat/core/threads.h"

#include "../src/segment_internal.h"
#include "colonflat/segment/segment.h"
#include "segment_volumes.h"

namespace cf {
namespace {

double radial(double y, double z, double cy, double cz) { return std::sqrt((y - cy) * (y - cy) + (z - cz) * (z - cz)); }

SegmentOptions fluid_options() {
  SegmentOptions o = small_volume_options();
  o.min_tagged_volume = 1;
  return o;
}

// The mask of `ct` segmented with fluid_options() and gravity fixed to supine (+y).
MaskImage::Pointer segment_supine(const CtImage* ct, SegmentStats* st) {
  SegmentOptions o = fluid_options();
  o.position = "supine";
  return segment_colon(ct, o, st);
}

// Voxels of the box [x0,x1] x [y0,y1] x [z0,z1] satisfying `inside`, and how many of them the mask holds.
std::pair<std::size_t, std::size_t> kept_in(const MaskImage* m, int x0, int x1, int y0, int y1, int z0, int z1,
                                            const std::function<bool(int, int, int)>& inside) {
  std::size_t n = 0, kept = 0;
  for (int x = x0; x <= x1; ++x)
    for (int y = y0; y <= y1; ++y)
      for (int z = z0; z <= z1; ++z)
        if (inside(x, y, z)) ++n, kept += at(m, x, y, z);
  return {n, kept};
}

// A colon tube (gas over a 750 HU pool) and a small-bowel loop of 380 HU joined to the pool's bottom
// by a 280 HU bridge (LoopOfAnotherLevelBridgedToPoolNotKept).
CtImage::Pointer loop_bridged_to_pool() {
  return make_volume(96, [&](double x, double y, double z) {
    if (x >= 10 && x <= 85 && radial(y, z, 34, 48) < 10) return y < 34 ? -1000.0 : 750.0;  // colon: gas over a pool
    if (x >= 15 && x <= 80 && radial(y, z, 50, 48) < 4) return 380.0;                      // small-bowel loop
    if (x >= 40 && x <= 56 && y >= 40 && y <= 50 && std::abs(z - 48) <= 4) return 280.0;   // bridge
    return kKeep;
  }, 0.6, 10);
}

// A colon tube with dependent fluid along its whole side (level at its axis) and a thinner loop of
// oral contrast (300 HU, radius 5 mm) pressed against the pool's bottom across a 1.5 mm wall (one
// bright body in the 3 x 3 x 3 mean): the pool is kept along the whole side, the loop is not.
TEST(SegmentFluid, SideFluidKeptLoopAcrossWallRejected) {
  auto ct = make_volume(96, [&](double x, double y, double z) {
    if (x >= 10 && x <= 85 && radial(y, z, 34, 48) < 10) return y < 34 ? -1000.0 : 450.0;  // colon: gas over fluid
    if (x >= 20 && x <= 75 && radial(y, z, 50.5, 48) < 5) return 300.0;                   // small-bowel loop
    return kKeep;
  }, 0.6, 10);
  SegmentStats st;
  auto m = segment_colon(ct, fluid_options(), &st);
  const auto pool = kept_in(m, 14, 81, 36, 42, 42, 54, [](int, int y, int z) { return radial(y, z, 34, 48) < 8; });
  EXPECT_EQ(pool.second, pool.first) << st.to_json()["decisions"].dump(1);
  const auto loop = kept_in(m, 22, 73, 47, 54, 45, 51, [](int, int y, int z) { return radial(y, z, 50.5, 48) < 3; });
  EXPECT_GT(loop.first, 500u);
  EXPECT_EQ(loop.second, 0u) << st.to_json()["decisions"].dump(1);
  EXPECT_TRUE(has_reason(st, "rejected", "")) << st.to_json()["decisions"].dump(1);
}

// One colon tube: a gas pocket with a shallow level (4 mm of fluid), a fully tagged middle stretch
// and a second gas pocket whose level lies 10 mm higher (the pockets' gas pressures differ). The
// fluid body meets each gas body along a level of its own: the whole tube is lumen, one segment.
TEST(SegmentFluid, FluidBetweenGasPocketsAtDifferentLevelsKept) {
  auto ct = make_volume(100, [&](double x, double y, double z) {
    if (x < 8 || x > 92 || radial(y, z, 40, 50) >= 9) return kKeep;
    if (x < 35) return y < 44 ? -1000.0 : 450.0;
    if (x > 65) return y < 34 ? -1000.0 : 450.0;
    return 450.0;
  }, 0.6, 10);
  SegmentStats st;
  auto m = segment_colon(ct, fluid_options(), &st);
  const auto tube = kept_in(m, 10, 90, 32, 48, 42, 58, [](int, int y, int z) { return radial(y, z, 40, 50) < 7; });
  EXPECT_GE(double(tube.second), 0.98 * double(tube.first)) << st.to_json()["decisions"].dump(1);
  const auto middle = kept_in(m, 40, 60, 32, 48, 42, 58, [](int, int y, int z) { return radial(y, z, 40, 50) < 7; });
  EXPECT_EQ(middle.second, middle.first);  // the fully tagged middle stretch, whole
  EXPECT_EQ(components(m), 1u);
}

// A colon tube along x whose gas (x 10..45) meets a fully tagged stretch (600 HU, x 46..85) across
// the lumen (supine: no level, kept by its open interface with the gas), and a loop of oral contrast
// (300 HU, radius 6 mm, along z) crossing under the stretch with one voxel of wall at the crossing:
// one bright body in the 3 x 3 x 3 mean, whose two pieces meet at the wall. The stretch is kept
// whole, the loop is not (fails on a84c05a: the two pieces were one candidate, kept together).
TEST(SegmentFluid, LoopPressedOnOpenStretchNotKeptWithIt) {
  auto ct = make_volume(96, [&](double x, double y, double z) {
    if (x >= 10 && x <= 85 && radial(y, z, 34, 48) < 10) return x <= 45 ? -1000.0 : 600.0;  // colon: gas, then fluid
    if (z >= 14 && z <= 82 && radial(x, y, 65, 50) < 6) return 300.0;                      // small-bowel loop
    return kKeep;
  }, 0.3, 10);
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto stretch = kept_in(m, 50, 82, 26, 42, 40, 56, [](int, int y, int z) { return radial(y, z, 34, 48) < 8; });
  EXPECT_EQ(stretch.second, stretch.first) << st.to_json()["decisions"].dump(1);
  EXPECT_TRUE(has_reason(st, "kept", "no wall between")) << st.to_json()["decisions"].dump(1);
  const auto loop = kept_in(m, 60, 70, 45, 55, 16, 80, [](int x, int y, int) { return radial(x, y, 65, 50) < 4; });
  EXPECT_GT(loop.first, 2000u);
  EXPECT_EQ(loop.second, 0u) << st.to_json()["decisions"].dump(1);
}

// Coarse 1.64 mm voxels (the core ball's radius is one voxel): a colon of square cross-section along
// z, gas over a pool (550 HU, level at mid-height, supine), and a loop of oral contrast (300 HU)
// pressed flat against the pool's side with one voxel of wall between. The wall is bright in the
// 3 x 3 x 3 mean, so the cores crossed it and the loop was part of the pool (fails on 8e52242: the
// loop kept whole); a core voxel must be fluid in its own value, so the wall now separates them.
TEST(SegmentFluid, LoopAcrossOneVoxelWallAtCoarsePixelsNotPartOfPool) {
  auto box = [](double x, double y, double z, double x0, double x1, double y0, double y1, double z0, double z1) {
    return x >= x0 && x <= x1 && y >= y0 && y <= y1 && z >= z0 && z <= z1;
  };
  auto ct = make_volume(96, [&](double x, double y, double z) {
    if (box(x, y, z, 28, 52, 28, 52, 10, 85)) return y < 40 ? -1000.0 : 550.0;  // colon: gas over fluid
    if (box(x, y, z, 54, 62, 41, 52, 20, 75)) return 300.0;                     // small-bowel loop
    return kKeep;
  }, 0.6, 10);
  const double sp[3] = {1.64, 1.64, 1.64};
  ct->SetSpacing(sp);
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto pool = kept_in(m, 30, 50, 41, 50, 14, 81, [](int, int, int) { return true; });
  EXPECT_EQ(pool.second, pool.first) << st.to_json()["decisions"].dump(1);
  const auto loop = kept_in(m, 56, 60, 43, 50, 22, 73, [](int, int, int) { return true; });
  EXPECT_GT(loop.first, 1000u);
  EXPECT_EQ(loop.second, 0u) << st.to_json()["decisions"].dump(1);
}

// A gas-filled colon tube whose dependent wall (supine: +y) carries a film of tagged fluid one voxel
// thick (700 HU before the blur, about 200-400 after): too thin to be bright in the 3 x 3 x 3 mean.
// The film's voxels directly below the gas at the bottom of the tube are lumen; the wall under the
// film is not (fails on 8e52242: few film voxels kept).
TEST(SegmentFluid, DependentFilmOneVoxelThickKept) {
  auto film = [](double x, double y, double z) { return x >= 10 && x <= 85 && y > 44 && radial(y, z, 40, 48) >= 9 && radial(y, z, 40, 48) < 10; };
  auto ct = make_volume(96, [&](double x, double y, double z) {
    if (film(x, y, z)) return 700.0;
    if (x >= 10 && x <= 85 && radial(y, z, 40, 48) < 10) return -1000.0;
    return kKeep;
  }, 0.6, 10);
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto f = kept_in(m, 12, 83, 44, 52, 36, 60, [&](int x, int y, int z) {
    return film(x, y, z) && std::abs(z - 48) <= 4 && ct->GetPixel({{std::size_t(x), std::size_t(y - 1), std::size_t(z)}}) < -600;
  });
  EXPECT_GT(f.first, 300u);
  EXPECT_GE(double(f.second), 0.95 * double(f.first)) << f.second << " of " << f.first;
  const auto wall = kept_in(m, 12, 83, 44, 55, 36, 60, [](int, int y, int z) { return y > 44 && radial(y, z, 40, 48) >= 11; });
  EXPECT_EQ(wall.second, 0u);
}

// A supine pool (750 HU) and, under it across 2 mm of wall, a loop of oral contrast (380 HU, radius
// 4 mm) joined to it by a broad 280 HU bridge (session 19, the real prone CT's 395 HU structure): the
// core ball passes through the bridge, so the loop's core was part of the pool's and the loop was
// kept with it. The loop's fluid is under the midpoint between the pool's level and fluid-threshold
// and reaches the pool only through the darker bridge: it is another lumen and is not kept, while
// the pool stays whole. Fails without the other-level rule (the loop kept with the pool).
TEST(SegmentFluid, LoopOfAnotherLevelBridgedToPoolNotKept) {
  auto ct = loop_bridged_to_pool();
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto pool = kept_in(m, 14, 81, 36, 43, 40, 56, [](int, int y, int z) { return radial(y, z, 34, 48) < 8.5; });
  EXPECT_EQ(pool.second, pool.first) << st.to_json()["decisions"].dump(1);
  const auto loop = kept_in(m, 18, 77, 47, 53, 45, 51, [](int x, int y, int z) { return (x < 36 || x > 60) && radial(y, z, 50, 48) < 2.5; });
  EXPECT_GT(loop.first, 500u);
  EXPECT_EQ(loop.second, 0u) << st.to_json()["decisions"].dump(1);
}

// Session 20, a sloping level: a gas tube whose 600 HU fluid meets the gas along a plane tilted 25
// degrees from the image axes, blurred (sigma 1 mm: a partial-volume layer of -600..+200 HU). Every voxel
// within 1.5 mm of the level and inside the lumen (1.5 mm from the wall) is lumen, and no wall voxel (1.5 mm
// beyond the tube's radius) is. Without the interface layer the layer stays out (a membrane).
TEST(SegmentFluid, TiltedLevelLayerKeptWallUntouched) {
  const double tilt = std::tan(25.0 * 3.14159265358979 / 180.0), cosine = std::cos(25.0 * 3.14159265358979 / 180.0);
  auto level = [&](double y, double z) { return (y - 42 - tilt * (z - 40)) * cosine; };  // signed distance (mm), fluid > 0
  auto ct = make_volume(80, [&](double x, double y, double z) {
    if (x < 8 || x > 72 || radial(y, z, 40, 40) >= 14) return kKeep;
    return level(y, z) > 0 ? 600.0 : -1000.0;
  }, 1.0, 10);
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto layer = kept_in(m, 14, 66, 20, 60, 20, 60, [&](int, int y, int z) {
    return std::abs(level(y, z)) <= 1.5 && radial(y, z, 40, 40) < 12.5;
  });
  EXPECT_GT(layer.first, 1000u);
  EXPECT_EQ(layer.second, layer.first) << layer.first - layer.second << " layer voxels left out";
  const auto wall = kept_in(m, 14, 66, 20, 60, 20, 60, [](int, int y, int z) { return radial(y, z, 40, 40) >= 15.5; });
  EXPECT_EQ(wall.second, 0u);
  EXPECT_EQ(components(m), 1u);
}

// Session 20, gas rests on fluid: two gas tubes stacked along gravity (supine, +y down) with one voxel
// of wall between them, the upper one's dependent fluid (600 HU, its surface tilted 25 degrees: no level
// pool, so step 4 marks no layer; kept as one lumen with its gas) lying on that wall. Along gravity the
// lower tube's gas lies below that fluid across the wall with an open-looking profile (the blur mixes
// the 1 mm wall away); the wall stays out and the two lumens stay apart. With the interface layer
// filled in either order along gravity, the wall is taken and the lumens join (one component).
TEST(SegmentFluid, WallUnderFluidAboveAnotherLoopsGasKept) {
  const double tilt = std::tan(25.0 * 3.14159265358979 / 180.0);
  auto ct = make_volume(80, [&](double x, double y, double z) {
    if (x < 10 || x > 70) return kKeep;
    if (radial(y, z, 30, 40) < 9.5) return y > 33 + tilt * (z - 40) ? 600.0 : -1000.0;  // upper tube: gas over fluid
    if (radial(y, z, 52, 40) < 10.5) return -1000.0;                      // lower tube: gas, top at y 41.5
    return kKeep;
  }, 0.6, 10);
  const double sp[3] = {0.75, 0.75, 0.75};  // the wall: 2 voxels, 1.5 mm
  ct->SetSpacing(sp);
  SegmentStats st;
  auto m = segment_supine(ct, &st);
  const auto wall = kept_in(m, 14, 66, 39, 42, 36, 44, [](int, int y, int z) {
    return radial(y, z, 30, 40) >= 9.5 && radial(y, z, 52, 40) >= 10.5;
  });
  EXPECT_GT(wall.first, 50u);
  EXPECT_EQ(wall.second, 0u);
  EXPECT_TRUE(at(m, 40, 37, 40) && at(m, 40, 45, 40));  // both lumens kept
  EXPECT_EQ(components(m), 2u);
}

// A dense bright blob (900 HU, like a vertebral body) 3 mm beside the colon's gas: it has no level
// under gas and does not continue the colon; it is not kept.
TEST(SegmentFluid, BoneLikeBlobsRejected) {
  auto ct = make_volume(96, [&](double x, double y, double z) {
    if (x >= 10 && x <= 85 && radial(y, z, 40, 40) < 9) return -1000.0;       // gas-filled colon
    if (std::sqrt((x - 48) * (x - 48) + (y - 40) * (y - 40) + (z - 61) * (z - 61)) < 9) return 900.0;  // blob beside
    return kKeep;
  }, 0.6, 10);
  SegmentStats st;
  auto m = segment_colon(ct, fluid_options(), &st);
  EXPECT_TRUE(at(m, 48, 40, 40));
  const auto blob = kept_in(m, 40, 56, 32, 48, 54, 68, [](int x, int y, int z) {
    return std::sqrt((x - 48) * (x - 48) + (y - 40) * (y - 40) + (z - 61) * (z - 61)) < 7;
  });
  EXPECT_GT(blob.first, 1000u);
  EXPECT_EQ(blob.second, 0u) << st.to_json()["decisions"].dump(1);
}

// The tagged-fluid steps (ball erosion, pieces grown, the other level's plateau, candidate bodies)
// and the passes split over the workers (box dilation and erosion, voxel passes, graph-cut slabs)
// give the same mask byte for byte for 1, 2 and 3 threads, on a volume where every one of them acts.
TEST(SegmentFluid, SameMaskForOneTwoAndThreeThreads) {
  auto ct = loop_bridged_to_pool();
  std::vector<MaskImage::Pointer> masks;
  for (int t : {1, 2, 3}) {
    set_thread_count(t);
    SegmentStats st;
    masks.push_back(segment_supine(ct, &st));
  }
  set_thread_count(0);
  const std::size_t n = masks[0]->GetLargestPossibleRegion().GetNumberOfPixels();
  std::size_t lumen = 0;
  for (std::size_t q = 0; q < n; ++q) lumen += masks[0]->GetBufferPointer()[q];
  EXPECT_GT(lumen, 10000u);  // the colon is there (pi x 10^2 x 76 mm: about 23 900 voxels)
  for (std::size_t i = 1; i < masks.size(); ++i) EXPECT_EQ(0, std::memcmp(masks[0]->GetBufferPointer(), masks[i]->GetBufferPointer(), n)) << i + 1 << " threads";
}

}  // namespace
namespace segment_detail {
namespace {

// The contact heights gathered the obvious way: voxels in raster order, the gas body found by
// stepping from the contact towards the gas side along the axis, at most wvox + 1 voxels.
void serial_heights(const LevelGatherInput& in, LevelHeights out[2]) {
  const Dims& d = *in.d;
  for (std::size_t k = 0; k < d.n[2]; ++k)
    for (std::size_t j = 0; j < d.n[1]; ++j)
      for (std::size_t i = 0; i < d.n[0]; ++i) {
        const std::size_t q = d.idx(i, j, k);
        if (!in.contact[q]) continue;
        long c[3] = {long(i), long(j), long(k)};
        const int side = in.contact[q] - 1;
        std::uint32_t g = 0;
        for (int t = 1; t <= in.wvox + 1 && !g; ++t) {
          c[in.axis] += side == 0 ? -1 : 1;
          if (c[in.axis] < 0 || c[in.axis] >= long(d.n[in.axis])) break;
          const std::size_t r = d.idx(std::size_t(c[0]), std::size_t(c[1]), std::size_t(c[2]));
          if (in.lab[r] == 1) g = in.gas->at(r);
        }
        out[side][{in.fluid_label[q], g}].push_back(float(double(in.axis == 0 ? i : in.axis == 1 ? j : k) * d.sp[in.axis]));
      }
}

// The level-contact gather split into z-slabs over the workers uses one slab per thread and gives
// every (fluid piece, gas body) list exactly as the serial raster scan does (same heights, same
// order), along each axis, for 1, 2 and 3 threads, on a random volume with many keys.
TEST(SegmentFluid, SlabSplitLevelGatherEqualsSerialScan) {
  const std::size_t n[3] = {13, 9, 8};
  const double sp[3] = {0.7, 0.8, 1.5};
  const Dims d = make_dims(n, sp);
  std::mt19937 rng(7);
  Bytes lab(d.total), contact(d.total), gas(d.total);
  std::vector<std::uint32_t> fluid(d.total);
  for (std::size_t q = 0; q < d.total; ++q) {
    gas[q] = lab[q] = rng() % 10 < 3;  // 1: gas
    contact[q] = lab[q] ? 0 : std::uint8_t(rng() % 3);
    fluid[q] = 1 + rng() % 4;
  }
  const RunLookup gl(component_runs(gas.data(), d));
  for (int axis = 0; axis < 3; ++axis) {
    const LevelGatherInput in{&d, axis, 1, contact.data(), lab.data(), fluid.data(), &gl};
    LevelHeights ref[2];
    serial_heights(in, ref);
    std::size_t with_gas = 0;
    for (const auto& kv : ref[0]) with_gas += kv.first.second != 0;
    EXPECT_GT(with_gas, 4u) << "axis " << axis;  // several gas bodies found, not only "none"
    for (int t : {1, 2, 3}) {
      set_thread_count(t);
      LevelHeights got[2];
      EXPECT_EQ(gather_level_heights(in, got), std::size_t(t)) << "axis " << axis << ", " << t << " threads";
      EXPECT_TRUE(got[0] == ref[0] && got[1] == ref[1]) << "axis " << axis << ", " << t << " threads";
    }
  }
  set_thread_count(0);
}

}  // namespace
}  // namespace segment_detail
}  // namespace cf
