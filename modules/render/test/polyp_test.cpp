// Polyp candidates: curvature signs on analytic shapes, detection of known bumps on a synthetic
// colon with haustral folds (folds not flagged), size estimates, known-polyp JSON and scoring.
#include <gtest/gtest.h>

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
