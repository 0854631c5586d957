// Diagnosis of raw mesh data: each defect is found with its count and example ids.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "colonflat/core/error.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/core/validation.h"

namespace cf {
namespace {

PolygonSoup soup_of(const TriangleList& t) {
  PolygonSoup s;
  s.points = t.points;
  for (const auto& tri : t.triangles) {
    std::int64_t ids[3] = {tri[0], tri[1], tri[2]};
    s.add_face(ids, 3);
  }
  return s;
}

// A clean closed mesh has no finding at all.
TEST(Validation, CleanSphereHasNoFindings) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  auto d = diagnose_soup(s);
  EXPECT_TRUE(d.findings.empty()) << d.summary(Severity::kNote);
}

// An empty soup is fatal.
TEST(Validation, EmptyIsFatal) {
  PolygonSoup s;
  auto d = diagnose_soup(s);
  ASSERT_TRUE(d.has("empty"));
  EXPECT_TRUE(d.has_at_least(Severity::kFatal));
}

// NaN coordinates are fatal and named by vertex id and the bad coordinate.
TEST(Validation, NonFiniteCoordinatesAreFatal) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  s.points[7][1] = std::numeric_limits<double>::quiet_NaN();
  s.points[9][0] = std::numeric_limits<double>::infinity();
  auto d = diagnose_soup(s);
  const Finding* f = d.find("nonfinite_coordinates");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->count, 2u);
  EXPECT_NE(f->message.find("vertex 7: y = nan"), std::string::npos) << f->message;
  EXPECT_NE(f->message.find("vertex 9: x = inf"), std::string::npos) << f->message;
  EXPECT_THROW(soup_to_triangles(s, LoadPolicy{}, d), PreconditionError);
}

// Out-of-range vertex ids are fatal and name the face.
TEST(Validation, OutOfRangeIndicesAreFatal) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  std::int64_t bad[3] = {0, 1, 999};
  s.add_face(bad, 3);
  auto d = diagnose_soup(s);
  const Finding* f = d.find("index_out_of_range");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->count, 1u);
  EXPECT_NE(f->message.find("-> 999"), std::string::npos);
}

// Quads are fan-triangulated and reported as repaired.
TEST(Validation, PolygonsAreTriangulated) {
  PolygonSoup s;
  s.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  std::int64_t q[4] = {0, 1, 2, 3};
  s.add_face(q, 4);
  auto d = diagnose_soup(s);
  ASSERT_TRUE(d.has("non_triangle_faces"));
  EXPECT_EQ(d.find("non_triangle_faces")->severity, Severity::kRepaired);
  auto t = soup_to_triangles(s, LoadPolicy{}, d);
  EXPECT_EQ(t.triangles.size(), 2u);
  LoadPolicy strict;
  strict.triangulate = false;
  EXPECT_THROW(soup_to_triangles(s, strict, d), PreconditionError);
}

// Faces repeating a vertex id are defects and dropped on load.
TEST(Validation, DegenerateFacesAreFoundAndDropped) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  std::int64_t deg[3] = {3, 3, 4};
  s.add_face(deg, 3);
  auto d = diagnose_soup(s);
  ASSERT_TRUE(d.has("degenerate_faces"));
  EXPECT_EQ(d.find("degenerate_faces")->count, 1u);
  auto t = soup_to_triangles(s, LoadPolicy{}, d);
  EXPECT_EQ(t.triangles.size(), s.num_faces() - 1);
}

// Duplicate faces (same vertex set, either orientation) are counted.
TEST(Validation, DuplicateFacesAreCounted) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  std::int64_t dup[3] = {s.face(2)[0], s.face(2)[2], s.face(2)[1]};
  s.add_face(dup, 3);
  auto d = diagnose_soup(s);
  ASSERT_TRUE(d.has("duplicate_faces"));
  EXPECT_EQ(d.find("duplicate_faces")->count, 1u);
}

// Unreferenced vertices are reported and dropped; coincident points are noted.
TEST(Validation, UnreferencedAndCoincidentVertices) {
  auto s = soup_of(synthetic::sphere(1, 8, 4));
  s.points.push_back({5, 5, 5});
  s.points.push_back(s.points[3]);
  std::int64_t f[3] = {static_cast<std::int64_t>(s.points.size() - 1), 0, 1};
  s.add_face(f, 3);
  auto d = diagnose_soup(s);
  ASSERT_TRUE(d.has("unreferenced_vertices"));
  EXPECT_EQ(d.find("unreferenced_vertices")->count, 1u);
  ASSERT_TRUE(d.has("coincident_vertices"));
  EXPECT_EQ(d.find("coincident_vertices")->count, 1u);
  auto t = soup_to_triangles(s, LoadPolicy{}, d);
  EXPECT_EQ(t.points.size(), s.points.size() - 1);
}

// Topology findings: boundary is a note when allowed and a defect when a closed mesh is expected.
TEST(Validation, BoundarySeverityFollowsPolicy) {
  auto topo = analyze_topology(synthetic::disk(1, 3, 8));
  MeshDiagnosis open, closed;
  add_topology_findings(topo, true, open);
  add_topology_findings(topo, false, closed);
  EXPECT_EQ(open.find("boundary_edges")->severity, Severity::kNote);
  EXPECT_EQ(closed.find("boundary_edges")->severity, Severity::kDefect);
  EXPECT_NE(closed.find("boundary_edges")->message.find("8 boundary edges in 1 boundary loop"), std::string::npos);
}

// An inconsistently oriented mesh is re-oriented into a consistent OpenMesh mesh.
TEST(Validation, InconsistentOrientationIsFixed) {
  auto t = synthetic::torus(3, 1, 12, 6);
  for (std::size_t f = 0; f < t.triangles.size(); f += 3) std::swap(t.triangles[f][1], t.triangles[f][2]);
  auto topo = analyze_topology(t);
  ASSERT_GT(topo.inconsistent_edges, 0u);
  Mesh m = triangles_to_mesh(t, topo, true);
  auto after = analyze_topology(m);
  EXPECT_TRUE(after.consistently_oriented);
  EXPECT_EQ(after.genus, 1);
  EXPECT_THROW(triangles_to_mesh(t, topo, false), PreconditionError);
}

// A non-manifold soup cannot become a halfedge mesh: the error names the defect.
TEST(Validation, NonManifoldIsRefusedWithReason) {
  TriangleList m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  try {
    triangles_to_mesh(m, analyze_topology(m), true);
    FAIL() << "expected PreconditionError";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("1 non-manifold edge has 3 or more faces"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cf
