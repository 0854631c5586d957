#pragma once
// FaceGrid: a spatial hash of a mesh's triangles that tells which triangles intersect improperly
// (beyond the corners or edge they share). Surgery uses it to keep caps from crossing the surface.
//
// Rules: disjoint triangles use VTK's triangle-triangle test; triangles sharing one vertex
// intersect when an edge of one pierces the other away from that vertex; triangles sharing an
// edge intersect when they fold flat onto each other. Faces are hashed by bounding box into cubic
// cells of `cell_size` (mm); a face spanning more than 512 cells is checked by every query.
// Moving a face: insert() it again at its new place (stale cells only cost time).
#include <array>
#include <cstddef>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

// A spatial hash of the mesh's triangles, to check new geometry for intersections with the
// rest of the surface (triangles sharing corners count when they meet beyond those corners).
class FaceGrid {
 public:
  FaceGrid(const Mesh& mesh, double cell_size);
  // A grid of some faces only.
  FaceGrid(const Mesh& mesh, double cell_size, const std::vector<Mesh::FaceHandle>& faces);
  void insert(const Mesh& mesh, Mesh::FaceHandle f);
  // Takes f out (f at the place where it was inserted).
  void erase(const Mesh& mesh, Mesh::FaceHandle f);
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
  // Calls visit(key) for each cell of f's bounding box; false (nothing visited) when they are more
  // than kMaxCellsPerFace.
  template <class Visit>
  bool visit_cells(const Mesh& mesh, Mesh::FaceHandle f, Visit&& visit);
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

}  // namespace cf
