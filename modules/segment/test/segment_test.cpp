// Colon segmentation: analytic synthetic volumes (gas body, fluid pool with a partial-volume layer,
// lungs, outside air, bone, small gas), bad input, options, the small phantom (Dice, polyps, leaks),
// DICOM and NRRD forms giving the same mask, and the `colonflat segment` command.
#include <gtest/gtest.h>

#include <itkConnectedComponentImageFilter.h>
#include <itkSmoothingRecursiveGaussianImageFilter.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <sstream>

#include "colonflat/core/stage.h"
#include "colonflat/testing/errors.h"
#include "colonflat/core/threads.h"
#include "colonflat/testing/small_phantom.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/segment/segment.h"
#include "colonflat/segment/segment_stage.h"
#include "colonflat/testing/stage_command.h"
#include "colonflat/testing/temp_dir.h"
#include "segment_volumes.h"
#include "../src/segment_internal.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A gas ellipsoid (the "colon", 20 mL) in tissue is segmented at its analytic boundary; outside air
// touching the border is not lumen.
TEST(SegmentSynthetic, GasBodyAnalyticBoundary) {
  const double cx = 32, cy = 32, cz = 32, r = 16.5;
  auto ct = make_volume(64, [&](double x, double y, double z) {
    const double d = std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz));
    return d < r ? -1000.0 : kKeep;
  }, 0.6, 15);
  SegmentStats st;
  auto m = segment_colon(ct, small_volume_options(), &st);
  std::size_t wrong = 0, truth = 0;
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        const bool in = std::sqrt((i - cx) * (i - cx) + (j - cy) * (j - cy) + (k - cz) * (k - cz)) < r;
        truth += in;
        wrong += in != at(m, i, j, k);
      }
  EXPECT_LT(double(wrong) / double(truth), 0.01) << wrong << " of " << truth;
  EXPECT_FALSE(at(m, 0, 0, 0));
  EXPECT_FALSE(at(m, 2, 30, 30));
  EXPECT_EQ(st.segments, 1);
  EXPECT_NEAR(st.lumen_volume_ml, 4.0 / 3.0 * M_PI * r * r * r / 1000.0, 0.3);
  EXPECT_NEAR(st.air_hu, -1000, 30);
  EXPECT_NEAR(st.tissue_hu, 40, 30);
  EXPECT_GT(st.band_voxels, 0u);
}

// A horizontal air/fluid level (fluid +450 HU on the dependent, posterior side) with a blurred
// partial-volume layer: the whole lumen is one segment and the layer is not a wall.
TEST(SegmentSynthetic, AirFluidLayerIsNotAWall) {
  const double cx = 32, cz = 32, r = 14, level_y = 36;  // y grows posteriorly (LPS): fluid for y > 36
  auto ct = make_volume(64, [&](double x, double y, double z) {
    // A tube along y... no: a tube along z with circular cross-section in x-y, from z 8 to 56.
    const double d = std::sqrt((x - cx) * (x - cx) + (y - 32) * (y - 32));
    if (d >= r || z < 8 || z > 56) return kKeep;
    return y > level_y ? 450.0 : -1000.0;
  }, 1.0, 10);
  SegmentStats st;
  auto m = segment_colon(ct, small_volume_options(), &st);
  EXPECT_EQ(st.segments, 1);
  EXPECT_EQ(components(m), 1u);
  EXPECT_GT(st.fluid_volume_ml, 1.0);
  // Every voxel on the interface rows inside the tube (away from the wall) is lumen.
  for (int z = 12; z <= 52; z += 4)
    for (int y = int(level_y) - 3; y <= int(level_y) + 3; ++y)
      for (int x = int(cx) - 8; x <= int(cx) + 8; ++x) {
        if (std::sqrt((x - cx) * (x - cx) + (y - 32.0) * (y - 32.0)) > r - 3) continue;
        EXPECT_TRUE(at(m, x, y, z)) << x << " " << y << " " << z;
      }
  // The tube wall stays wall (2 voxels outside the tube).
  EXPECT_FALSE(at(m, int(cx + r + 2), 32, 32));
  EXPECT_FALSE(at(m, int(cx), int(32 + r + 2), 32));  // below the fluid
}

// Gas touching the superior face (lungs) and a small gas bubble are removed; bright bone that
// touches no gas is not taken for tagged fluid.
TEST(SegmentSynthetic, LungsSmallGasAndBoneRemoved) {
  auto ct = make_volume(64, [&](double x, double y, double z) {
    const double dc = std::sqrt((x - 32) * (x - 32) + (y - 24) * (y - 24) + (z - 24) * (z - 24));
    if (dc < 12) return -1000.0;                                   // colon (7 mL)
    if (z > 54 && std::abs(x - 32) < 20 && std::abs(y - 32) < 20) return -850.0;  // lung base at the top
    const double db = std::sqrt((x - 48) * (x - 48) + (y - 48) * (y - 48) + (z - 20) * (z - 20));
    if (db < 3) return -1000.0;                                    // small gas bubble (0.1 mL)
    if (std::abs(x - 32) < 5 && y > 44 && y < 54 && z < 50) return 500.0;  // bone column
    return kKeep;
  });
  SegmentOptions o = small_volume_options();
  SegmentStats st;
  auto m = segment_colon(ct, o, &st);
  EXPECT_TRUE(at(m, 32, 24, 24));
  EXPECT_FALSE(at(m, 32, 32, 60));  // lung
  EXPECT_FALSE(at(m, 48, 48, 20));  // bubble
  EXPECT_FALSE(at(m, 32, 49, 30));  // bone
  EXPECT_EQ(st.segments, 1);
  EXPECT_EQ(st.fluid_volume_ml, 0.0);
}

// Two separate gas bodies of similar size are both kept (a collapsed colon); max-segments 1 keeps one.
TEST(SegmentSynthetic, SeveralSegmentsKept) {
  auto ct = make_volume(64, [&](double x, double y, double z) {
    const double a = std::sqrt((x - 20) * (x - 20) + (y - 32) * (y - 32) + (z - 32) * (z - 32));
    const double b = std::sqrt((x - 44) * (x - 44) + (y - 32) * (y - 32) + (z - 32) * (z - 32));
    return (a < 9 || b < 8) ? -1000.0 : kKeep;
  });
  SegmentOptions o = small_volume_options();
  SegmentStats st;
  auto m = segment_colon(ct, o, &st);
  EXPECT_EQ(st.segments, 2);
  ASSERT_EQ(st.segment_volumes_ml.size(), 2u);
  EXPECT_GT(st.segment_volumes_ml[0], st.segment_volumes_ml[1]);
  o.max_segments = 1;
  auto m1 = segment_colon(ct, o, &st);
  EXPECT_EQ(st.segments, 1);
  EXPECT_TRUE(at(m1, 20, 32, 32));
  EXPECT_FALSE(at(m1, 44, 32, 32));
}

// The graph cut removes isolated noisy voxels that thresholds alone would keep or miss.
TEST(SegmentSynthetic, GraphCutAtLeastAsGoodAsThresholds) {
  const double r = 15;
  auto truth_at = [&](int i, int j, int k) { return std::sqrt((i - 32.0) * (i - 32.0) + (j - 32.0) * (j - 32.0) + (k - 32.0) * (k - 32.0)) < r; };
  auto ct = make_volume(64, [&](double x, double y, double z) { return truth_at(int(x), int(y), int(z)) ? -1000.0 : kKeep; }, 0.8, 120);
  SegmentOptions o = small_volume_options();
  auto gc = segment_colon(ct, o);
  o.graph_cut = false;
  auto th = segment_colon(ct, o);
  std::size_t e_gc = 0, e_th = 0;
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        e_gc += truth_at(i, j, k) != at(gc, i, j, k);
        e_th += truth_at(i, j, k) != at(th, i, j, k);
      }
  EXPECT_LE(e_gc, e_th);
}

using testing::error_of;

// Not CT-like (scanner units without negative values), absurd spacing, no colon: clear errors.
TEST(SegmentBadInput, ClearPreconditionErrors) {
  auto shifted = make_volume(32, [](double, double, double) { return kKeep; }, 0);
  for (std::size_t q = 0; q < shifted->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) shifted->GetBufferPointer()[q] += 1024;
  EXPECT_NE(error_of([&] { segment_colon(shifted); }).find("not a CT volume in HU"), std::string::npos);
  EXPECT_THROW(segment_colon(shifted), PreconditionError);

  auto no_colon = make_volume(32, [](double, double, double) { return kKeep; }, 0);
  EXPECT_NE(error_of([&] { segment_colon(no_colon); }).find("no colon found"), std::string::npos);

  auto small_gas = make_volume(32, [](double x, double y, double z) {
    return std::abs(x - 16) < 3 && std::abs(y - 16) < 3 && std::abs(z - 16) < 3 ? -1000.0 : kKeep;
  }, 0);
  EXPECT_NE(error_of([&] { segment_colon(small_gas); }).find("no colon found"), std::string::npos);  // < 20 mL

  auto absurd = make_volume(32, [](double, double, double) { return kKeep; }, 0);
  const double sp[3] = {1, 1, 50};
  absurd->SetSpacing(sp);
  EXPECT_NE(error_of([&] { segment_colon(absurd); }).find("absurd voxel spacing"), std::string::npos);

  auto tiny = CtImage::New();
  tiny->SetRegions(CtImage::SizeType{{4, 4, 4}});
  tiny->Allocate();
  EXPECT_THROW(segment_colon(tiny), PreconditionError);
}

// Invalid options are usage errors naming the option.
TEST(SegmentOptionsCheck, InvalidOptionsRejected) {
  auto bad = [](const std::function<void(SegmentOptions&)>& f) {
    SegmentOptions o;
    f(o);
    return error_of([&] { validate(o); });
  };
  EXPECT_EQ(bad([](SegmentOptions&) {}), "");
  EXPECT_NE(bad([](SegmentOptions& o) { o.band_width = 0; }).find("--band-width"), std::string::npos);
  EXPECT_NE(bad([](SegmentOptions& o) { o.air_threshold = 0; }).find("--air-threshold"), std::string::npos);
  EXPECT_NE(bad([](SegmentOptions& o) { o.fluid_max = 100; }).find("--fluid-max"), std::string::npos);
  EXPECT_NE(bad([](SegmentOptions& o) { o.max_segments = 0; }).find("--max-segments"), std::string::npos);
  EXPECT_NE(bad([](SegmentOptions& o) { o.smoothness = std::nan(""); }).find("--smoothness"), std::string::npos);
  SegmentOptions o;
  o.edge_sigma = 0;
  EXPECT_THROW(segment_colon(nullptr, o), UsageError);
}

using testing::small_phantom;

// Small phantom (2.8 mm voxels): Dice >= 0.99, no leak into outside air or lungs, one segment.
TEST(SegmentPhantom, SmallPhantomDice) {
  for (std::uint64_t seed : {1, 4}) {
    SCOPED_TRACE(seed);
    const Phantom& p = small_phantom(seed);
    SegmentStats st;
    auto m = segment_colon(p.ct, {}, &st);
    EXPECT_GE(dice(m, p.lumen), 0.99);
    EXPECT_EQ(st.segments, 1);
    // No leak: nothing segmented in the top 10 slices (lungs) or the outer 10 voxels (outside air).
    const auto sz = m->GetLargestPossibleRegion().GetSize();
    for (std::size_t k = 0; k < sz[2]; ++k)
      for (std::size_t j = 0; j < sz[1]; ++j)
        for (std::size_t i = 0; i < sz[0]; ++i) {
          const bool border = i < 10 || j < 10 || i + 10 >= sz[0] || j + 10 >= sz[1] || k + 10 >= sz[2];
          if (border) ASSERT_FALSE(at(m, int(i), int(j), int(k))) << i << " " << j << " " << k;
        }
    // Polyp head centres (those at least 8 mm wide) stay wall.
    for (const auto& q : p.polyps) {
      if (q.diameter_mm < 8) continue;
      MaskImage::PointType pt;
      for (int d = 0; d < 3; ++d) pt[d] = q.center_lps_mm[d];
      MaskImage::IndexType idx;
      ASSERT_TRUE(m->TransformPhysicalPointToIndex(pt, idx));
      EXPECT_FALSE(m->GetPixel(idx)) << "polyp " << q.id;
    }
  }
}

// segment_colon's voxels_read is called once, after which the CT's voxels are not read again: they
// are overwritten with 3000 HU in the call, and the mask is still the one of the untouched CT, byte
// for byte, on the same grid, with the same volume and gravity (read from the CT's header).
TEST(SegmentPhantom, VoxelsAreNotReadAfterTheCropIsCopied) {
  const Phantom& p = small_phantom(1);
  SegmentStats ref_st, st;
  const auto ref = segment_colon(p.ct, {}, &ref_st);
  auto ct = CtImage::New();
  ct->CopyInformation(p.ct);
  ct->SetRegions(p.ct->GetLargestPossibleRegion());
  ct->SetMetaDataDictionary(p.ct->GetMetaDataDictionary());
  ct->Allocate();
  const std::size_t n = ct->GetLargestPossibleRegion().GetNumberOfPixels();
  std::copy_n(p.ct->GetBufferPointer(), n, ct->GetBufferPointer());
  int calls = 0;
  const auto m = segment_colon(ct, {}, &st, [&] { ++calls, std::fill_n(ct->GetBufferPointer(), n, 3000.0f); });
  EXPECT_EQ(calls, 1);
  ASSERT_EQ(m->GetLargestPossibleRegion(), ref->GetLargestPossibleRegion());
  EXPECT_EQ(std::memcmp(m->GetBufferPointer(), ref->GetBufferPointer(), n), 0);
  EXPECT_EQ(m->GetOrigin(), ref->GetOrigin());
  EXPECT_EQ(m->GetSpacing(), ref->GetSpacing());
  EXPECT_EQ(m->GetDirection(), ref->GetDirection());
  EXPECT_EQ(st.lumen_volume_ml, ref_st.lumen_volume_ml);
  EXPECT_EQ(st.gravity, ref_st.gravity);
  EXPECT_EQ(st.gravity_source, ref_st.gravity_source);
  EXPECT_GT(st.lumen_volume_ml, 0.0);
}

// A collapsed colon gives two segments, both kept.
TEST(SegmentPhantom, CollapsedColonTwoSegments) {
  const Phantom& p = small_phantom(2, true);
  SegmentStats st;
  auto m = segment_colon(p.ct, {}, &st);
  EXPECT_EQ(st.segments, 2);
  EXPECT_GE(dice(m, p.lumen), 0.99);
}

// The graph cut's slabs, the box mean and every voxel pass use cf::thread_count() workers: 1, 2 and
// 5 threads give the same mask byte for byte and the same max-flow (slab flows summed in order).
TEST(SegmentPhantom, SameMaskForAnyThreadCount) {
  const Phantom& p = small_phantom(1);
  std::vector<MaskImage::Pointer> masks;
  std::vector<double> flows;
  for (int t : {1, 2, 5}) {
    set_thread_count(t);
    SegmentStats st;
    masks.push_back(segment_colon(p.ct, {}, &st));
    flows.push_back(st.flow);
  }
  set_thread_count(0);
  const std::size_t n = masks[0]->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t i = 1; i < masks.size(); ++i) {
    EXPECT_EQ(0, std::memcmp(masks[0]->GetBufferPointer(), masks[i]->GetBufferPointer(), n)) << i;
    EXPECT_EQ(flows[0], flows[i]) << i;
  }
  EXPECT_GT(count(masks[0]), 10000u);
}

testing::CommandResult run_segment(const std::vector<std::string>& args) {
  return testing::run_stage_command([] { return make_segment_stage(); }, args);
}

// The DICOM-series and NRRD forms of the same phantom give identical masks (via `colonflat segment`).
TEST(SegmentPhantom, DicomAndNrrdGiveIdenticalMasks) {
  testing::TempDir tmp;
  const Phantom& p = small_phantom(3);
  write_phantom(p, tmp / "n", "nrrd");
  write_phantom(p, tmp / "d", "dicom");
  ASSERT_EQ(run_segment({tmp.str("n/ct.nrrd"), "-o", tmp.str("mn.nrrd"), "-q"}).code, 0);
  const auto r = run_segment({tmp.str("d/dicom"), "-o", tmp.str("md.nrrd"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  auto a = read_mask(tmp / "mn.nrrd"), b = read_mask(tmp / "md.nrrd");
  ASSERT_EQ(a->GetLargestPossibleRegion().GetSize(), b->GetLargestPossibleRegion().GetSize());
  EXPECT_EQ(0, std::memcmp(a->GetBufferPointer(), b->GetBufferPointer(), a->GetLargestPossibleRegion().GetNumberOfPixels()));
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(a->GetOrigin()[d], b->GetOrigin()[d], 1e-6);
  EXPECT_GT(count(a), 10000u);
}

// `colonflat segment` writes the mask and a report with segments, volumes, time and peak memory.
TEST(SegmentStageTool, WritesMaskAndReport) {
  testing::TempDir tmp;
  write_ct_volume(small_phantom(1).ct, tmp / "ct.nrrd");
  const auto r = run_segment({tmp.str("ct.nrrd"), "-o", tmp.str("mask.nrrd"), "--report", tmp.str("r.json"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = read_json_file(tmp / "r.json");
  EXPECT_EQ(j["stage"], "segment");
  EXPECT_EQ(j["result"]["segments"], 1);
  EXPECT_GT(j["result"]["lumen_volume_ml"].get<double>(), 500);
  EXPECT_TRUE(j["result"].contains("peak_memory_mib"));
  EXPECT_TRUE(j["result"].contains("time_s"));
  EXPECT_EQ(j["parameters"]["band-width"], 2.0);
  EXPECT_GE(dice(read_mask(tmp / "mask.nrrd"), small_phantom(1).lumen), 0.99);
}

// Bad input through the command: one error line, exit 3 (bad input) or 2 (usage), nothing written.
TEST(SegmentStageTool, BadInputWritesNothing) {
  testing::TempDir tmp;
  // Scanner units: not CT-like.
  auto shifted = make_volume(32, [](double, double, double) { return kKeep; }, 0);
  for (std::size_t q = 0; q < shifted->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) shifted->GetBufferPointer()[q] += 1024;
  write_ct_volume(shifted, tmp / "units.nrrd");
  auto r = run_segment({tmp.str("units.nrrd"), "-o", tmp.str("m.nrrd")});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("colonflat segment: error: not a CT volume in HU"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "m.nrrd"));
  // Missing file, empty folder.
  r = run_segment({tmp.str("none.nrrd"), "-o", tmp.str("m.nrrd")});
  EXPECT_EQ(r.code, 3);
  EXPECT_EQ(r.err, "colonflat segment: error: " + tmp.str("none.nrrd") + ": no such file\n");
  fs::create_directories(tmp / "empty");
  r = run_segment({tmp.str("empty"), "-o", tmp.str("m.nrrd")});
  EXPECT_EQ(r.code, 3);
  EXPECT_NE(r.err.find("no readable DICOM"), std::string::npos) << r.err;
  // Parameter out of range.
  write_ct_volume(small_phantom(1).ct, tmp / "ct.nrrd");
  r = run_segment({tmp.str("ct.nrrd"), "-o", tmp.str("m.nrrd"), "--band-width", "0"});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "colonflat segment: error: --band-width must be >= 0.5 (got 0)\n");
  EXPECT_FALSE(fs::exists(tmp / "m.nrrd"));
}

// The stage declares its ports with the pipeline's artifact names and default files.
TEST(SegmentStageTool, Spec) {
  SegmentStage s;
  EXPECT_EQ(s.spec().name, "segment");
  ASSERT_EQ(s.spec().inputs.size(), 1u);
  EXPECT_EQ(s.spec().inputs[0].name, "ct");
  EXPECT_EQ(s.spec().inputs[0].type, &volume_artifact());
  EXPECT_EQ(s.spec().inputs[0].file_name, "ct.nrrd");
  ASSERT_EQ(s.spec().outputs.size(), 1u);
  EXPECT_EQ(s.spec().outputs[0].name, "mask");
  EXPECT_EQ(s.spec().outputs[0].type, &mask_artifact());
  EXPECT_EQ(s.spec().outputs[0].file_name, "lumen_mask.nrrd");
  EXPECT_EQ(s.params_json()["interface-width"], 3.0);
}

}  // namespace
}  // namespace cf

namespace cf {
namespace {

// Real CT (the shared head CT, converted from scanner units to HU): it holds no colon, so the
// segmentation refuses it with "no colon found" (its airway gas, 56 mL, is far below an insufflated
// colon), and as stored (scanner units) it is "not a CT volume in HU".
TEST(SegmentRealCt, HeadCtHasNoColon) {
  const fs::path f = fs::path(COLONFLAT_SHARED_DIR) / "ct" / "vtk_headsq_quarter_ct_head" / "headsq_quarter.nrrd";
  if (!fs::exists(f)) GTEST_SKIP() << "shared data not available";
  auto ct = read_ct_volume(f);
  EXPECT_NE(error_of([&] { segment_colon(ct); }).find("not a CT volume in HU"), std::string::npos);
  for (std::size_t q = 0; q < ct->GetLargestPossibleRegion().GetNumberOfPixels(); ++q) ct->GetBufferPointer()[q] -= 1024;
  SegmentStats st;
  const std::string e = error_of([&] { segment_colon(ct, {}, &st); });
  EXPECT_NE(e.find("no colon found"), std::string::npos) << e << st.to_json().dump();
  // Its bone touches the sinus gas but has no level surface: not taken for tagged fluid.
  SegmentOptions o;
  o.min_colon_volume = 0;
  auto m = segment_colon(ct, o, &st);
  EXPECT_EQ(st.fluid_volume_ml, 0.0);
  EXPECT_GE(st.rejected_fluid_components, 1u);
}

}  // namespace
}  // namespace cf

namespace cf::segment_detail {
namespace {

// The input check's HU tally split over the workers (air and soft-tissue counts, lowest and highest
// value) equals the serial count on a random volume, for 1, 2 and 3 threads.
TEST(SegmentInput, HuTallyOverWorkersEqualsSerialCount) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> hu(-1024, 2500);
  std::vector<float> v(100003);
  for (float& x : v) x = hu(rng);
  v[77] = -1500, v[99999] = 3100;  // the extremes, in different chunks
  std::size_t air = 0, soft = 0;
  for (float x : v) air += x < -800, soft += x > -200 && x < 200;
  EXPECT_GT(air, 5000u);
  EXPECT_GT(soft, 5000u);
  for (int t : {1, 2, 3}) {
    set_thread_count(t);
    const HuTally got = tally_hu(v.data(), v.size());
    EXPECT_EQ(got.air, air) << t << " threads";
    EXPECT_EQ(got.soft, soft) << t << " threads";
    EXPECT_EQ(got.lo, -1500.0f) << t << " threads";
    EXPECT_EQ(got.hi, 3100.0f) << t << " threads";
  }
  set_thread_count(0);
}

}  // namespace
}  // namespace cf::segment_detail
