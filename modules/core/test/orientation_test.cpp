// Orientation of surfaces from other tools (orientation.h): signed volume and nesting depth per
// component, inward components reversed, flipped patches turned back, non-orientable surfaces
// refused with the reason, and the read-time turns reported by the stage helper.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/orientation.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

TriangleList reversed(TriangleList t) {
  for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
  return t;
}

std::vector<ComponentSide> sides_of(const TriangleList& t) { return component_sides(t, analyze_topology(t)); }

OrientationReport orient(TriangleList& t) { return orient_outward(t, analyze_topology(t)); }

TriangleList moebius_strip() {
  TriangleList m;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, w = 0.3, c = std::cos(a / 2) * w;
    m.points.push_back({(1 + c) * std::cos(a), (1 + c) * std::sin(a), std::sin(a / 2) * w});
    m.points.push_back({(1 - c) * std::cos(a), (1 - c) * std::sin(a), -std::sin(a / 2) * w});
  }
  for (int i = 0; i < n; ++i) {
    int a0 = 2 * i, a1 = 2 * i + 1, b0 = 2 * (i + 1), b1 = 2 * (i + 1) + 1;
    if (i == n - 1) b0 = 1, b1 = 0;  // the half twist
    m.triangles.push_back({a0, b0, b1});
    m.triangles.push_back({a0, b1, a1});
  }
  return m;
}

// The faces of `t` whose first vertex lies above z = `z0` (a cap-shaped patch on a sphere).
std::vector<std::size_t> patch_above(const TriangleList& t, double z0) {
  std::vector<std::size_t> out;
  for (std::size_t f = 0; f < t.triangles.size(); ++f)
    if (t.points[std::size_t(t.triangles[f][0])][2] > z0) out.push_back(f);
  return out;
}

// The signed volume of an outward sphere is its volume, positive; reversed it is negative, and
// only the reversed one points into the lumen.
TEST(CoreOrientation, SignedVolumeSignOfASphere) {
  const TriangleList s = synthetic::sphere(10, 48, 24);
  const auto out = sides_of(s), in = sides_of(reversed(s));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].volume_mm3, 4.0 / 3.0 * M_PI * 1000, 0.03 * 4.0 / 3.0 * M_PI * 1000);
  EXPECT_NEAR(in[0].volume_mm3, -out[0].volume_mm3, 1e-9 * out[0].volume_mm3);
  EXPECT_EQ(out[0].depth, 0);
  EXPECT_FALSE(out[0].inward());
  EXPECT_TRUE(in[0].inward());
}

// An inward torus is reversed back exactly (same triangles as the outward one), and the note
// says what was done.
TEST(CoreOrientation, InwardTorusIsReversedToTheOutwardOne) {
  const TriangleList outward = synthetic::torus(30, 10, 40, 16);
  TriangleList t = reversed(outward);
  const OrientationReport r = orient(t);
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_TRUE(r.changes[0].reversed);
  EXPECT_LT(r.changes[0].volume_mm3, 0);
  EXPECT_EQ(r.changes[0].faces, outward.triangles.size());
  EXPECT_NE(r.notes()[0].find("component 0 (1280 faces, "), std::string::npos) << r.notes()[0];
  EXPECT_NE(r.notes()[0].find("normals pointed into the lumen; reversed"), std::string::npos) << r.notes()[0];
  EXPECT_EQ(t.triangles, outward.triangles);
  EXPECT_TRUE(orient(t).empty());  // outward: nothing to do
}

// Components are oriented one by one: of an outward sphere, an inward torus and an inward open
// tube, only the torus is reversed (an open component has no volume: kept).
TEST(CoreOrientation, EachComponentOnItsOwn) {
  const TriangleList sphere = synthetic::sphere(10, 24, 12), torus = synthetic::torus(30, 10, 40, 16);
  const TriangleList tube = synthetic::translated(reversed(synthetic::open_cylinder(5, 40, 16, 8)), 0, 200, 0);
  TriangleList t = synthetic::disjoint_union(synthetic::disjoint_union(synthetic::translated(sphere, 100, 0, 0), reversed(torus)), tube);
  const TopologyReport topo = analyze_topology(t);
  const OrientationReport r = orient_outward(t, topo);
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(topo.components[std::size_t(r.changes[0].component)].faces, torus.triangles.size());
  const TriangleList expected = synthetic::disjoint_union(synthetic::disjoint_union(synthetic::translated(sphere, 100, 0, 0), torus), tube);
  EXPECT_EQ(t.triangles, expected.triangles);
}

// A cavity (a small sphere inside a large one) must face into itself, negative volume, as
// reconstruct writes it: kept; facing out it is reversed; and when every normal of the pair is
// reversed, both are reversed back.
TEST(CoreOrientation, CavityWallFacesIntoTheCavity) {
  const TriangleList outer = synthetic::sphere(50, 48, 24), cavity = reversed(synthetic::sphere(10, 24, 12));
  TriangleList good = synthetic::disjoint_union(outer, synthetic::translated(cavity, 5, 3, 2));
  const auto sides = sides_of(good);
  ASSERT_EQ(sides.size(), 2u);
  EXPECT_EQ(sides[1].depth, 1);
  EXPECT_TRUE(sides[1].cavity());
  EXPECT_LT(sides[1].volume_mm3, 0);
  const TriangleList expected = good;
  EXPECT_TRUE(orient(good).empty());
  TriangleList wrong_cavity = synthetic::disjoint_union(outer, synthetic::translated(reversed(cavity), 5, 3, 2));
  EXPECT_EQ(orient(wrong_cavity).reversed_components(), 1u);
  EXPECT_EQ(wrong_cavity.triangles, expected.triangles);
  TriangleList all_inward = reversed(expected);
  EXPECT_EQ(orient(all_inward).reversed_components(), 2u);
  EXPECT_EQ(all_inward.triangles, expected.triangles);
}

// A patch of flipped faces (a polar cap, 10 % of a sphere) is turned back, and only the patch;
// when the flipped part is the majority (all but the cap), the minority is turned and the
// then inward sphere reversed: either way the outward sphere comes back.
TEST(CoreOrientation, FlippedPatchIsTurnedBack) {
  const TriangleList sphere = synthetic::sphere(10, 48, 24);
  const auto cap = patch_above(sphere, 8.0);
  ASSERT_GT(cap.size(), 20u);
  ASSERT_LT(cap.size(), sphere.triangles.size() / 5);
  TriangleList t = sphere;
  for (std::size_t f : cap) std::swap(t.triangles[f][1], t.triangles[f][2]);
  OrientationReport r = make_consistent(t, analyze_topology(t));
  ASSERT_EQ(r.changes.size(), 1u);
  EXPECT_EQ(r.changes[0].flipped_faces, cap.size());
  EXPECT_FALSE(r.changes[0].reversed);
  EXPECT_NE(r.notes()[0].find(std::to_string(cap.size()) + " faces were oriented against their neighbours"), std::string::npos);
  EXPECT_EQ(t.triangles, sphere.triangles);

  TriangleList most = reversed(sphere);
  for (std::size_t f : cap) std::swap(most.triangles[f][1], most.triangles[f][2]);
  r = make_consistent(most, analyze_topology(most));
  EXPECT_EQ(r.flipped_faces(), cap.size());
  r.append(orient(most));
  EXPECT_EQ(r.reversed_components(), 1u);
  EXPECT_EQ(most.triangles, sphere.triangles);
}

// A Moebius strip has no inside: refused with the component, its size and the reason.
TEST(CoreOrientation, NonOrientableIsRefusedWithTheReason) {
  TriangleList m = moebius_strip();
  try {
    make_consistent(m, analyze_topology(m));
    FAIL() << "expected PreconditionError";
  } catch (const PreconditionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("component 0 (24 faces"), std::string::npos) << what;
    EXPECT_NE(what.find("is not orientable"), std::string::npos) << what;
  }
}

// orient_outward on an OpenMesh mesh rebuilds it reversed, same vertices in the same order.
TEST(CoreOrientation, MeshIsRebuiltOutward) {
  const TriangleList outward = synthetic::torus(30, 10, 40, 16);
  Mesh m = synthetic::to_mesh(reversed(outward));
  EXPECT_EQ(orient_outward(m).reversed_components(), 1u);
  EXPECT_EQ(to_triangle_list(m).triangles, outward.triangles);
  EXPECT_EQ(to_triangle_list(m).points, outward.points);
}

void write_off(const TriangleList& t, const std::filesystem::path& p) {
  std::ofstream o(p);
  o << "OFF\n" << t.points.size() << " " << t.triangles.size() << " 0\n";
  o.precision(17);
  for (const auto& q : t.points) o << q[0] << " " << q[1] << " " << q[2] << "\n";
  for (const auto& tr : t.triangles) o << "3 " << tr[0] << " " << tr[1] << " " << tr[2] << "\n";
}

// A file whose faces disagree (an inward sphere with its cap flipped) and a stage reading it: the
// reader turns the cap, the stage helper reverses the sphere; the report and the progress lines
// say both, and the bag holds the outward sphere.
TEST(CoreOrientation, StageInputReportsWhatWasTurnedAndReversed) {
  const TriangleList sphere = synthetic::sphere(10, 48, 24);
  TriangleList t = reversed(sphere);
  const auto cap = patch_above(sphere, 8.0);
  for (std::size_t f : cap) std::swap(t.triangles[f][1], t.triangles[f][2]);
  testing::TempDir tmp;
  write_off(t, tmp / "in.off");
  ArtifactBag bag;
  bag.put("surface", mesh_artifact().read(tmp / "in.off"));
  std::ostringstream log;
  RunContext ctx;
  ctx.log = &log;
  const nlohmann::json j = orient_mesh_input(bag, "surface", ctx, "denoise");
  EXPECT_EQ(j["reversed_components"], 1);
  EXPECT_EQ(j["flipped_faces"], cap.size());
  EXPECT_NE(log.str().find("denoise: surface: component 0 (" + std::to_string(sphere.triangles.size()) + " faces, "), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("normals pointed into the lumen; reversed"), std::string::npos) << log.str();
  EXPECT_EQ(to_triangle_list(bag.get<Mesh>("surface")).triangles, sphere.triangles);
  OpenMesh::MPropHandleT<std::string> h;
  EXPECT_FALSE(bag.get<Mesh>("surface").get_property_handle(h, kReadOrientationProperty));
}

// The topology a stage gets back from orienting its input (render's snapshot caption uses its
// genus) is the reversed mesh's own: an inward torus beside an outward sphere gives genus 1 in
// two components, as analyze_topology of the bag's mesh says afterwards.
TEST(CoreOrientation, StageInputHandsBackTheMeshTopology) {
  const TriangleList t = synthetic::disjoint_union(reversed(synthetic::torus(30, 10, 40, 16)),
                                                   synthetic::translated(synthetic::sphere(10, 24, 12), 100, 0, 0));
  ArtifactBag bag;
  bag.put("surface", synthetic::to_mesh(t));
  RunContext ctx;
  TopologyReport topo;
  const nlohmann::json j = orient_mesh_input(bag, "surface", ctx, "render", &topo);
  EXPECT_EQ(j["reversed_components"], 1);
  const TopologyReport after = analyze_topology(bag.get<Mesh>("surface"));
  ASSERT_TRUE(topo.genus.has_value());
  EXPECT_EQ(*topo.genus, 1);
  EXPECT_EQ(topo.genus, after.genus);
  ASSERT_EQ(topo.components.size(), 2u);
  ASSERT_EQ(after.components.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(topo.components[c].faces, after.components[c].faces);
    EXPECT_EQ(topo.components[c].euler, after.components[c].euler);
  }
}

// oriented_mesh_input orients as orient_mesh_input does (an inward torus reversed in the bag, the
// same report and progress line) and hands back the bag mesh's triangle list with its topology.
TEST(CoreOrientation, OrientedInputEqualsOrientMeshInput) {
  const TriangleList inward = reversed(synthetic::torus(30, 10, 40, 16));
  ArtifactBag a, b;
  a.put("denoised", synthetic::to_mesh(inward));
  b.put("denoised", synthetic::to_mesh(inward));
  std::ostringstream log_a, log_b;
  RunContext ctx_a, ctx_b;
  ctx_a.log = &log_a, ctx_b.log = &log_b;
  const nlohmann::json ja = orient_mesh_input(a, "denoised", ctx_a, "flatten");
  const OrientedMesh in = oriented_mesh_input(b, "denoised", ctx_b, "flatten");
  EXPECT_EQ(in.orientation, ja);
  EXPECT_EQ(in.orientation["reversed_components"], 1);
  EXPECT_EQ(log_b.str(), log_a.str());
  const TriangleList bag_list = to_triangle_list(b.get<Mesh>("denoised"));
  EXPECT_EQ(to_triangle_list(a.get<Mesh>("denoised")).triangles, bag_list.triangles);
  EXPECT_EQ(in.triangles().triangles, bag_list.triangles);
  EXPECT_EQ(in.topology.face_component, analyze_topology(bag_list).face_component);
  EXPECT_EQ(in.topology.genus, std::optional<int>(1));
}

// On the mesh's stand-in (the triangle list `colonflat run` holds it as), oriented_mesh_input and
// orient_surface orient as on the mesh: the same report and progress lines, the bag's list itself
// reversed in place (no copy: triangles() is that list) and equal to the mesh's, the same topology.
TEST(CoreOrientation, StandInIsOrientedAsTheMesh) {
  const TriangleList inward = reversed(synthetic::torus(30, 10, 40, 16));
  ArtifactBag a, b, c;
  a.put("denoised", synthetic::to_mesh(inward));
  b.put("denoised", to_triangle_list(synthetic::to_mesh(inward)));
  c.put("surface", to_triangle_list(synthetic::to_mesh(inward)));
  std::ostringstream log_a, log_b, log_c;
  RunContext ctx_a, ctx_b, ctx_c;
  ctx_a.log = &log_a, ctx_b.log = &log_b, ctx_c.log = &log_c;
  const OrientedMesh on_mesh = oriented_mesh_input(a, "denoised", ctx_a, "flatten");
  const OrientedMesh on_list = oriented_mesh_input(b, "denoised", ctx_b, "flatten");
  EXPECT_EQ(on_list.orientation, on_mesh.orientation);
  EXPECT_EQ(on_list.orientation["reversed_components"], 1);
  EXPECT_EQ(log_b.str(), log_a.str());
  EXPECT_EQ(&on_list.triangles(), &b.get<TriangleList>("denoised"));
  EXPECT_EQ(on_list.triangles().triangles, on_mesh.triangles().triangles);
  EXPECT_EQ(on_list.triangles().triangles, to_triangle_list(a.get<Mesh>("denoised")).triangles);
  EXPECT_EQ(on_list.topology.face_component, on_mesh.topology.face_component);
  TopologyReport topo;
  const nlohmann::json j = orient_surface(bag_surface_for_orienting(c, "surface"), ctx_c, "render", "surface", &topo);
  EXPECT_EQ(j, on_mesh.orientation);
  EXPECT_EQ(c.get<TriangleList>("surface").triangles, on_mesh.triangles().triangles);
  EXPECT_EQ(topo.genus, std::optional<int>(1));
  EXPECT_NE(log_c.str().find("render: surface: "), std::string::npos);
}

// A topology handed on in the bag ("<port>.topology", as denoise leaves it) is taken only when it
// fits the mesh: a report of the same mesh is taken as it is (a marked field survives), reports of
// another mesh (other counts) or of the mesh moved by 1 mm (same counts) are not (a new analysis);
// the entry stays in the bag in every case (render's snapshot reads it after flatten).
TEST(CoreOrientation, HandedOnTopologyIsTakenOnlyWhenItFitsTheMesh) {
  const TriangleList sphere = synthetic::sphere(10, 24, 12);
  const TopologyReport own = analyze_topology(sphere);
  auto mean_edge_taken = [&](TopologyReport handed) {
    handed.mean_edge_length = -1;  // the mark: no analysis gives it
    ArtifactBag bag;
    bag.put("denoised", synthetic::to_mesh(sphere));
    bag.put(topology_entry("denoised"), std::move(handed));
    RunContext ctx;
    const OrientedMesh in = oriented_mesh_input(bag, "denoised", ctx, "flatten");
    EXPECT_TRUE(bag.has(topology_entry("denoised")));
    EXPECT_EQ(in.triangles().triangles, sphere.triangles);
    EXPECT_EQ(in.topology.face_component, own.face_component);
    EXPECT_EQ(in.topology.faces, own.faces);
    return in.topology.mean_edge_length;
  };
  EXPECT_EQ(mean_edge_taken(own), -1);
  EXPECT_EQ(mean_edge_taken(analyze_topology(synthetic::sphere(10, 20, 10))), own.mean_edge_length);
  EXPECT_EQ(mean_edge_taken(analyze_topology(synthetic::translated(sphere, 1, 0, 0))), own.mean_edge_length);
  EXPECT_TRUE(topology_fits(own, sphere));
  EXPECT_FALSE(topology_fits(own, synthetic::translated(sphere, 0, 0, -1)));
}

// orient_mesh_input and orient_surface (mesh or stand-in) take a topology handed on in the bag
// (reconstruct's of "surface") only when it fits the surface: the same mesh's report is used as it
// is (a marked field survives) and the entry stays for the next reader; a report of another mesh is
// not (a new analysis). Either way the inward torus is reversed with the same report and progress
// line as without an entry.
TEST(CoreOrientation, HandedOnTopologyOrientsTheStageInputAndStays) {
  const TriangleList inward = reversed(synthetic::torus(30, 10, 40, 16));
  const TopologyReport own = analyze_topology(inward);
  ArtifactBag plain;
  plain.put("surface", synthetic::to_mesh(inward));
  std::ostringstream plain_log;
  RunContext plain_ctx;
  plain_ctx.log = &plain_log;
  const nlohmann::json expected = orient_mesh_input(plain, "surface", plain_ctx, "denoise");
  ASSERT_EQ(expected["reversed_components"], 1);
  auto oriented = [&](TopologyReport handed, bool as_list) {
    handed.mean_edge_length = -1;  // the mark: no analysis gives it
    ArtifactBag bag;
    if (as_list) bag.put("surface", to_triangle_list(synthetic::to_mesh(inward)));
    else bag.put("surface", synthetic::to_mesh(inward));
    bag.put(topology_entry("surface"), std::move(handed));
    std::ostringstream log;
    RunContext ctx;
    ctx.log = &log;
    TopologyReport topo;
    const nlohmann::json j = as_list ? orient_surface(bag_surface_for_orienting(bag, "surface"), ctx, "denoise",
                                                      "surface", &topo, handed_topology_entry(bag, "surface"))
                                     : orient_mesh_input(bag, "surface", ctx, "denoise", &topo);
    EXPECT_EQ(j, expected);
    EXPECT_EQ(log.str(), plain_log.str());
    EXPECT_TRUE(bag.has(topology_entry("surface")));
    const TriangleList now = as_list ? bag.get<TriangleList>("surface") : to_triangle_list(bag.get<Mesh>("surface"));
    EXPECT_EQ(now.triangles, to_triangle_list(plain.get<Mesh>("surface")).triangles);
    EXPECT_EQ(topo.face_component, own.face_component);
    EXPECT_EQ(topo.genus, std::optional<int>(1));
    return topo.mean_edge_length;
  };
  for (bool as_list : {false, true}) {
    EXPECT_EQ(oriented(own, as_list), -1) << as_list;
    EXPECT_EQ(oriented(analyze_topology(synthetic::torus(30, 10, 36, 16)), as_list), own.mean_edge_length) << as_list;
  }
}

// Reading a non-orientable file fails with one line naming the file and the reason.
TEST(CoreOrientation, NonOrientableFileIsRefused) {
  testing::TempDir tmp;
  write_off(moebius_strip(), tmp / "moebius.off");
  try {
    load_mesh(tmp / "moebius.off");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("moebius.off"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("is not orientable"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cf
