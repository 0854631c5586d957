// Acceptance on medium-size realistic phantoms (issue 13): supine and prone, two fully tagged
// stretches, small bowel with oral contrast and gas bubbles, bladder with excreted contrast,
// enhanced aorta and a rectal tube: Dice >= 0.97, every fully tagged stretch kept, no small-bowel,
// bladder, vessel or tube voxel kept, gravity taken from the PatientPosition (medium-size phantoms).
#include <gtest/gtest.h>

#include <itkConnectedComponentImageFilter.h>

#include <map>

#include "colonflat/phantom/phantom.h"
#include "colonflat/segment/segment.h"
#include "segment_volumes.h"

namespace cf {
namespace {

// Voxels of each fully tagged stretch in the truth: lumen components of at least 1 mL that hold no
// colon gas (label 1); `small` counts the voxels of smaller gas-free lumen fragments.
std::vector<std::vector<std::size_t>> tagged_stretches(const Phantom& p, std::size_t& small) {
  using CC = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>;
  auto cc = CC::New();
  cc->SetInput(p.lumen);
  cc->Update();
  const std::uint32_t* lab = cc->GetOutput()->GetBufferPointer();
  const unsigned char* truth = p.labels->GetBufferPointer();
  const std::size_t n = p.lumen->GetLargestPossibleRegion().GetNumberOfPixels();
  std::vector<unsigned char> has_gas(cc->GetObjectCount() + 1, 0);
  for (std::size_t q = 0; q < n; ++q)
    if (truth[q] == 1) has_gas[lab[q]] = 1;
  std::map<std::uint32_t, std::vector<std::size_t>> by;
  for (std::size_t q = 0; q < n; ++q)
    if (lab[q] && !has_gas[lab[q]]) by[lab[q]].push_back(q);
  std::vector<std::vector<std::size_t>> out;
  const auto sp = p.lumen->GetSpacing();
  small = 0;
  for (auto& [l, v] : by) {
    if (double(v.size()) * sp[0] * sp[1] * sp[2] >= 1000.0) out.push_back(std::move(v));
    else small += v.size();
  }
  return out;
}

// Supine and prone phantoms of one seed with all the hard anatomy (two fully tagged stretches,
// small bowel with oral contrast and gas, bladder, aorta, rectal tube), at the medium size
// (256 x 256 x 200, 1.4 x 1.4 x 2 mm) to keep the test short; the full size is in segment_bench:
// Dice >= 0.97, every stretch kept, no small-bowel / bladder / aorta voxel, no rectal tube voxel.
TEST(SegmentAcceptance, RealisticPhantomsSupineAndProne) {
  for (const char* position : {"supine", "prone"}) {
    SCOPED_TRACE(position);
    PhantomOptions po;
    po.size = "medium";
    po.seed = 2;
    po.position = position;
    po.fully_tagged_segments = 2;
    po.oral_contrast = po.excreted_contrast = po.enhanced_vessels = po.rectal_tube = true;
    const Phantom p = generate_phantom(po);
    std::size_t fragments = 0;
    const auto stretches = tagged_stretches(p, fragments);
    ASSERT_EQ(stretches.size(), 2u) << stretches.size() << " gas-free lumen bodies; " << fragments << " voxels in fragments";
    SegmentStats st;
    auto m = segment_colon(p.ct, {}, &st);
    EXPECT_GE(dice(m, p.lumen), 0.97);
    EXPECT_EQ(st.gravity, std::string(position) == "prone" ? "-y (anterior)" : "+y (posterior)");
    EXPECT_NE(st.gravity_source.find("PatientPosition"), std::string::npos);
    for (const auto& s : stretches) {
      std::size_t kept = 0;
      for (std::size_t q : s) kept += m->GetBufferPointer()[q] != 0;
      EXPECT_GE(double(kept) / double(s.size()), 0.95) << s.size() << " voxels";
    }
    EXPECT_EQ(st.tagged_stretches, 2) << st.to_json()["decisions"].dump();
    std::size_t wrong[9] = {};
    const unsigned char* truth = p.labels->GetBufferPointer();
    for (std::size_t q = 0; q < p.lumen->GetLargestPossibleRegion().GetNumberOfPixels(); ++q)
      if (m->GetBufferPointer()[q]) ++wrong[truth[q]];
    EXPECT_EQ(wrong[3] + wrong[4], 0u) << "small-bowel voxels kept";
    EXPECT_EQ(wrong[5], 0u) << "bladder voxels kept";
    EXPECT_EQ(wrong[8], 0u) << "aorta voxels kept";
    const auto sp = p.lumen->GetSpacing();
    EXPECT_LT(double(wrong[6]) * sp[0] * sp[1] * sp[2] * 1e-3, 0.1) << "rectal tube kept (mL)";
  }
}

}  // namespace
}  // namespace cf
