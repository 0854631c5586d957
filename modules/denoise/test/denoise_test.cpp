// Denoising end to end on synthetic meshes: genus 0, connectivity, stopping rules, policies,
// boundaries, several components, and the paper's separating-loop failure.
#include <gtest/gtest.h>

#include "colonflat/core/error.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/denoise.h"

namespace cf {
namespace {

using namespace synthetic;

void expect_clean(const DenoiseResult& r, std::size_t components, int genus) {
  EXPECT_EQ(r.after.components.size(), components);
  EXPECT_EQ(r.after.genus, genus);
  EXPECT_TRUE(r.after.manifold);
  EXPECT_TRUE(r.after.consistently_oriented);
  for (const auto& c : r.after.components) EXPECT_TRUE(c.genus.has_value());
}

// A genus-5 chain becomes one closed genus-0 surface with exactly 5 loops, none separating.
TEST(DenoiseExact, ChainToGenusZero) {
  Mesh m = to_mesh(torus_chain(5, 3, 1, 16, 8, 10));
  DenoiseResult r = denoise(m, DenoiseOptions{});
  expect_clean(r, 1, 0);
  EXPECT_TRUE(r.after.closed);
  ASSERT_EQ(r.loops.size(), 5u);
  for (const auto& L : r.loops) {
    EXPECT_FALSE(L.separating);
    EXPECT_EQ(L.type, "handle");  // the meridians of the tori
    EXPECT_GT(L.length, 5.0);
  }
  // Loops are cut shortest first (greedy) and report input vertex ids.
  for (std::size_t i = 1; i < r.loops.size(); ++i) EXPECT_GE(r.loops[i].length, r.loops[i - 1].length - 1e-9);
  for (int id : r.loops[0].vertex_ids) {
    EXPECT_GE(id, 0);
    EXPECT_LT(id, static_cast<int>(m.n_vertices()));
  }
  EXPECT_EQ(r.report["totals"]["loops"], 5);
  EXPECT_EQ(r.report["genus_after"], 0);
}

// Two disjoint tori: each component is denoised on its own; 2 components of genus 0.
TEST(DenoiseExact, SeveralComponents) {
  Mesh m = to_mesh(disjoint_union(torus(3, 1, 16, 8), translated(torus(2, 0.5, 20, 8), 20, 0, 0)));
  DenoiseResult r = denoise(m, DenoiseOptions{});
  expect_clean(r, 2, 0);
  ASSERT_EQ(r.loops.size(), 2u);
  EXPECT_NE(r.loops[0].component, r.loops[1].component);
}

// The default never cuts the separating neck of two tori joined by a thin tube, though the neck is
// shorter than any handle loop; the paper's Algorithm 2 picks the neck and splits the mesh.
TEST(DenoiseExact, DefaultAvoidsSeparatingNeckPaperDoesNot) {
  Mesh m = to_mesh(torus_chain(2, 3, 1, 16, 8, 10));  // neck loop ~4.7, meridians ~6.1
  DenoiseResult exact = denoise(m, DenoiseOptions{});
  expect_clean(exact, 1, 0);
  for (const auto& L : exact.loops) EXPECT_FALSE(L.separating);
  DenoiseOptions p;
  p.method = "paper";
  DenoiseResult paper = denoise(m, p);
  ASSERT_FALSE(paper.loops.empty());
  EXPECT_TRUE(paper.loops[0].separating) << "paper's first loop, length " << paper.loops[0].length;
  EXPECT_LT(paper.loops[0].length, exact.loops[0].length);
  EXPECT_EQ(paper.after.components.size(), 2u);  // the mesh was split
  EXPECT_GT(*paper.after.genus, 0);               // and a handle remains after g = 2 iterations
}

// --max-loop-length cuts only the small handles: a chain of a thin and a fat torus keeps the fat one.
TEST(DenoiseExact, MaxLoopLengthStopsEarly) {
  Mesh m = to_mesh(disjoint_union(torus(3, 0.3, 24, 8), translated(torus(6, 2, 24, 8), 30, 0, 0)));
  DenoiseOptions o;
  o.max_loop_length = 5.0;  // thin meridian ~1.9 mm, fat meridian ~12 mm
  DenoiseResult r = denoise(m, o);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_LT(r.loops[0].length, 5.0);
  EXPECT_EQ(r.after.genus, 1);
  EXPECT_EQ(r.report["stop_reason"], "no loop shorter than --max-loop-length remains");
}

// --target-genus stops at the requested total genus.
TEST(DenoiseExact, TargetGenus) {
  Mesh m = to_mesh(torus_chain(4, 3, 1, 16, 8, 10));
  DenoiseOptions o;
  o.target_genus = 2;
  DenoiseResult r = denoise(m, o);
  EXPECT_EQ(r.loops.size(), 2u);
  EXPECT_EQ(r.after.genus, 2);
}

// --policy fill cuts tunnel loops (a torus's inner equator), --policy cut handle loops (meridians).
TEST(DenoiseExact, PolicyCutAndFill) {
  Mesh m = to_mesh(torus(3, 1, 24, 12));
  DenoiseOptions fill;
  fill.policy = "fill";
  DenoiseResult f = denoise(m, fill);
  ASSERT_EQ(f.loops.size(), 1u);
  EXPECT_EQ(f.loops[0].type, "tunnel");
  EXPECT_NEAR(f.loops[0].length, 24 * 2 * 2 * std::sin(3.14159265358979 / 24), 1e-6);
  expect_clean(f, 1, 0);
  DenoiseOptions cut;
  cut.policy = "cut";
  DenoiseResult c = denoise(m, cut);
  ASSERT_EQ(c.loops.size(), 1u);
  EXPECT_EQ(c.loops[0].type, "handle");
  EXPECT_LT(c.loops[0].length, f.loops[0].length);
}

// An open surface keeps its boundary: a torus with a hole becomes a disk-like surface (genus 0, 1 loop).
TEST(DenoiseExact, BoundaryIsKept) {
  auto t = torus(3, 1, 16, 8);
  t.triangles.erase(t.triangles.begin() + 40, t.triangles.begin() + 42);
  Mesh m = to_mesh(t);
  DenoiseResult r = denoise(m, DenoiseOptions{});
  expect_clean(r, 1, 0);
  EXPECT_EQ(r.after.boundary_loops, 1u);
  EXPECT_EQ(r.after.boundary_edges, r.before.boundary_edges);
}

// A genus-0 input is returned unchanged (no loop), and invalid options are rejected.
TEST(DenoiseExact, GenusZeroAndInvalidOptions) {
  Mesh s = to_mesh(sphere(1, 12, 6));
  DenoiseResult r = denoise(s, DenoiseOptions{});
  EXPECT_TRUE(r.loops.empty());
  EXPECT_EQ(r.mesh.n_faces(), s.n_faces());
  DenoiseOptions bad;
  bad.target_genus = -1;
  EXPECT_THROW(denoise(s, bad), UsageError);
  bad = DenoiseOptions{};
  bad.method = "magic";
  EXPECT_THROW(denoise(s, bad), UsageError);
  bad = DenoiseOptions{};
  bad.method = "paper";
  bad.policy = "fill";
  EXPECT_THROW(denoise(s, bad), UsageError);
}

// Element-by-element equality of two meshes: points, face corners, halfedge links, status.
void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  ASSERT_EQ(a.n_edges(), b.n_edges());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  for (auto v : a.vertices()) {
    EXPECT_EQ(a.point(v), b.point(v));
    EXPECT_EQ(a.halfedge_handle(v), b.halfedge_handle(v));
  }
  for (auto h : a.halfedges()) {
    EXPECT_EQ(a.to_vertex_handle(h), b.to_vertex_handle(h));
    EXPECT_EQ(a.next_halfedge_handle(h), b.next_halfedge_handle(h));
    EXPECT_EQ(a.prev_halfedge_handle(h), b.prev_halfedge_handle(h));
    EXPECT_EQ(a.face_handle(h), b.face_handle(h));
  }
  for (auto f : a.faces()) EXPECT_EQ(a.status(f).bits(), b.status(f).bits());
}

// The working copy is the input itself: a genus-0 input comes back identical, element by
// element, whether it holds only the standard arrays (copied onto huge pages), an extra
// property (copied by assignment) or deleted elements (garbage-collected like OpenMesh does).
TEST(DenoiseExact, WorkingCopyIsTheInput) {
  const Mesh s = to_mesh(sphere(1, 40, 20));
  expect_same_mesh(denoise(s, DenoiseOptions{}).mesh, s);
  Mesh tagged = s;
  OpenMesh::VPropHandleT<int> tag;
  tagged.add_property(tag, "tag");
  const DenoiseResult r = denoise(tagged, DenoiseOptions{});
  expect_same_mesh(r.mesh, s);
  Mesh holed = s;
  holed.delete_face(Mesh::FaceHandle(0), false);
  Mesh expected = holed;
  expected.garbage_collection();
  expect_same_mesh(denoise(holed, DenoiseOptions{}).mesh, expected);
}

// denoise_into() builds the result in the caller's mesh (as DenoiseStage does, where its bag keeps
// it): the mesh and loops denoise() returns, element by element; DenoiseResult::mesh comes back
// empty, and an output mesh that is not empty is refused.
TEST(DenoiseExact, IntoTheCallersMeshGivesTheSameResult) {
  const Mesh m = to_mesh(torus_chain(3, 3, 1, 16, 8, 10));
  const DenoiseResult a = denoise(m, DenoiseOptions{});
  Mesh out;
  const DenoiseResult b = denoise_into(out, m, DenoiseOptions{});
  EXPECT_EQ(b.mesh.n_vertices(), 0u);
  EXPECT_EQ(b.after.genus, 0);
  expect_same_mesh(out, a.mesh);
  ASSERT_EQ(b.loops.size(), a.loops.size());
  for (std::size_t i = 0; i < a.loops.size(); ++i) EXPECT_EQ(b.loops[i].vertex_ids, a.loops[i].vertex_ids) << i;
  EXPECT_THROW(denoise_into(out, m, DenoiseOptions{}), PreconditionError);
}

// The paper method refuses open meshes with an actionable message.
TEST(DenoisePaper, RefusesOpenMesh) {
  Mesh m = to_mesh(open_cylinder(1, 3, 12, 4));
  DenoiseOptions p;
  p.method = "paper";
  try {
    denoise(m, p);
    FAIL();
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("use --method exact"), std::string::npos);
  }
}

// On a single torus the paper's loop is non-separating and the result is genus 0.
TEST(DenoisePaper, TorusToGenusZero) {
  DenoiseOptions p;
  p.method = "paper";
  DenoiseResult r = denoise(to_mesh(torus(3, 1, 16, 8)), p);
  ASSERT_EQ(r.loops.size(), 1u);
  EXPECT_FALSE(r.loops[0].separating);
  EXPECT_EQ(r.after.genus, 0);
}

}  // namespace
}  // namespace cf
