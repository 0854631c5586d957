// The phantom's prone position (issue 17 contract 4), fully tagged stretches and the extra anatomy
// of issue 13 (small bowel with oral contrast, bladder, aorta, rectal tube), their ground truth and
// the DICOM PatientPosition written with the volume.
#include <gtest/gtest.h>

#include <itkConnectedComponentImageFilter.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstring>

#include "colonflat/core/stage.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

Phantom make(const std::string& position, int tagged = 0, bool extras = false, std::uint64_t seed = 1) {
  PhantomOptions o;
  o.size = "small";
  o.seed = seed;
  o.position = position;
  o.fully_tagged_segments = tagged;
  o.oral_contrast = o.excreted_contrast = o.enhanced_vessels = o.rectal_tube = extras;
  return generate_phantom(o);
}

std::size_t lumen_components(const MaskImage* m) {
  auto cc = itk::ConnectedComponentImageFilter<MaskImage, itk::Image<std::uint32_t, 3>>::New();
  cc->SetInput(m);
  cc->SetFullyConnected(false);
  cc->Update();
  return cc->GetObjectCount();
}

// Mean LPS y (mm) of the voxels with truth label `label`.
double mean_y(const Phantom& p, unsigned char label) {
  const auto sz = p.labels->GetLargestPossibleRegion().GetSize();
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t k = 0, q = 0; k < sz[2]; ++k)
    for (std::size_t j = 0; j < sz[1]; ++j)
      for (std::size_t i = 0; i < sz[0]; ++i, ++q)
        if (p.labels->GetBufferPointer()[q] == label) sum += p.labels->GetOrigin()[1] + double(j) * p.labels->GetSpacing()[1], ++n;
  return n ? sum / double(n) : NAN;
}

// Mean CT value (HU) on rings of radius 4, 5 and 6 mm (8 directions each) perpendicular to the
// centreline at every point where the lumen is fully collapsed (radius 0); NaN if there is none.
double collapsed_neck_ring_hu(const Phantom& p) {
  const auto& c = p.centerline;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 2; i + 2 < c.size(); ++i) {
    if (c[i].radius_mm > 0) continue;
    const Eigen::Vector3d x(c[i].p_lps_mm.data()), T = (Eigen::Vector3d(c[i + 2].p_lps_mm.data()) - Eigen::Vector3d(c[i - 2].p_lps_mm.data())).normalized();
    const Eigen::Vector3d U = T.unitOrthogonal(), V = T.cross(U);
    for (double r : {4.0, 5.0, 6.0})
      for (int a = 0; a < 8; ++a) {
        const Eigen::Vector3d q = x + r * (std::cos(a * M_PI / 4) * U + std::sin(a * M_PI / 4) * V);
        CtImage::PointType pt;
        for (int d = 0; d < 3; ++d) pt[d] = q[d];
        CtImage::IndexType id;
        if (p.ct->TransformPhysicalPointToIndex(pt, id)) sum += p.ct->GetPixel(id), ++n;
      }
  }
  return n ? sum / double(n) : NAN;
}

// Prone and supine of a seed: the same polyps (id, size, type, position along the colon within
// 3 %), the fixed rectum identical, the transverse colon moved, fluid anterior instead of posterior.
TEST(PhantomPosition, ProneIsTheSameColonDeformed) {
  const Phantom sup = make("supine"), pro = make("prone");
  EXPECT_EQ(sup.patient_position, "HFS");
  EXPECT_EQ(pro.patient_position, "HFP");
  ASSERT_EQ(sup.polyps.size(), pro.polyps.size());
  double moved = 0;
  for (std::size_t i = 0; i < sup.polyps.size(); ++i) {
    const auto &a = sup.polyps[i], &b = pro.polyps[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.diameter_mm, b.diameter_mm);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.segment, b.segment);
    EXPECT_NEAR(a.centreline_mm, b.centreline_mm, 0.03 * a.centreline_mm);
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += std::pow(a.center_lps_mm[k] - b.center_lps_mm[k], 2);
    moved = std::max(moved, std::sqrt(d2));
  }
  EXPECT_GT(moved, 3.0);  // at least one polyp lies on the mobile colon
  ASSERT_EQ(sup.centerline.size(), pro.centerline.size());
  double rect = 0, trans = 0;
  for (std::size_t i = 0; i < sup.centerline.size(); ++i) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += std::pow(sup.centerline[i].p_lps_mm[k] - pro.centerline[i].p_lps_mm[k], 2);
    if (sup.centerline[i].segment == "rectum") rect = std::max(rect, std::sqrt(d2));
    if (sup.centerline[i].segment == "transverse") trans = std::max(trans, std::sqrt(d2));
  }
  EXPECT_EQ(rect, 0.0);
  EXPECT_GT(trans, 6.0);
  EXPECT_GT(mean_y(sup, 2), mean_y(sup, 1));  // supine: fluid posterior of the gas
  EXPECT_LT(mean_y(pro, 2), mean_y(pro, 1));  // prone: fluid anterior
  EXPECT_EQ(pro.description["dicom_patient_position"], "HFP");
  EXPECT_EQ(lumen_components(pro.lumen), 1u);
}

// K fully tagged stretches: each a lumen component of colon fluid only, so the lumen splits into
// 2K + 1 components; their volumes are reported.
TEST(PhantomPosition, FullyTaggedStretches) {
  for (const char* position : {"supine", "prone"}) {
    SCOPED_TRACE(position);
    const Phantom p = make(position, 2);
    const auto& st = p.description["colon"]["fully_tagged_stretches"];
    ASSERT_EQ(st.size(), 2u);
    for (const auto& s : st) EXPECT_GT(s["volume_ml"].get<double>(), 10);
    EXPECT_EQ(lumen_components(p.lumen), 5u);
  }
}

// A collapsed neck keeps the open colon's wall tissue (walls apposed, no fat between them): the
// rings 4-6 mm around its axis are soft tissue (mean > -30 HU, fat is -90), supine and prone.
TEST(PhantomPosition, CollapsedNecksAreWallNotFat) {
  for (const char* position : {"supine", "prone"}) {
    SCOPED_TRACE(position);
    const double hu = collapsed_neck_ring_hu(make(position, 2));
    ASSERT_FALSE(std::isnan(hu));
    EXPECT_GT(hu, -30);
  }
}

// Oral contrast, bladder, aorta and rectal tube: present in the truth labels, none of it lumen,
// small-bowel contrast bright in the CT, gas bubbles small, the tube reaching the inferior face.
TEST(PhantomPosition, ExtraAnatomyInTruth) {
  const Phantom p = make("supine", 0, true, 3);
  const unsigned char* lab = p.labels->GetBufferPointer();
  const unsigned char* lum = p.lumen->GetBufferPointer();
  const float* hu = p.ct->GetBufferPointer();
  std::size_t count[9] = {}, in_lumen = 0;
  double contrast_hu = 0;
  const std::size_t n = p.lumen->GetLargestPossibleRegion().GetNumberOfPixels();
  for (std::size_t q = 0; q < n; ++q) {
    ++count[lab[q]];
    if (lab[q] >= 3 && lab[q] != 7) in_lumen += lum[q];
    if (lab[q] == 3) contrast_hu += hu[q];
  }
  for (int l : {3, 4, 5, 6, 8}) EXPECT_GT(count[l], 0u) << l;
  EXPECT_EQ(in_lumen, 0u);
  EXPECT_GT(contrast_hu / double(count[3]), 250);
  const double voxel_ml = 2.8 * 2.8 * 3.125 / 1000;
  EXPECT_LT(double(count[4]) * voxel_ml, 15);  // a few bubbles
  EXPECT_GT(double(count[3]) * voxel_ml, 30);  // loops of contrast
  const auto sz = p.labels->GetLargestPossibleRegion().GetSize();
  bool tube_at_face = false;
  for (std::size_t q = 0; q < sz[0] * sz[1]; ++q) tube_at_face = tube_at_face || lab[q] == 6;
  EXPECT_TRUE(tube_at_face);
  EXPECT_EQ(lumen_components(p.lumen), 1u);
}

// The PatientPosition is written with the CT (NRRD and DICOM) and read back.
TEST(PhantomPosition, PatientPositionWrittenAndRead) {
  testing::TempDir tmp;
  const Phantom p = make("prone");
  write_phantom(p, tmp / "n", "nrrd");
  write_phantom(p, tmp / "d", "dicom");
  EXPECT_EQ(patient_position(read_ct_volume(tmp / "n" / "ct.nrrd")), "HFP");
  EXPECT_EQ(patient_position(read_ct_volume(tmp / "d" / "dicom")), "HFP");
  EXPECT_TRUE(fs::exists(tmp / "n" / "labels.nrrd"));
  const auto polyps = read_json_file(tmp / "n" / "polyps.json");
  ASSERT_FALSE(polyps.empty());
  EXPECT_TRUE(polyps[0].contains("position_lps_mm"));
  EXPECT_TRUE(polyps[0].contains("centreline_mm"));
}

// Invalid position and stretch count are usage errors.
TEST(PhantomPosition, InvalidOptionsRejected) {
  PhantomOptions o;
  o.position = "standing";
  EXPECT_THROW(generate_phantom(o), UsageError);
  o = {};
  o.fully_tagged_segments = 4;
  EXPECT_THROW(generate_phantom(o), UsageError);
}

}  // namespace
}  // namespace cf
