// compact_ct / expand_ct: a CT of 16-bit integer HU is held in 16 bits and comes back voxel for
// voxel with its geometry and header; any other CT is not compacted. compact_mask / expand_mask:
// the same for a 0/1 mask in one bit per voxel.
#include <gtest/gtest.h>

#include <itkMetaDataObject.h>

#include <array>
#include <filesystem>
#include <cmath>
#include <memory>
#include <limits>
#include <string>

#include "colonflat/testing/files.h"
#include "colonflat/testing/temp_dir.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// 6 x 5 x 4 voxels, oblique (30 degrees about z), HU spanning the whole 16-bit range, and a
// PatientPosition in the header dictionary.
CtImage::Pointer small_ct() {
  auto im = CtImage::New();
  im->SetRegions(CtImage::SizeType{{6, 5, 4}});
  const double sp[3] = {0.7, 0.8, 1.25}, org[3] = {-100.5, 20.25, -300};
  im->SetSpacing(sp);
  im->SetOrigin(org);
  CtImage::DirectionType dir;
  dir.SetIdentity();
  dir[0][0] = dir[1][1] = std::sqrt(3.0) / 2;
  dir[0][1] = -0.5;
  dir[1][0] = 0.5;
  im->SetDirection(dir);
  im->Allocate();
  const std::size_t n = im->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t i = 0; i < n; ++i) im->GetBufferPointer()[i] = float(int(i * 997 % 4096) - 1024);
  im->GetBufferPointer()[0] = -32768.0f;
  im->GetBufferPointer()[1] = 32767.0f;
  itk::EncapsulateMetaData<std::string>(im->GetMetaDataDictionary(), "PatientPosition", "HFP");
  return im;
}

std::string patient_position(const itk::ImageBase<3>& im) {
  std::string v;
  itk::ExposeMetaData<std::string>(im.GetMetaDataDictionary(), "PatientPosition", v);
  return v;
}

// `back` has the grid (spacing, origin, direction) of `original` and the header's position.
void expect_same_grid(const itk::ImageBase<3>& back, const itk::ImageBase<3>& original, const std::string& position) {
  EXPECT_EQ(back.GetSpacing(), original.GetSpacing());
  EXPECT_EQ(back.GetOrigin(), original.GetOrigin());
  EXPECT_EQ(back.GetDirection(), original.GetDirection());
  EXPECT_EQ(patient_position(back), position);
}

// Integer HU over the whole 16-bit range: held as short, expanded back equal voxel for voxel with
// the same grid and header.
TEST(CompactCt, IntegerHuComeBackExactly) {
  const CtImage::Pointer ct = small_ct();
  const CompactCtImage::Pointer c = compact_ct(*ct);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->GetBufferPointer()[0], -32768);
  EXPECT_EQ(patient_position(*c), "HFP");
  const CtImage::Pointer back = expand_ct(*c);
  ASSERT_EQ(back->GetLargestPossibleRegion(), ct->GetLargestPossibleRegion());  // before the voxels are read
  expect_same_grid(*back, *ct, "HFP");
  const std::size_t n = ct->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(back->GetBufferPointer()[i], ct->GetBufferPointer()[i]) << i;
}

// One voxel that is not a 16-bit integer (a fraction, out of range, NaN) keeps the CT in float.
TEST(CompactCt, AnyOtherValueIsNotCompacted) {
  for (float bad : {0.5f, 32768.0f, -32769.0f, std::numeric_limits<float>::quiet_NaN()}) {
    CtImage::Pointer ct = small_ct();
    ct->GetBufferPointer()[37] = bad;
    EXPECT_FALSE(compact_ct(*ct)) << bad;
  }
}

// The volume artifact's hooks use them: its stand-in is the 16-bit image, and expand gives the CT.
TEST(CompactCt, VolumeArtifactCompactsAndExpands) {
  const CtImage::Pointer ct = small_ct();
  const std::optional<std::any> stand_in = volume_artifact().compact(std::any(ct));
  ASSERT_TRUE(stand_in);
  ASSERT_NE(std::any_cast<CompactCtImage::Pointer>(&*stand_in), nullptr);
  const auto back = std::any_cast<CtImage::Pointer>(volume_artifact().expand(*stand_in));
  EXPECT_EQ(back->GetBufferPointer()[1], 32767.0f);
}

// nx x ny x nz voxels, oblique like small_ct, a header entry, voxel i = 1 where (i * 7919) % 5 < 2:
// runs of both values that cross every 64-voxel word boundary.
MaskImage::Pointer patterned_mask(unsigned nx, unsigned ny, unsigned nz) {
  const CtImage::Pointer ct = small_ct();
  auto m = MaskImage::New();
  m->SetRegions(MaskImage::SizeType{{nx, ny, nz}});
  m->SetSpacing(ct->GetSpacing());
  m->SetOrigin(ct->GetOrigin());
  m->SetDirection(ct->GetDirection());
  m->Allocate();
  const std::size_t n = m->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t i = 0; i < n; ++i) m->GetBufferPointer()[i] = (i * 7919) % 5 < 2 ? 1 : 0;
  itk::EncapsulateMetaData<std::string>(m->GetMetaDataDictionary(), "PatientPosition", "HFS");
  return m;
}

// A 0/1 mask (105 voxels: not a whole number of words; 140 000: many words over the threads) is
// held in one bit per voxel and comes back voxel for voxel with its grid and header.
TEST(CompactMask, BinaryMaskComesBackExactly) {
  for (const auto& [nx, ny, nz] : {std::array<unsigned, 3>{7, 5, 3}, std::array<unsigned, 3>{70, 50, 40}}) {
    const MaskImage::Pointer m = patterned_mask(nx, ny, nz);
    const std::size_t n = m->GetLargestPossibleRegion().GetNumberOfPixels();
    const std::shared_ptr<const CompactMask> c = compact_mask(*m);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->bits.size(), (n + 63) / 64);
    const MaskImage::Pointer back = expand_mask(*c);
    ASSERT_EQ(back->GetLargestPossibleRegion(), m->GetLargestPossibleRegion());  // before the voxels are read
    expect_same_grid(*back, *m, "HFS");
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(back->GetBufferPointer()[i], m->GetBufferPointer()[i]) << i;
  }
}

// A mask with any voxel other than 0 and 1 (a label map) stays as it is.
TEST(CompactMask, NonBinaryMaskIsNotCompacted) {
  for (unsigned char bad : {2, 255}) {
    MaskImage::Pointer m = patterned_mask(70, 50, 40);
    m->GetBufferPointer()[70 * 50 * 40 - 1] = bad;
    EXPECT_FALSE(compact_mask(*m)) << int(bad);
  }
}

// The mask artifact's hooks use them, and expanded() puts the mask back in the bag in its place.
TEST(CompactMask, MaskArtifactCompactsAndTheBagExpandsItOnRead) {
  const MaskImage::Pointer m = patterned_mask(7, 5, 3);
  const std::optional<std::any> stand_in = mask_artifact().compact(std::any(m));
  ASSERT_TRUE(stand_in);
  ASSERT_NE(std::any_cast<std::shared_ptr<const CompactMask>>(&*stand_in), nullptr);
  ArtifactBag bag;
  bag.put("mask", *stand_in);
  const MaskImage::Pointer back = expanded<MaskImage::Pointer>(bag, "mask", mask_artifact());
  ASSERT_NE(std::any_cast<MaskImage::Pointer>(&bag.raw("mask")), nullptr);
  EXPECT_NE(back.GetPointer(), m.GetPointer());
  for (std::size_t i = 0; i < 105; ++i) ASSERT_EQ(back->GetBufferPointer()[i], m->GetBufferPointer()[i]) << i;
}

// The volume and mask artifacts write their stand-ins (the 16-bit CT, the packed mask) to the very
// bytes they write for the values (the ArtifactType::write contract `colonflat run` relies on).
TEST(CompactCt, StandInsAreWrittenAsTheValues) {
  testing::TempDir tmp;
  const CtImage::Pointer ct = small_ct();
  const MaskImage::Pointer mask = patterned_mask(21, 5, 4);
  const std::pair<const ArtifactType*, std::any> cases[] = {{&volume_artifact(), std::any(ct)},
                                                            {&mask_artifact(), std::any(mask)}};
  for (const auto& [type, value] : cases) {
    const std::optional<std::any> stand_in = type->compact(value);
    ASSERT_TRUE(stand_in) << type->name;
    const fs::path a = tmp.path() / (type->name + "_value.nrrd"), b = tmp.path() / (type->name + "_stand_in.nrrd");
    type->write(value, a, a);
    type->write(*stand_in, b, b);
    const std::string bytes = testing::slurp(a);
    EXPECT_GT(bytes.size(), 100u) << type->name;
    EXPECT_EQ(bytes, testing::slurp(b)) << type->name;
  }
}

}  // namespace
}  // namespace cf
