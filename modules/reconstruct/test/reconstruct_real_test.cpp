// Acceptance on a real CT colonography lumen mask (../shared/real, skipped when absent): the
// default sub-voxel surface is a closed oriented manifold with the staircase's components and
// genus, every vertex within half a voxel of the mask's voxel boundary, and the constrained fairing
// makes it markedly smoother than windowed sinc alone; genus and time reported.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>

#include "colonflat/core/topology.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

namespace fs = std::filesystem;

// RMS angle (degrees) between the normals of the two faces at each edge: the surface's roughness
// at the scale of one triangle (the staircase's terraces and the ripples they leave).
double dihedral_rms_degrees(Mesh& m) {
  m.request_face_normals();
  m.update_face_normals();
  double sum = 0;
  std::size_t count = 0;
  for (auto e : m.edges()) {
    const auto h = m.halfedge_handle(e, 0);
    const auto a = m.normal(m.face_handle(h)), b = m.normal(m.opposite_face_handle(h));
    const double degrees = std::acos(std::max(-1.0, std::min(1.0, double(a | b)))) * 180.0 / M_PI;
    sum += degrees * degrees;
    ++count;
  }
  return count ? std::sqrt(sum / double(count)) : 0.0;
}

// The real mask: closed manifold, max displacement <= 1/2 voxel, same components and genus as the
// staircase surface (the field keeps the binary mask's triangles).
TEST(ReconstructReal, SubvoxelSurfaceOfARealMask) {
  const fs::path file = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
  if (!fs::exists(file)) GTEST_SKIP() << file << " missing";
  const MaskImage::Pointer mask = read_mask(file);
  ReconstructStats st;
  Mesh surface = reconstruct_surface(mask.GetPointer(), ReconstructOptions{}, &st);
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
  // The fairing ran, lowered its energy and made the wall smoother than windowed sinc alone.
  EXPECT_EQ(st.fairing_iterations, ReconstructOptions{}.fairing_iterations);
  EXPECT_LT(st.fairing_energy_after, 0.7 * st.fairing_energy_before);
  ReconstructOptions no_fairing;
  no_fairing.fairing_iterations = 0;
  Mesh sinc_only = reconstruct_surface(mask.GetPointer(), no_fairing);
  const double faired_degrees = dihedral_rms_degrees(surface), sinc_degrees = dihedral_rms_degrees(sinc_only);
  EXPECT_LT(faired_degrees, 0.8 * sinc_degrees);
  std::cout << "[ real ] dihedral RMS " << faired_degrees << " deg with fairing, " << sinc_degrees
            << " deg windowed sinc alone; fairing energy " << st.fairing_energy_before << " -> "
            << st.fairing_energy_after << " mm^2, " << st.fairing_vertices_at_limit << " vertices at 1/2 voxel, "
            << st.time_fairing_s << " s\n";
  std::cout << "[ real ] " << st.faces << " faces, " << st.kept.size() << " components, genus " << st.genus
            << " (staircase " << raw_st.genus << "), max displacement " << d.max_voxels << " voxel (mean "
            << d.mean_voxels << "), field " << st.time_field_s << " s, total " << st.time_total_s << " s\n";
}

}  // namespace
}  // namespace cf
