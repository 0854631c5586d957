// Acceptance on a real CT colonography lumen mask (../shared/real, skipped when absent): the
// default sub-voxel surface is a closed oriented manifold with the staircase's components and
// genus, every vertex within half a voxel of the mask's voxel boundary; genus and time reported.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>

#include "colonflat/core/topology.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

namespace fs = std::filesystem;

// The real mask: closed manifold, max displacement <= 1/2 voxel, same components and genus as the
// staircase surface (the field keeps the binary mask's triangles).
TEST(ReconstructReal, SubvoxelSurfaceOfARealMask) {
  const fs::path file = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
  if (!fs::exists(file)) GTEST_SKIP() << file << " missing";
  const MaskImage::Pointer mask = read_mask(file);
  ReconstructStats st;
  const Mesh surface = reconstruct_surface(mask.GetPointer(), ReconstructOptions{}, &st);
  const TopologyReport t = analyze_topology(surface);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented);
  EXPECT_EQ(t.unreferenced_vertices, 0u);
  ASSERT_TRUE(t.genus);
  EXPECT_EQ(*t.genus, st.genus);
  EXPECT_EQ(st.field_source, "mask (sinc)");  // the mask-only default
  const BoundaryDistance d = distance_to_mask_boundary(surface, mask.GetPointer());
  EXPECT_EQ(d.far, 0u);
  EXPECT_LE(d.max_voxels, 0.5);
  ReconstructOptions raw;
  raw.subvoxel = "off";
  ReconstructStats raw_st;
  reconstruct_surface(mask.GetPointer(), raw, &raw_st);
  EXPECT_EQ(st.kept.size(), raw_st.kept.size());
  EXPECT_EQ(st.genus, raw_st.genus);
  EXPECT_EQ(st.faces, raw_st.faces);
  std::cout << "[ real ] " << st.faces << " faces, " << st.kept.size() << " components, genus " << st.genus
            << " (staircase " << raw_st.genus << "), max displacement " << d.max_voxels << " voxel (mean "
            << d.mean_voxels << "), field " << st.time_field_s << " s, total " << st.time_total_s << " s\n";
}

}  // namespace
}  // namespace cf
