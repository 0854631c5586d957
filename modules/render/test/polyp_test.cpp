// Polyp candidates: curvature signs on analytic shapes, detection of known bumps on a synthetic
// colon with haustral folds (folds not flagged), size estimates, known-polyp JSON and scoring.
#include <gtest/gtest.h>
#include <vtkIdList.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "colonflat/core/error.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/render/polyps.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

synthetic::ColonOptions polyp_colon() {
  return synthetic::colon_options(420, 20, 0.8, {{45, 0.3, 6}, {115, 2.0, 8}, {185, 4.0, 10}, {255, 1.0, 12}, {325, 5.5, 7}});
}

std::vector<KnownPolyp> truth(const synthetic::Colon& c) {
  std::vector<KnownPolyp> t;
  for (const auto& p : c.polyps) t.push_back({p.id, p.center, p.diameter, "sessile"});
  return t;
}

// A CT-like lumen mask of a horizontal tube (radius 11 mm, axis z, 0.7 mm voxels) with a tagged-fluid
// level at y = 4 mm (supine: +y down; gas above, fluid below, both lumen) whose one-voxel partial-
// volume layer is left out of the lumen over part of the level (a disc of radius 5 mm reaching the
// wall: what a segmentation missing part of the gas/fluid interface leaves), and two 9 mm
// hemispherical polyps on the wall: one far from the level (top wall, z = 75) and one standing
// in the fluid and through the level (-x wall at y = 4, z = 40). Meshed with flying edges,
// smoothed (windowed sinc) like reconstruct; outward normals.
struct MeniscusTube {
  TriangleList surface;
  std::vector<std::array<double, 3>> normals;
  std::vector<KnownPolyp> polyps;
};

MeniscusTube meniscus_tube() {
  const double h = 0.7, r = 11, level = 4;
  const int nx = 40, ny = 40, nz = 150;
  MeniscusTube t;
  t.polyps = {{1, {0, -r, 75}, 9, "sessile"}, {2, {-std::sqrt(r * r - level * level), level, 40}, 9, "sessile"}};
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(nx, ny, nz);
  img->SetSpacing(h, h, h);
  img->SetOrigin(-h * (nx - 1) / 2, -h * (ny - 1) / 2, -h * 5);
  img->AllocateScalars(VTK_FLOAT, 1);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double x = img->GetOrigin()[0] + i * h, y = img->GetOrigin()[1] + j * h, z = img->GetOrigin()[2] + k * h;
        const double zc = std::clamp(z, 15.0, 95.0);
        bool lumen = std::hypot(x, y, z - zc) < r;
        if (std::abs(y - level) < 0.5 * h && std::hypot(x - 6, z - 40) < 5) lumen = false;  // membrane
        for (const auto& p : t.polyps)
          if (std::hypot(x - p.center_lps_mm[0], y - p.center_lps_mm[1], z - p.center_lps_mm[2]) < 4.5) lumen = false;
        img->SetScalarComponentFromFloat(i, j, k, 0, lumen ? 1.0f : 0.0f);
      }
  auto fe = vtkSmartPointer<vtkFlyingEdges3D>::New();
  fe->SetInputData(img);
  fe->SetValue(0, 0.5);
  auto smooth = vtkSmartPointer<vtkWindowedSincPolyDataFilter>::New();
  smooth->SetInputConnection(fe->GetOutputPort());
  smooth->SetNumberOfIterations(20);
  smooth->SetPassBand(0.1);
  auto nf = vtkSmartPointer<vtkPolyDataNormals>::New();
  nf->SetInputConnection(smooth->GetOutputPort());
  nf->SplittingOff();
  nf->AutoOrientNormalsOn();  // closed surface: normals out of the lumen
  nf->Update();
  vtkPolyData* pd = nf->GetOutput();
  for (vtkIdType v = 0; v < pd->GetNumberOfPoints(); ++v) {
    double p[3], n[3];
    pd->GetPoint(v, p);
    pd->GetPointData()->GetNormals()->GetTuple(v, n);
    t.surface.points.push_back({p[0], p[1], p[2]});
    t.normals.push_back({n[0], n[1], n[2]});
  }
  auto ids = vtkSmartPointer<vtkIdList>::New();
  for (vtkIdType c = 0; c < pd->GetNumberOfCells(); ++c) {
    pd->GetCellPoints(c, ids);
    t.surface.triangles.push_back({int(ids->GetId(0)), int(ids->GetId(1)), int(ids->GetId(2))});
  }
  return t;
}

// Inside a tube (normals out of the lumen) the wall is a rut: SI ~ -0.5, curvedness 1/(r sqrt 2).
TEST(PolypCurvature, TubeWallIsRut) {
  const double r = 10;
  FlatMap f = flatten_colon(synthetic::open_cylinder(r, 60, 96, 90));
  std::vector<int> map;
  TriangleList s = flat_to_surface(f, &map);
  std::vector<std::array<double, 3>> n(s.points.size());
  for (std::size_t i = 0; i < map.size(); ++i) n[map[i]] = f.normal[i];
  Curvature c = surface_curvature(s, n, 2.5);
  int checked = 0;
  for (std::size_t v = 0; v < s.points.size(); v += 37) {
    if (s.points[v][2] < 10 || s.points[v][2] > 50) continue;
    EXPECT_NEAR(c.si[v], -0.5, 0.03);
    EXPECT_NEAR(c.cv[v], 1 / (r * std::sqrt(2.0)), 0.01);
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

// On a colon with folds and five polyps (6-12 mm): every polyp found near its apex, size within
// 35%, no fold flagged.
TEST(PolypDetect, FindsBumpsNotFolds) {
  auto c = synthetic::colon(polyp_colon());
  FlatMap f = flatten_colon(c.mesh);
  std::vector<int> map;
  TriangleList s = flat_to_surface(f, &map);
  std::vector<std::array<double, 3>> n(s.points.size());
  for (std::size_t i = 0; i < map.size(); ++i) n[map[i]] = f.normal[i];
  PolypOptions all;
  all.min_score = 0;
  for (const auto& k : detect_polyps(s, n, all))
    std::printf("cand %d at %.1f %.1f %.1f size %.1f score %.2f si %.2f cv %.3f cap %.1f elong %.2f\n", k.id,
                k.center_lps_mm[0], k.center_lps_mm[1], k.center_lps_mm[2], k.size_mm, k.score, k.mean_si, k.mean_cv,
                k.cap_area_mm2, k.elongation);
  auto cands = detect_polyps(s, n, PolypOptions{});
  const auto sc = score_detections(cands, truth(c), 6.0, 3.0);
  EXPECT_EQ(sc.polyps, 5);
  EXPECT_EQ(sc.polyps_detected, 5);
  EXPECT_EQ(sc.false_positives, 0);
  for (const auto& p : c.polyps)
    for (const auto& k : cands) {
      const double d = std::hypot(k.center_lps_mm[0] - p.center[0], k.center_lps_mm[1] - p.center[1],
                                  k.center_lps_mm[2] - p.center[2]);
      if (d < 3) EXPECT_NEAR(k.size_mm, p.diameter, 0.35 * p.diameter) << "polyp " << p.id;
    }
}

// A colon with folds only: no candidates.
TEST(PolypDetect, FoldsAloneGiveNoCandidates) {
  auto o = polyp_colon();
  o.polyps.clear();
  auto c = synthetic::colon(o);
  FlatMap f = flatten_colon(c.mesh);
  std::vector<int> map;
  TriangleList s = flat_to_surface(f, &map);
  std::vector<std::array<double, 3>> n(s.points.size());
  for (std::size_t i = 0; i < map.size(); ++i) n[map[i]] = f.normal[i];
  EXPECT_TRUE(detect_polyps(s, n, PolypOptions{}).empty());
}

// A fluid level's partial-volume membrane (one voxel between gas and tagged fluid, lumen on both
// sides) is not a polyp: both 9 mm polyps (one far from the level, one through it) are found, no
// candidate lies on the membrane.
TEST(PolypDetect, FluidLevelMembraneIsNotAPolyp) {
  const MeniscusTube t = meniscus_tube();
  const auto cands = detect_polyps(t.surface, t.normals, PolypOptions{});
  const auto sc = score_detections(cands, t.polyps, 6.0, 3.0);
  EXPECT_EQ(sc.polyps_detected, 2);
  EXPECT_EQ(sc.false_positives, 0);
}

// Known polyp lists: phantom-style objects and bare [x,y,z] lists; bad entries name the file.
TEST(PolypKnown, ReadsJsonLists) {
  testing::TempDir tmp;
  std::ofstream(tmp / "a.json") << R"([{"id": 7, "center_lps_mm": [1, 2, 3], "diameter_mm": 8, "type": "sessile"}])";
  std::ofstream(tmp / "b.json") << R"([[1, 2, 3], [4, 5, 6]])";
  std::ofstream(tmp / "c.json") << R"([{"id": 1}])";
  auto a = read_known_polyps(tmp / "a.json");
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].id, 7);
  EXPECT_EQ(a[0].diameter_mm, 8);
  EXPECT_EQ(read_known_polyps(tmp / "b.json").size(), 2u);
  EXPECT_THROW(read_known_polyps(tmp / "c.json"), InputError);
}

}  // namespace
}  // namespace cf
