// The CT-colonography phantom: determinism, anatomy and HU values, ground truth consistency, the
// `colonflat phantom` command and its files (NRRD and DICOM forms).
#include <gtest/gtest.h>

#include <itkConnectedComponentImageFilter.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "colonflat/core/stage.h"
#include "colonflat/testing/small_phantom.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/phantom/phantom_tool.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

const Phantom& small(std::uint64_t seed = 1, bool collapsed = false) { return testing::small_phantom(seed, collapsed); }

std::size_t lumen_components(const MaskImage* m) {
  using CC = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>;
  auto cc = CC::New();
  cc->SetInput(m);
  cc->SetFullyConnected(false);
  cc->Update();
  return cc->GetObjectCount();
}

float hu_at(const Phantom& p, const std::array<double, 3>& x) {
  CtImage::PointType pt;
  for (int d = 0; d < 3; ++d) pt[d] = x[d];
  CtImage::IndexType i;
  if (!p.ct->TransformPhysicalPointToIndex(pt, i)) return NAN;
  return p.ct->GetPixel(i);
}
bool lumen_at(const Phantom& p, const std::array<double, 3>& x) {
  MaskImage::PointType pt;
  for (int d = 0; d < 3; ++d) pt[d] = x[d];
  MaskImage::IndexType i;
  if (!p.lumen->TransformPhysicalPointToIndex(pt, i)) return false;
  return p.lumen->GetPixel(i) != 0;
}

// The same seed gives the same volume and ground truth; another seed gives another case.
TEST(PhantomGenerate, DeterministicPerSeed) {
  PhantomOptions o;
  o.size = "small";
  o.seed = 1;
  const Phantom a = generate_phantom(o);
  const Phantom& b = small(1);
  const std::size_t n = a.ct->GetLargestPossibleRegion().GetNumberOfPixels();
  EXPECT_EQ(0, std::memcmp(a.ct->GetBufferPointer(), b.ct->GetBufferPointer(), n * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.lumen->GetBufferPointer(), b.lumen->GetBufferPointer(), n));
  EXPECT_EQ(polyps_json(a), polyps_json(b));
  const Phantom& c = small(2);
  EXPECT_NE(0, std::memcmp(a.ct->GetBufferPointer(), c.ct->GetBufferPointer(), n * sizeof(float)));
  EXPECT_NE(polyps_json(a), polyps_json(c));
}

// Small size: 128^3 voxels of 2.8 x 2.8 x 3.125 mm, identity direction, LPS.
TEST(PhantomGenerate, SmallGeometry) {
  const Phantom& p = small();
  const auto sz = p.ct->GetLargestPossibleRegion().GetSize();
  EXPECT_EQ(sz[0], 128u);
  EXPECT_EQ(sz[1], 128u);
  EXPECT_EQ(sz[2], 128u);
  EXPECT_DOUBLE_EQ(p.ct->GetSpacing()[0], 2.8);
  EXPECT_DOUBLE_EQ(p.ct->GetSpacing()[2], 3.125);
  EXPECT_EQ(p.lumen->GetLargestPossibleRegion().GetSize(), sz);
  EXPECT_EQ(p.description["coordinate_system"], "LPS");
}

// The colon: 1.2-1.6 m, radius about 12-30 mm, six named segments in order, one connected lumen.
TEST(PhantomGenerate, ColonAnatomy) {
  for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
    SCOPED_TRACE(seed);
    const Phantom& p = small(seed);
    const auto& c = p.description["colon"];
    EXPECT_GE(c["length_mm"].get<double>(), 1200);
    EXPECT_LE(c["length_mm"].get<double>(), 1600);
    EXPECT_GE(c["radius_range_mm"][0].get<double>(), 11);
    EXPECT_LE(c["radius_range_mm"][1].get<double>(), 33);
    std::vector<std::string> names;
    for (const auto& s : c["segments"]) names.push_back(s["name"]);
    EXPECT_EQ(names, (std::vector<std::string>{"rectum", "sigmoid", "descending", "transverse", "ascending", "cecum"}));
    EXPECT_GT(c["folds"].get<int>(), 15);
    EXPECT_EQ(lumen_components(p.lumen), 1u);
    const double ml = c["lumen_volume_ml"].get<double>();
    EXPECT_GT(ml, 800);
    EXPECT_LT(ml, 3000);
  }
}

// HU: outside air -1000, colon gas about -1000, tagged fluid +300..+600 in the lumen, soft tissue.
TEST(PhantomGenerate, HounsfieldValues) {
  const Phantom& p = small();
  EXPECT_NEAR(p.ct->GetPixel({{0, 0, 0}}), -1000, 80);
  const std::size_t n = p.ct->GetLargestPossibleRegion().GetNumberOfPixels();
  double gas = 0, fluid = 0;
  std::size_t ng = 0, nf = 0, lung = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float v = p.ct->GetBufferPointer()[i];
    EXPECT_EQ(v, std::round(v));
    if (p.lumen->GetBufferPointer()[i]) {
      if (v < -900) {
        gas += v;
        ++ng;
      }
      if (v > 250) {
        fluid += v;
        ++nf;
      }
    }
    lung += v > -900 && v < -800;
  }
  ASSERT_GT(ng, 1000u);
  ASSERT_GT(nf, 100u);
  EXPECT_NEAR(gas / double(ng), -1000, 30);
  EXPECT_GT(fluid / double(nf), 300);
  EXPECT_LT(fluid / double(nf), 620);
  EXPECT_GT(lung, 1000u);  // lung bases
  for (const auto& pool : p.description["colon"]["fluid_pools"]) {
    EXPECT_GE(pool["hu"].get<double>(), 300);
    EXPECT_LE(pool["hu"].get<double>(), 600);
  }
}

// Polyps: 4-15 mm, sessile and pedunculated, heads are tissue (not lumen) next to the lumen.
TEST(PhantomGenerate, PolypsGroundTruth) {
  const Phantom& p = small(3);
  ASSERT_GE(p.polyps.size(), 5u);
  std::set<std::string> types;
  for (const auto& q : p.polyps) {
    SCOPED_TRACE(q.id);
    types.insert(q.type);
    EXPECT_GE(q.diameter_mm, 4);
    EXPECT_LE(q.diameter_mm, 15);
    EXPECT_FALSE(lumen_at(p, q.center_lps_mm)) << "polyp head centre must be wall";
    // Lumen within one radius + 3 mm of the head centre.
    bool near_lumen = false;
    const double r = 0.5 * q.diameter_mm + 3;
    for (int a = 0; a < 3 && !near_lumen; ++a)
      for (int s = -1; s <= 1; s += 2) {
        auto x = q.center_lps_mm;
        x[a] += s * r;
        near_lumen = near_lumen || lumen_at(p, x);
      }
    EXPECT_TRUE(near_lumen);
  }
  EXPECT_EQ(types, (std::set<std::string>{"pedunculated", "sessile"}));
}

// Topological noise: strands, a near touch and fold holes are recorded with their positions.
TEST(PhantomGenerate, NoiseSitesRecorded) {
  const Phantom& p = small(1);
  std::map<std::string, int> n;
  for (const auto& s : p.noise_sites) ++n[s.type];
  EXPECT_GE(n["strand"], 2);
  EXPECT_EQ(n["near_touch"], 1);
  EXPECT_GE(n["fold_hole"], 1);
  // A strand runs through the centreline: its centre is tissue, inside the colon.
  for (const auto& s : p.noise_sites)
    if (s.type == "strand") EXPECT_FALSE(lumen_at(p, s.center_lps_mm));
  PhantomOptions o;
  o.size = "small";
  o.topological_noise = false;
  EXPECT_TRUE(generate_phantom(o).noise_sites.empty());
}

// The centreline runs inside the lumen (except where strands or folds cross it).
TEST(PhantomGenerate, CenterlineInsideLumen) {
  const Phantom& p = small(2);
  ASSERT_GT(p.centerline.size(), 500u);
  std::size_t inside = 0;
  for (const auto& c : p.centerline) inside += lumen_at(p, c.p_lps_mm);
  EXPECT_GT(double(inside) / double(p.centerline.size()), 0.97);
  EXPECT_EQ(p.centerline.front().segment, "rectum");
  EXPECT_EQ(p.centerline.back().segment, "cecum");
}

// The collapsed option splits the lumen into two parts.
TEST(PhantomGenerate, CollapsedSegmentSplitsLumen) {
  const Phantom& p = small(1, true);
  EXPECT_EQ(lumen_components(p.lumen), 2u);
  EXPECT_FALSE(p.description["colon"]["collapsed"].is_null());
}

// Invalid options are usage errors.
TEST(PhantomGenerate, InvalidOptionsRejected) {
  PhantomOptions o;
  o.size = "huge";
  EXPECT_THROW(generate_phantom(o), UsageError);
  o = {};
  o.noise_hu = -1;
  EXPECT_THROW(generate_phantom(o), UsageError);
  o = {};
  o.blur_mm = 9;
  EXPECT_THROW(generate_phantom(o), UsageError);
}

struct Run {
  int code;
  std::string out, err;
};
Run run_tool(const std::vector<std::string>& args) {
  auto t = make_phantom_tool();
  std::ostringstream out, err;
  const int code = t->run(args, out, err);
  return {code, out.str(), err.str()};
}

// `colonflat phantom` writes the volume and every ground-truth file; they match the in-memory phantom.
TEST(PhantomTool, WritesVolumeAndGroundTruth) {
  testing::TempDir tmp;
  const auto r = run_tool({"-o", tmp.str("case"), "--seed", "1", "--size", "small", "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"ct.nrrd", "lumen_mask.nrrd", "polyps.json", "centerline.json", "noise_sites.json", "phantom.json"})
    EXPECT_TRUE(fs::exists(tmp / "case" / f)) << f;
  const Phantom& p = small(1);
  auto ct = read_ct_volume(tmp / "case" / "ct.nrrd");
  const std::size_t n = ct->GetLargestPossibleRegion().GetNumberOfPixels();
  EXPECT_EQ(0, std::memcmp(ct->GetBufferPointer(), p.ct->GetBufferPointer(), n * sizeof(float)));
  auto m = read_mask(tmp / "case" / "lumen_mask.nrrd");
  EXPECT_EQ(0, std::memcmp(m->GetBufferPointer(), p.lumen->GetBufferPointer(), n));
  const auto polyps = read_json_file(tmp / "case" / "polyps.json");
  ASSERT_EQ(polyps.size(), p.polyps.size());
  for (const auto& q : polyps) {
    EXPECT_TRUE(q.contains("id"));
    EXPECT_EQ(q["center_lps_mm"].size(), 3u);
    EXPECT_TRUE(q["type"] == "sessile" || q["type"] == "pedunculated");
    EXPECT_GT(q["diameter_mm"].get<double>(), 0);
  }
  const auto cl = read_json_file(tmp / "case" / "centerline.json");
  EXPECT_EQ(cl["points"].size(), p.centerline.size());
  const auto ph = read_json_file(tmp / "case" / "phantom.json");
  EXPECT_EQ(ph["seed"], 1);
  EXPECT_EQ(ph["files"]["ct"], "ct.nrrd");
}

// --format dicom writes a DICOM series that reads back to the same HU volume and geometry.
TEST(PhantomTool, DicomFormatMatchesNrrd) {
  testing::TempDir tmp;
  ASSERT_EQ(run_tool({"-o", tmp.str("d"), "--size", "small", "--format", "dicom", "-q"}).code, 0);
  EXPECT_FALSE(fs::exists(tmp / "d" / "ct.nrrd"));
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(tmp / "d" / "dicom")) files += e.path().extension() == ".dcm";
  EXPECT_EQ(files, 128u);
  auto ct = read_ct_volume(tmp / "d" / "dicom");
  const Phantom& p = small(1);
  const std::size_t n = p.ct->GetLargestPossibleRegion().GetNumberOfPixels();
  ASSERT_EQ(ct->GetLargestPossibleRegion().GetSize(), p.ct->GetLargestPossibleRegion().GetSize());
  EXPECT_EQ(0, std::memcmp(ct->GetBufferPointer(), p.ct->GetBufferPointer(), n * sizeof(float)));
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(ct->GetSpacing()[d], p.ct->GetSpacing()[d], 1e-9);
    EXPECT_NEAR(ct->GetOrigin()[d], p.ct->GetOrigin()[d], 1e-9);
  }
  EXPECT_EQ(list_dicom_series(tmp / "d" / "dicom").at(0).modality, "CT");
}

// Bad options: exit 2, one error line, nothing written.
TEST(PhantomTool, BadOptionsWriteNothing) {
  testing::TempDir tmp;
  for (const auto& args : std::vector<std::vector<std::string>>{{"-o", tmp.str("x"), "--size", "huge"},
                                                                {"-o", tmp.str("x"), "--format", "png"},
                                                                {"-o", tmp.str("x"), "--noise", "-3"}}) {
    const auto r = run_tool(args);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("colonflat phantom: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "x"));
  }
}

}  // namespace
}  // namespace cf
