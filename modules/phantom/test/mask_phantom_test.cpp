// Tests of `colonflat phantom --from-mask` (paint_phantom_from_mask): a CT painted around a lumen
// mask built here (a haustrated U-shaped colon, RAS-like flipped direction) and, when the shared
// data is present, around the real mask downsampled.
#include <gtest/gtest.h>

#include <itkConnectedComponentImageFilter.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <fstream>
#include <sstream>

#include "colonflat/core/stage.h"
#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/phantom/phantom_tool.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

using V = std::array<double, 3>;

double seg_dist(const V& p, const V& a, const V& b, double* len, double* tout) {
  double ab2 = 0, t = 0;
  for (int d = 0; d < 3; ++d) ab2 += (b[d] - a[d]) * (b[d] - a[d]), t += (p[d] - a[d]) * (b[d] - a[d]);
  t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
  *len = std::sqrt(ab2);
  *tout = t;
  double s = 0;
  for (int d = 0; d < 3; ++d) s += std::pow(a[d] + t * (b[d] - a[d]) - p[d], 2);
  return std::sqrt(s);
}

// A U-shaped colon (two limbs 130 mm apart joined at the top) with haustral bulges every 30 mm,
// 2 x 2 x 2.5 mm voxels, direction diag(-1, -1, 1) as a RAS NIfTI reads into LPS.
MaskImage::Pointer u_colon_mask() {
  auto m = MaskImage::New();
  m->SetRegions(MaskImage::SizeType{{105, 90, 72}});
  const double sp[3] = {2, 2, 2.5};
  m->SetSpacing(sp);
  const double org[3] = {105, 90, -90};
  m->SetOrigin(org);
  MaskImage::DirectionType dir;
  dir.SetIdentity();
  dir(0, 0) = -1;
  dir(1, 1) = -1;
  m->SetDirection(dir);
  m->Allocate();
  const std::vector<V> path = {{-65, 0, -80}, {-65, 0, 50}, {65, 0, 50}, {65, 0, -80}};
  for (int k = 0; k < 72; ++k)
    for (int j = 0; j < 90; ++j)
      for (int i = 0; i < 105; ++i) {
        MaskImage::PointType pt;
        m->TransformIndexToPhysicalPoint({{i, j, k}}, pt);
        const V p = {pt[0], pt[1], pt[2]};
        double best = 1e9, s = 0, along = 0;
        for (std::size_t t = 0; t + 1 < path.size(); ++t) {
          double len, u;
          const double d = seg_dist(p, path[t], path[t + 1], &len, &u);
          if (d < best) best = d, s = along + u * len;
          along += len;
        }
        const double r = 15 + 3 * std::cos(2 * 3.14159265 * s / 30);
        m->SetPixel({{i, j, k}}, best < r ? 1 : 0);
      }
  return m;
}

const MaskImage::Pointer& u_mask() {
  static const MaskImage::Pointer m = u_colon_mask();
  return m;
}

struct Painted {
  MaskPhantom p;
  explicit Painted(const MaskPhantomOptions& o, const MaskImage* m = u_mask()) : p(paint_phantom_from_mask(m, o)) {}
};

// Depth (mm along gravity) of a voxel, and the index step that goes one voxel down.
struct Gravity {
  V down;
  int axis = 0, sign = 1;
  Gravity(const MaskImage* m, const V& g) : down(g) {
    for (int a = 0; a < 3; ++a) {
      double c = 0;
      for (int d = 0; d < 3; ++d) c += m->GetDirection()(d, a) * g[d];
      if (std::abs(c) > 0.5) axis = a, sign = c > 0 ? 1 : -1;
    }
  }
  double depth(const MaskImage* m, const MaskImage::IndexType& i) const {
    MaskImage::PointType pt;
    m->TransformIndexToPhysicalPoint(i, pt);
    return pt[0] * down[0] + pt[1] * down[1] + pt[2] * down[2];
  }
};

// Pools in one position: each has one level surface (every fluid voxel under gas is in one layer),
// lies on the dependent side (no gas below fluid), and is 10-30 % of its pocket's height deep.
void check_pools(const MaskPhantom& p, const MaskImage* m, int* pools_out) {
  const Gravity g(m, p.gravity_lps);
  const auto size = m->GetLargestPossibleRegion().GetSize();
  const double step = m->GetSpacing()[g.axis];
  std::map<int, std::pair<double, double>> range;  // body -> (shallowest, deepest) depth
  std::map<int, std::set<long>> surface;           // body -> depths of voxels under gas (in 1e-3 mm)
  const unsigned char* mk = m->GetBufferPointer();
  auto id = [&](const MaskImage::IndexType& i) { return std::size_t(i[0] + size[0] * (i[1] + size[1] * i[2])); };
  int pools = 0;
  for (std::size_t b = 0; b < p.bodies.size(); ++b) pools += p.bodies[b].kind == "pool";
  for (unsigned k = 0; k < size[2]; ++k)
    for (unsigned j = 0; j < size[1]; ++j)
      for (unsigned i = 0; i < size[0]; ++i) {
        MaskImage::IndexType x = {{i, j, k}};
        const int b = p.fluid_id[id(x)];
        if (b == 0 || p.bodies[b - 1].kind != "pool") continue;
        const double d = g.depth(m, x);
        auto& r = range.try_emplace(b, d, d).first->second;
        r.first = std::min(r.first, d), r.second = std::max(r.second, d);
        for (int s : {-1, 1}) {
          MaskImage::IndexType y = x;
          y[g.axis] += s * g.sign;
          if (y[g.axis] < 0 || y[g.axis] >= long(size[g.axis])) continue;
          const bool gas = mk[id(y)] && p.fluid_id[id(y)] == 0;
          if (s == 1) {
            EXPECT_FALSE(gas) << "gas below pool " << b;
          }
          if (s == -1 && gas) surface[b].insert(std::lround(d * 1000));
        }
      }
  EXPECT_EQ(int(range.size()), pools);
  for (const auto& [b, r] : range) {
    EXPECT_LE(surface[b].size(), 1u) << "pool " << b << " has several surface levels";
    const MaskFluidBody& f = p.bodies[b - 1];
    EXPECT_NEAR(r.second, f.bottom_depth_mm, 1e-6);
    EXPECT_LE((r.second - r.first) / f.pocket_height_mm, 0.30 + 1e-9) << "pool " << b;
    EXPECT_GE((r.second - r.first + step) / f.pocket_height_mm, 0.10 - 1e-9) << "pool " << b;
    EXPECT_GT(f.level_depth_mm, r.second - 0.30 * f.pocket_height_mm - 1e-9);
  }
  *pools_out = pools;
}

// Supine, prone and left side down: level pools on the dependent side, 10-30 % of each pocket.
TEST(MaskPhantom, PoolsAreLevelDependentAndTenToThirtyPercent) {
  double mean_y[2] = {0, 0};
  for (const char* pos : {"supine", "prone", "left-down"}) {
    MaskPhantomOptions o;
    o.position = pos;
    o.fully_tagged = 0;
    o.bowel_loops = 0;
    Painted c(o);
    int pools = 0;
    check_pools(c.p, u_mask(), &pools);
    EXPECT_GE(pools, 2) << pos;
    // Mean LPS y of pool voxels relative to the lumen's: posterior (+) supine, anterior (-) prone.
    double fy = 0, ly = 0;
    std::size_t nf = 0, nl = 0;
    const auto& m = u_mask();
    for (std::size_t q = 0; q < c.p.fluid_id.size(); ++q) {
      if (!m->GetBufferPointer()[q]) continue;
      MaskImage::PointType pt;
      m->TransformIndexToPhysicalPoint(m->ComputeIndex(q), pt);
      ly += pt[1], ++nl;
      if (c.p.fluid_id[q]) fy += pt[1], ++nf;
    }
    ASSERT_GT(nf, 0u);
    if (std::string(pos) != "left-down") mean_y[std::string(pos) == "prone"] = fy / nf - ly / nl;
  }
  EXPECT_GT(mean_y[0], 5.0);
  EXPECT_LT(mean_y[1], -5.0);
}

// The CT, lumen and labels have the mask's geometry; the lumen truth is the mask; colon gas and
// colon fluid labels cover exactly the mask.
TEST(MaskPhantom, GeometryAndTruthAreTheMasks) {
  Painted c(MaskPhantomOptions{});
  const MaskImage* m = u_mask();
  for (const itk::ImageBase<3>* im : {static_cast<const itk::ImageBase<3>*>(c.p.phantom.ct.GetPointer()),
                                      static_cast<const itk::ImageBase<3>*>(c.p.phantom.lumen.GetPointer()),
                                      static_cast<const itk::ImageBase<3>*>(c.p.phantom.labels.GetPointer())}) {
    EXPECT_EQ(im->GetLargestPossibleRegion().GetSize(), m->GetLargestPossibleRegion().GetSize());
    for (int d = 0; d < 3; ++d) {
      EXPECT_DOUBLE_EQ(im->GetSpacing()[d], m->GetSpacing()[d]);
      EXPECT_DOUBLE_EQ(im->GetOrigin()[d], m->GetOrigin()[d]);
    }
    EXPECT_EQ(im->GetDirection(), m->GetDirection());
  }
  const std::size_t n = m->GetLargestPossibleRegion().GetNumberOfPixels();
  std::size_t fluid = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const unsigned char lab = c.p.phantom.labels->GetBufferPointer()[q];
    ASSERT_EQ(c.p.phantom.lumen->GetBufferPointer()[q], m->GetBufferPointer()[q]);
    ASSERT_EQ(lab == 1 || lab == 2, m->GetBufferPointer()[q] != 0);
    ASSERT_EQ(lab == 2, c.p.fluid_id[q] != 0);
    fluid += lab == 2;
  }
  EXPECT_GT(fluid, 0u);
  EXPECT_EQ(c.p.phantom.patient_position, "HFS");
}

std::size_t components(const std::vector<unsigned char>& on, const MaskImage* like) {
  auto im = MaskImage::New();
  im->CopyInformation(like);
  im->SetRegions(like->GetLargestPossibleRegion());
  im->Allocate();
  std::copy(on.begin(), on.end(), im->GetBufferPointer());
  auto cc = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>::New();
  cc->SetInput(im);
  cc->SetFullyConnected(true);
  cc->Update();
  return cc->GetObjectCount();
}

// A fully tagged stretch fills the whole lumen there: it is one body, cuts the gas into two
// pieces (no gas passes beside it, not even diagonally), 500-900 HU inside.
TEST(MaskPhantom, FullyTaggedStretchFillsTheLumen) {
  MaskPhantomOptions o;
  o.pools = false;
  o.bowel_loops = 0;
  o.noise_hu = 0;
  Painted c(o);
  ASSERT_EQ(c.p.bodies.size(), 1u);
  EXPECT_EQ(c.p.bodies[0].kind, "stretch");
  EXPECT_GE(c.p.bodies[0].to_mm - c.p.bodies[0].from_mm, 60);
  const MaskImage* m = u_mask();
  std::vector<unsigned char> gas(c.p.fluid_id.size()), fluid(c.p.fluid_id.size());
  double hu = 0;
  std::size_t nf = 0;
  for (std::size_t q = 0; q < gas.size(); ++q) {
    gas[q] = m->GetBufferPointer()[q] && !c.p.fluid_id[q];
    fluid[q] = c.p.fluid_id[q] != 0;
    if (fluid[q]) hu += c.p.phantom.ct->GetBufferPointer()[q], ++nf;
  }
  EXPECT_EQ(components(gas, m), 2u);
  EXPECT_EQ(components(fluid, m), 1u);
  EXPECT_GT(hu / nf, 450);  // 500-900 HU, minus partial volume at the ends beside gas
  EXPECT_LT(hu / nf, 900);
}

// Small bowel (22-30 mm loops, ~300 HU) never overlaps the mask, one loop at least touches the
// colon wall (contrast within wall + bowel wall + 2 mm of the lumen), the bladder is never lumen.
TEST(MaskPhantom, SmallBowelNeverOverlapsAndSomeTouches) {
  MaskPhantomOptions o;
  o.noise_hu = 0;
  Painted c(o);
  const MaskImage* m = u_mask();
  const auto& loops = c.p.phantom.description["small_bowel"];
  ASSERT_GE(loops.size(), 2u);
  for (const auto& l : loops) {
    EXPECT_GE(l["radius_mm"].get<double>(), 11);
    EXPECT_LE(l["radius_mm"].get<double>(), 15);
  }
  auto dm = itk::SignedMaurerDistanceMapImageFilter<MaskImage, itk::Image<float, 3>>::New();
  dm->SetInput(m);
  dm->SetUseImageSpacing(true);
  dm->SetSquaredDistance(false);
  dm->SetInsideIsPositive(false);
  dm->Update();
  const float* dist = dm->GetOutput()->GetBufferPointer();
  double nearest = 1e9, hu = 0;
  std::size_t n = 0;
  for (std::size_t q = 0; q < c.p.fluid_id.size(); ++q) {
    const unsigned char lab = c.p.phantom.labels->GetBufferPointer()[q];
    if (lab != 3 && lab != 5) continue;
    ASSERT_EQ(m->GetBufferPointer()[q], 0);
    if (lab == 3) nearest = std::min(nearest, double(dist[q])), ++n, hu += c.p.phantom.ct->GetBufferPointer()[q];
  }
  ASSERT_GT(n, 0u);
  EXPECT_LE(nearest, 3.0 + 2.0 + 2.0 + 2.0);  // + one 2 mm voxel of the coarse clearance
  EXPECT_GE(nearest, 3.0);                    // never inside the colon wall
  EXPECT_NEAR(hu / n, 300, 60);               // blur at the loop's edge lowers the mean
}

// HU of the tissue classes: colon gas -1000 with the set noise, tagged fluid 400-900 HU.
TEST(MaskPhantom, HounsfieldValuesPerClass) {
  MaskPhantomOptions o;
  o.bowel_loops = 0;
  Painted c(o);
  const auto* ct = c.p.phantom.ct.GetPointer();
  const auto* lab = c.p.phantom.labels->GetBufferPointer();
  const auto size = ct->GetLargestPossibleRegion().GetSize();
  double s[3] = {0, 0, 0}, s2 = 0;
  std::size_t n[3] = {0, 0, 0};
  for (unsigned k = 1; k + 1 < size[2]; ++k)
    for (unsigned j = 1; j + 1 < size[1]; ++j)
      for (unsigned i = 1; i + 1 < size[0]; ++i) {
        const std::size_t q = i + size[0] * (j + size[1] * k);
        bool interior = true;  // all 26 neighbours carry the same label
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di)
              interior = interior && lab[q + di + long(size[0]) * (dj + long(size[1]) * dk)] == lab[q];
        if (!interior || lab[q] > 2) continue;
        const double v = ct->GetBufferPointer()[q];
        s[lab[q]] += v, ++n[lab[q]];
        if (lab[q] == 1) s2 += v * v;
      }
  ASSERT_GT(n[1], 100u);
  ASSERT_GT(n[2], 10u);
  const double gas = s[1] / n[1], sd = std::sqrt(std::max(0.0, s2 / n[1] - gas * gas));
  EXPECT_NEAR(gas, -1000, 5);
  EXPECT_GT(sd, 14);  // sigma 20 HU, less where -1000 - noise is clamped at -1024
  EXPECT_LT(sd, 22);
  EXPECT_GT(s[2] / n[2], 400);  // pools 400-800 HU, stretches 500-900 HU
  EXPECT_LT(s[2] / n[2], 900);
  EXPECT_GT(n[0], 1000u);
}

struct ToolRun {
  int code;
  std::string err;
};
ToolRun tool(const std::vector<std::string>& args) {
  auto t = make_phantom_tool();
  std::ostringstream out, err;
  return {t->run(args, out, err), err.str()};
}

// The command writes the CT with PatientPosition HFP (prone) or none (--no-position-header) and
// the mask as lumen_mask.nrrd beside labels.nrrd and phantom.json.
TEST(MaskPhantom, CommandWritesCtAndTruthWithOrWithoutHeader) {
  testing::TempDir tmp;
  write_mask(u_mask(), tmp / "mask.nii.gz");
  ASSERT_EQ(tool({"--from-mask", tmp.str("mask.nii.gz"), "-o", tmp.str("p"), "--position", "prone", "-q"}).code, 0);
  ASSERT_EQ(tool({"--from-mask", tmp.str("mask.nii.gz"), "-o", tmp.str("n"), "--no-position-header", "-q"}).code, 0);
  for (const char* f : {"ct.nrrd", "lumen_mask.nrrd", "labels.nrrd", "phantom.json"}) EXPECT_TRUE(fs::exists(tmp / "p" / f)) << f;
  EXPECT_EQ(patient_position(read_ct_volume(tmp / "p" / "ct.nrrd")), "HFP");
  EXPECT_EQ(patient_position(read_ct_volume(tmp / "n" / "ct.nrrd")), "");
  auto back = read_mask(tmp / "p" / "lumen_mask.nrrd");
  const std::size_t n = back->GetLargestPossibleRegion().GetNumberOfPixels();
  EXPECT_TRUE(std::equal(back->GetBufferPointer(), back->GetBufferPointer() + n, u_mask()->GetBufferPointer()));
  EXPECT_EQ(read_json_file(tmp / "p" / "phantom.json")["position"], "prone");
}

// Bad mask input (missing, not binary, empty) and options that do not apply: one error line,
// non-zero exit, nothing written.
TEST(MaskPhantom, BadMaskGivesOneLineErrorAndWritesNothing) {
  testing::TempDir tmp;
  auto bad = MaskImage::New();
  bad->SetRegions(MaskImage::SizeType{{8, 8, 8}});
  bad->Allocate();
  bad->FillBuffer(0);
  write_mask(bad, tmp / "empty.nrrd");
  bad->SetPixel({{2, 2, 2}}, 1);
  bad->SetPixel({{3, 3, 3}}, 2);
  write_mask(bad, tmp / "two.nrrd");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--from-mask", tmp.str("missing.nii.gz")}, "missing.nii.gz: "},
      {{"--from-mask", tmp.str("two.nrrd")}, "two.nrrd: not a binary mask"},
      {{"--from-mask", tmp.str("empty.nrrd")}, "empty.nrrd: empty mask"},
      {{"--from-mask", tmp.str("empty.nrrd"), "--size", "small"}, "--size does not apply"},
      {{"--from-mask", tmp.str("empty.nrrd"), "--position", "upside-down"}, "--position must be"},
      {{"--no-position-header"}, "--no-position-header needs --from-mask"}};
  for (const auto& [args, what] : cases) {
    std::vector<std::string> a = args;
    a.insert(a.end(), {"-o", tmp.str("x"), "-q"});
    const ToolRun r = tool(a);
    EXPECT_NE(r.code, 0) << r.err;
    EXPECT_EQ(r.err.rfind("colonflat phantom: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "x"));
  }
}

}  // namespace
}  // namespace cf
