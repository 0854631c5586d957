#pragma once
// Exact topology of a triangle mesh, also of broken ones (non-manifold, open, several pieces).
//
// Conventions (docs/conventions.md; tested in topology_test.cpp):
//   V counts vertices referenced by at least one triangle (unreferenced ones are reported apart),
//   E counts distinct undirected edges, F counts triangles; chi = V - E + F.
//   A component is a maximal set of triangles connected through shared vertices.
//   For an orientable 2-manifold component with b boundary loops: genus g = (2 - chi - b) / 2.
//   Total genus is the sum over components. Genus is undefined (std::nullopt) for a component
//   that is not a manifold or not orientable.
//   A boundary edge has one triangle, a manifold edge two, a non-manifold edge three or more.
//   A vertex is non-manifold when its triangles form more than one fan (e.g. a bowtie), counted
//   only where all its edges have at most two triangles or it lies on a non-manifold edge.
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"

namespace cf {

struct ComponentTopology {
  std::size_t vertices = 0, edges = 0, faces = 0;
  std::size_t boundary_edges = 0, boundary_loops = 0;
  long long euler = 0;  // V - E + F of this component
  bool closed = false, manifold = false, orientable = false;
  std::optional<int> genus;  // (2 - chi - b) / 2 when manifold and orientable
};

struct TopologyReport {
  std::size_t vertices = 0, edges = 0, faces = 0;
  std::size_t unreferenced_vertices = 0;
  std::size_t boundary_edges = 0, boundary_loops = 0;
  std::size_t nonmanifold_edges = 0, nonmanifold_vertices = 0;
  std::size_t inconsistent_edges = 0;  // manifold edges both triangles traverse the same way
  long long euler = 0;
  bool closed = false, manifold = false, orientable = false;
  bool consistently_oriented = false;
  std::optional<int> genus;  // sum of component genera when every component has one
  std::vector<ComponentTopology> components;  // largest (by faces) first
  std::array<double, 3> bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  double mean_edge_length = 0;

  // A few example element ids for diagnostics (at most kMaxExamples each).
  static constexpr std::size_t kMaxExamples = 5;
  std::vector<std::array<int, 2>> example_boundary_edges, example_nonmanifold_edges,
      example_inconsistent_edges;
  std::vector<int> example_nonmanifold_vertices;

  // Component id of every triangle (ids index `components`).
  std::vector<int> face_component;
};

// Topology of an indexed triangle list. Preconditions: every id in [0, #P).
TopologyReport analyze_topology(const TriangleList& mesh);
// Topology of an OpenMesh mesh (deleted elements must have been garbage-collected).
TopologyReport analyze_topology(const Mesh& mesh);
// Whether `t` (a report handed on with a mesh) can stand for analyze_topology(mesh) without a new
// analysis: one face_component per triangle, the mesh's face and vertex counts, and (every vertex
// referenced) its exact bounding box. O(#P); a cheap guard, not a proof (callers vouch for the rest).
bool topology_fits(const TopologyReport& t, const TriangleList& mesh);
// `known` (a report handed on with `mesh`; null: none) when it fits the mesh (topology_fits), else
// analyze_topology(mesh).
TopologyReport known_or_analysed(const TopologyReport* known, const TriangleList& mesh);

// Conversions between the two representations (same vertex and face order).
TriangleList to_triangle_list(const Mesh& mesh);
// True when a vertex or face of `mesh` is marked deleted (not yet garbage-collected): its
// to_triangle_list then keeps the deleted vertices' slots and leaves the deleted faces out.
bool has_deleted_elements(const Mesh& mesh);
// The mesh's live faces in face order, each face's corners in fv_range order (#F x 3 vertex ids;
// the triangles of to_triangle_list).
std::vector<std::array<int, 3>> mesh_triangles(const Mesh& mesh);

}  // namespace cf
