#pragma once
// Topological surgery along an edge loop (Algorithm 3 of the seed paper, with separated caps).
//
// cut_and_cap() slices the mesh along a simple edge cycle, which splits each loop vertex into a
// left and a right copy and opens two boundary rings, then fills each ring with a fan to a new
// vertex. Unlike the paper, whose two centroid fans coincide in space, each ring is first pulled
// a fraction of the way into its own side (towards its own neighbours), and each cap is a small
// disk relaxed to a discrete minimal surface spanning its pulled ring (centre vertex at the
// centroid for a plain fan), so the two caps are disjoint and follow non-planar loops. With a
// guard, caps are first minimum-area triangulations of the pulled rings, restricted when needed
// to triangles that intersect nothing (see surgery.cpp, step 7a). Nothing is deleted: the input's
// vertex ids stay valid (right copies keep the original ids; left copies and caps are appended).
#include <array>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

class HomologyBasis;

// A spatial hash of the mesh's triangles, to check new geometry for intersections with the
// rest of the surface (triangles sharing corners count when they meet beyond those corners).
class FaceGrid {
 public:
  FaceGrid(const Mesh& mesh, double cell_size);
  void insert(const Mesh& mesh, Mesh::FaceHandle f);
  // Pairs (f in `faces`, g any face) that intersect improperly; pairs inside `faces` count once.
  // Precondition: every face in `faces` was insert()ed at its current position.
  std::size_t count_intersections(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces) const;
  // Intersections of triangles not (yet) in the mesh, given by mesh vertex ids, with the grid's
  // faces and with each other.
  std::size_t count_triangles(const Mesh& mesh, const std::vector<std::array<int, 3>>& tris) const;
  // True when triangle `tri` (mesh vertex ids, not in the mesh) intersects a grid face or one of
  // `others` (stops at the first hit).
  bool hits(const Mesh& mesh, const std::array<int, 3>& tri, const std::vector<std::array<int, 3>>& others = {}) const;
  // The intersecting pairs themselves (same rules as count_intersections).
  std::vector<std::pair<int, int>> intersecting_pairs(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces) const;

 private:
  struct Key {
    long long x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return static_cast<std::size_t>(k.x * 73856093LL ^ k.y * 19349663LL ^ k.z * 83492791LL);
    }
  };
  Key key(const Vec3& p) const;
  std::vector<int> candidates(const Vec3& lo, const Vec3& hi) const;  // faces in the box's cells, sorted, unique
  // Grid faces that triangle (ids, p) intersects improperly (at most 1 with first_only).
  std::size_t grid_hits(const Mesh& mesh, const std::array<int, 3>& ids, const std::array<Vec3, 3>& p,
                        bool first_only) const;
  static constexpr long long kMaxCellsPerFace = 512;
  double cell_;
  std::unordered_map<Key, std::vector<int>, KeyHash> cells_;
  std::vector<int> big_;  // faces spanning more than kMaxCellsPerFace cells (each once)
  std::unordered_set<int> big_set_;
};

struct SurgeryOptions {
  double ring_pull = 0.25;  // fraction (0..0.5) of the way from a ring vertex to the centroid of
                            // its same-side neighbours; 0 gives the paper's coincident caps
  int cap_rings = 4;        // concentric rings of a cap (1 = the paper's fan to the centroid)
  FaceGrid* guard = nullptr;  // when set: try placements until the new geometry intersects
                              // nothing (see SurgeryResult::intersections), and update the grid
};

struct SurgeryResult {
  std::vector<Mesh::VertexHandle> left_ring, right_ring;  // copies, in loop order
  Mesh::VertexHandle left_cap, right_cap;                 // cap centres
  std::size_t intersections = 0;  // triangle pairs the chosen placement still intersects (guard only)
};

// Preconditions (checked, PreconditionError otherwise): `loop` is a simple cycle of >= 3
// vertices, consecutive vertices share an edge, and no loop vertex lies on the boundary.
// When `homology` is given, new edges get classes consistent with it modulo the loop's class.
SurgeryResult cut_and_cap(Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop, const SurgeryOptions& opts,
                          HomologyBasis* homology = nullptr);

// Minimum-area triangulation of a closed polygon (dynamic programming, O(n^3)); triangles
// (i, m, j) with i < m < j index `ring` and are oriented like the polygon, listed as ears: each
// triangle has two edges on the polygon left by removing the ones before it. With `allowed`, only
// triangles it accepts are used (called once per candidate that would improve a subproblem);
// empty result when no triangulation consists of allowed triangles.
std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed = {});

// True when a and b are connected in the mesh graph (bidirectional breadth-first search, which
// stops early when both sides meet: cheap for the small handles of denoising).
bool vertices_connected(const Mesh& mesh, Mesh::VertexHandle a, Mesh::VertexHandle b);

}  // namespace cf
