// Every mesh in ../shared/meshes agrees with MANIFEST.tsv (genus, components, closed, manifold,
// Euler characteristic, defect counts); every BAD_ mesh yields its specific diagnosis.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/validation.h"
#include "colonflat/testing/manifest.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

using Row = testing::ManifestRow;
std::vector<Row> read_manifest() { return testing::read_mesh_manifest(); }

struct Inspected {
  MeshDiagnosis diag;
  TopologyReport topo;
};

Inspected inspect(const fs::path& p) {
  Inspected x;
  PolygonSoup soup = read_polygon_soup(p);
  x.diag = diagnose_soup(soup);
  TriangleList t = soup_to_triangles(soup, LoadPolicy{}, x.diag);
  x.topo = analyze_topology(t);
  add_topology_findings(x.topo, false, x.diag);
  return x;
}

class SharedMeshes : public ::testing::TestWithParam<std::string> {};

std::vector<std::string> mesh_names() {
  std::vector<std::string> names;
  for (const auto& r : read_manifest()) names.push_back(r.at("name"));
  return names;
}

Row row_of(const std::string& name) {
  for (const auto& r : read_manifest())
    if (r.at("name") == name) return r;
  return {};
}

// Topology of each shared mesh matches the manifest's columns.
TEST_P(SharedMeshes, MatchesManifest) {
  const Row r = row_of(GetParam());
  const fs::path p = fs::path(COLONFLAT_SHARED_DIR) / "meshes" / (r.at("name") + ".off");
  const Inspected x = inspect(p);
  const auto& t = x.topo;
  EXPECT_EQ(t.faces, std::stoul(r.at("faces")));
  EXPECT_EQ(t.vertices + t.unreferenced_vertices, std::stoul(r.at("vertices")));
  EXPECT_EQ(t.components.size(), std::stoul(r.at("components")));
  EXPECT_EQ(t.closed, r.at("closed") == "True");
  EXPECT_EQ(t.manifold, r.at("manifold") == "True");
  EXPECT_EQ(t.orientable, r.at("orientable") == "True");
  EXPECT_EQ(t.boundary_edges, std::stoul(r.at("boundary_edges")));
  EXPECT_EQ(t.nonmanifold_edges, std::stoul(r.at("nonmanifold_edges")));
  if (r.at("genus") != "NA") {
    ASSERT_TRUE(t.genus.has_value());
    EXPECT_EQ(*t.genus, std::stoi(r.at("genus")));
    EXPECT_EQ(t.euler, std::stoll(r.at("euler")));
    EXPECT_EQ(*t.components.front().genus, std::stoi(r.at("largest_component_genus")));
    EXPECT_FALSE(x.diag.has_at_least(Severity::kDefect)) << x.diag.summary(Severity::kDefect);
  } else {
    EXPECT_TRUE(x.diag.has_at_least(Severity::kDefect)) << "a BAD_ mesh must be diagnosed";
  }
}

INSTANTIATE_TEST_SUITE_P(Manifest, SharedMeshes, ::testing::ValuesIn(mesh_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) { return i.param; });

// The manifest is there and lists the meshes this suite expects (a missing ../shared fails loudly).
TEST(SharedMeshesManifest, IsPresent) {
  EXPECT_GE(read_manifest().size(), 20u) << "expected ../shared/meshes/MANIFEST.tsv beside the checkout";
}

// Each BAD_ mesh gets its specific diagnosis, with the manifest's counts.
TEST(SharedMeshesBad, SpecificDiagnoses) {
  const fs::path dir = fs::path(COLONFLAT_SHARED_DIR) / "meshes";
  {
    auto x = inspect(dir / "BAD_eight_open.off");
    ASSERT_TRUE(x.diag.has("boundary_edges"));
    EXPECT_EQ(x.diag.find("boundary_edges")->count, 96u);
    ASSERT_TRUE(x.diag.has("coincident_vertices"));
    EXPECT_EQ(x.diag.find("coincident_vertices")->count, 48u);
  }
  {
    auto x = inspect(dir / "BAD_eight_hole.off");
    ASSERT_TRUE(x.diag.has("boundary_edges"));
    EXPECT_EQ(x.diag.find("boundary_edges")->count, 6u);
    EXPECT_EQ(x.topo.boundary_loops, 1u);
    EXPECT_FALSE(x.diag.has("nonmanifold_edges"));
  }
  {
    auto x = inspect(dir / "BAD_beast.off");
    ASSERT_TRUE(x.diag.has("nonmanifold_edges"));
    EXPECT_EQ(x.diag.find("nonmanifold_edges")->count, 2u);
    ASSERT_TRUE(x.diag.has("nonmanifold_vertices"));
    EXPECT_EQ(x.diag.find("nonmanifold_vertices")->count, 4u);
  }
  {
    auto x = inspect(dir / "BAD_heptoroid_unwelded.off");
    ASSERT_TRUE(x.diag.has("boundary_edges"));
    EXPECT_EQ(x.diag.find("boundary_edges")->count, 11056u);
    ASSERT_TRUE(x.diag.has("coincident_vertices"));
    EXPECT_EQ(x.diag.find("coincident_vertices")->count, 5291u);
    ASSERT_TRUE(x.diag.has("nonmanifold_vertices"));
  }
  {
    auto x = inspect(dir / "BAD_happy_vrip_res3.off");
    ASSERT_TRUE(x.diag.has("nonmanifold_edges"));
    EXPECT_EQ(x.diag.find("nonmanifold_edges")->count, 2816u);
    ASSERT_TRUE(x.diag.has("duplicate_faces"));
  }
}

}  // namespace
}  // namespace cf
