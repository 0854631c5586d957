#pragma once
// Internal to the denoise module: "shortcut first" (docs/denoise.md, issue 26 session 28
// "shortcut"). Two touching colon loops whose wall is fused form a handle (a fused contact); when
// the contact's opening is wider than the colon, the shortest loop that kills the handle is the
// colon's girth somewhere on the stretch the contact bypasses, and cutting it cuts the colon in
// pieces. A contact is a shortcut between places far apart along the colon, the colon itself never
// is: cutting a contact's opening lengthens the surface's shortest path d between its two
// farthest points (the colon's ends), cutting the girth of a bypassed stretch does not. d is
// measured on a coarse graph of the surface (CoarseSurface), so that a test costs milliseconds.
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf::detail {

// The surface's vertices merged into cubic cells of side `cell` mm, each cell split into its
// pieces connected by mesh edges inside the cell (the two sides of a thin wall in one cell stay
// apart): one node per piece, at the mean of its vertices; an arc between two nodes that a mesh
// edge joins, as long as the distance between their means. Built from the mesh as it is; later
// cuts are entered with block(). Vertices created after the build have no node.
class CoarseSurface {
 public:
  CoarseSurface(const Mesh& mesh, double cell);
  std::size_t size() const { return centre_.size(); }
  // Node of a vertex id, -1 for vertices created after the build.
  int node_of(int vertex) const { return vertex >= 0 && vertex < int(node_of_.size()) ? node_of_[vertex] : -1; }
  int vertex_of(int node) const { return first_vertex_[node]; }  // a vertex of the node
  const Vec3& centre(int node) const { return centre_[node]; }  // mean of its vertices (mm)
  bool blocked(int node) const { return blocked_[node] != 0; }
  // Nodes holding any of `vertices` (vertex ids; those without a node are skipped), sorted, unique.
  std::vector<int> nodes_of(const std::vector<int>& vertices) const;
  void block(const std::vector<int>& nodes);  // a cut: no path enters these nodes any more
  // Shortest distances (mm) from node `from` over the nodes neither blocked nor in `also` (sorted);
  // +inf where unreached. parent (optional): predecessor per node, -1 at `from` and unreached.
  std::vector<double> distances(int from, const std::vector<int>& also = {}, std::vector<int>* parent = nullptr) const;
  // Nodes of the shortest path from `from` to `to` given distances() from `from` and its parents.
  static std::vector<int> path_to(int to, const std::vector<int>& parent);
  // Arcs of node n: [arc_start(n), arc_start(n + 1)) into arc_node / arc_length.
  int arc_start(int n) const { return start_[n]; }
  int arc_node(int a) const { return arcs_[a]; }

 private:
  void make_arcs(const Mesh& mesh);
  std::vector<int> node_of_, first_vertex_;
  std::vector<Vec3> centre_;
  std::vector<int> start_, arcs_;
  std::vector<double> arc_length_;
  std::vector<std::uint8_t> blocked_;
};

// What the shortest path between a component's two farthest points does when a loop is cut.
struct ShortcutTest {
  bool measured = false;  // false: no ends or no path (the rule does not apply)
  double before = 0, after = 0;  // mm: d now and with the loop's nodes blocked (+inf: none)
  std::vector<int> path;         // nodes of the current shortest path, end a to end b
};

// The coarse surface plus, per input component, its two ends (two farthest-tip sweeps on the
// coarse graph at the component's first test; kept, since cuts never move a colon's ends). A
// tip, not just the farthest point: with fused contacts left, the farthest point from one end can
// lie in the middle of a bypassed stretch (the real CT: 1 466 mm from the rectum at z 341).
class ShortcutPaths {
 public:
  ShortcutPaths(const Mesh& mesh, double cell) : coarse_(mesh, cell), cell_(cell) {}
  const CoarseSurface& coarse() const { return coarse_; }
  const Vec3& centre_of(int node) const { return coarse_.centre(node); }
  // d between `component`'s ends now and with the nodes of `loop` (vertex ids) blocked; `start`:
  // a vertex id of the component with a node (where the farthest-point sweeps begin).
  ShortcutTest test(const std::vector<int>& loop, int component, int start);
  void block(const std::vector<int>& loop) { coarse_.block(coarse_.nodes_of(loop)); }  // a loop was cut

 private:
  std::pair<int, int> ends(int component, int start);
  CoarseSurface coarse_;
  double cell_;
  std::map<int, std::pair<int, int>> ends_;  // component -> its two end nodes
};

// The shortest mesh path from vertex `from` to vertex `to` through the vertices whose nodes lie
// on `nodes` (a path of the coarse graph) or beside them; empty when there is none.
std::vector<Mesh::VertexHandle> mesh_path_along(const Mesh& mesh, const CoarseSurface& coarse,
                                                const std::vector<int>& nodes, int from, int to);

// Largest distance between two of the loop's vertices (mm).
double loop_diameter(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop);

}  // namespace cf::detail
