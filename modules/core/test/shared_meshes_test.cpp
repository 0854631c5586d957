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

// The diagnosis holds a finding `kind` counting `count` items.
void expect_finding(const MeshDiagnosis& diag, const std::string& kind, std::size_t count) {
  ASSERT_TRUE(diag.has(kind));
  EXPECT_EQ(diag.find(kind)->count, count) << kind;
}

// Each BAD_ mesh gets its specific diagnosis, with the manifest's counts.
TEST(SharedMeshesBad, SpecificDiagnoses) {
  const fs::path dir = fs::path(COLONFLAT_SHARED_DIR) / "meshes";
  {
    auto x = inspect(dir / "BAD_eight_open.off");
    expect_finding(x.diag, "boundary_edges", 96u);
    expect_finding(x.diag, "coincident_vertices", 48u);
  }
  {
    auto x = inspect(dir / "BAD_eight_hole.off");
    expect_finding(x.diag, "boundary_edges", 6u);
    EXPECT_EQ(x.topo.boundary_loops, 1u);
    EXPECT_FALSE(x.diag.has("nonmanifold_edges"));
  }
  {
    auto x = inspect(dir / "BAD_beast.off");
    expect_finding(x.diag, "nonmanifold_edges", 2u);
    expect_finding(x.diag, "nonmanifold_vertices", 4u);
  }
  {
    auto x = inspect(dir / "BAD_heptoroid_unwelded.off");
    expect_finding(x.diag, "boundary_edges", 11056u);
    expect_finding(x.diag, "coincident_vertices", 5291u);
    ASSERT_TRUE(x.diag.has("nonmanifold_vertices"));
  }
  {
    auto x = inspect(dir / "BAD_happy_vrip_res3.off");
    expect_finding(x.diag, "nonmanifold_edges", 2816u);
    ASSERT_TRUE(x.diag.has("duplicate_faces"));
  }
}

}  // namespace
}  // namespace cf
