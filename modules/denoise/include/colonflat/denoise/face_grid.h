#pragma once
// FaceGrid: a spatial hash of a mesh's triangles that tells which triangles intersect improperly
// (beyond the corners or edge they share). Surgery uses it to keep caps from crossing the surface.
//
// Rules: disjoint triangles use VTK's triangle-triangle test; triangles sharing one vertex
// intersect when an edge of one pierces the other away from that vertex; triangles sharing an
// edge intersect when they fold flat onto each other. Faces are hashed by bounding box into cubic
// cells of `cell_size` (mm); a face spanning more than 512 cells is checked by every query.
// Moving a face: insert() it again at its new place (stale cells only cost time).
// Storage: the constructor's faces in compressed rows per cell (an open-addressing table from
// cell to row, filled in two passes: no allocation per cell; 1.56 M faces in about 0.15 s
// instead of 0.8 s with a vector per cell), faces insert()ed later in a hash map of cells.
#include <array>
#include <limits>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

// The grid's test for two triangles given by mesh vertex ids and points (p[i] the point of
// ids[i]): true when they intersect beyond the corners or edge they share (rules above).
bool triangles_intersect_improperly(const std::array<int, 3>& ids, const std::array<Vec3, 3>& p,
                                    const std::array<int, 3>& gids, const std::array<Vec3, 3>& q);

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
  // Forgets every face with an id >= first that was insert()ed (faces an undone surgery added and
  // the mesh no longer has); faces below keep their entries (moved back faces: stale cells only
  // cost time). Costs one pass over the inserted faces' cells, not a rebuild.
  void forget_faces_from(int first);
  // A pair (f, g) of face ids that a count leaves out when it returns true (called only for
  // pairs that intersect; an empty filter leaves out nothing).
  using PairFilter = std::function<bool(int f, int g)>;
  // Pairs (f in `faces`, g any face) that intersect improperly; pairs inside `faces` count once.
  // The count stops at `stop_at` (a result below it is exact): a caller that only compares the
  // count with a best one so far stops there. Pairs `skip` accepts are not counted.
  // Precondition: every face in `faces` was insert()ed at its current position.
  std::size_t count_intersections(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces,
                                  std::size_t stop_at = std::numeric_limits<std::size_t>::max(),
                                  const PairFilter& skip = {}) const;
  // Intersections of triangles not (yet) in the mesh, given by mesh vertex ids, with the grid's
  // faces and with each other.
  std::size_t count_triangles(const Mesh& mesh, const std::vector<std::array<int, 3>>& tris) const;
  // True when triangle `tri` (mesh vertex ids, not in the mesh) intersects a grid face or one of
  // `others` (stops at the first hit).
  bool hits(const Mesh& mesh, const std::array<int, 3>& tri, const std::vector<std::array<int, 3>>& others = {}) const;
  // Distance from `origin` along the unit direction `dir` to the first grid face the ray meets,
  // faces with corner `skip_vertex` (the vertex the ray leaves from) ignored; `max_dist` when
  // none is nearer.
  double free_distance(const Mesh& mesh, const Vec3& origin, const Vec3& dir, double max_dist, int skip_vertex) const;
  // True when the segment between mesh vertices a and b (not an edge of the mesh) pierces a grid
  // face other than at a or b. Then every triangle with that side intersects that face improperly
  // (hits() would say so), which makes this a cheap first test for cap triangles.
  bool segment_hits(const Mesh& mesh, int a, int b) const;
  // The intersecting pairs themselves (same rules as count_intersections; at most `stop_at`).
  std::vector<std::pair<int, int>> intersecting_pairs(
      const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces,
      std::size_t stop_at = std::numeric_limits<std::size_t>::max(), const PairFilter& skip = {}) const;

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
  // The range of cells of f's bounding box; false when they are more than kMaxCellsPerFace.
  bool cell_range(const Mesh& mesh, Mesh::FaceHandle f, Key& a, Key& b) const;
  template <class Visit>
  bool visit_cells(const Mesh& mesh, Mesh::FaceHandle f, Visit&& visit) const;
  std::vector<int> candidates(const Vec3& lo, const Vec3& hi) const;  // faces in the box's cells, sorted, unique
  template <class Visit>
  bool triangle_cells(const std::array<Vec3, 3>& p, Visit&& visit) const;  // the cells triangle p's plane crosses
  template <class Visit>
  bool segment_cells(const Vec3& p, const Vec3& q, Visit&& visit) const;  // the cells segment pq passes through
  template <class Visit>
  bool cell_faces(const Key& k, Visit&& visit) const;  // the faces of cell k
  void insert_dynamic(const Mesh& mesh, Mesh::FaceHandle f);
  // Faces given to the constructor, in compressed rows per cell.
  class StaticCells {
   public:
    static constexpr std::uint32_t kNoRow = 0xffffffffu;
    static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);
    // The cell's code (x, y, z in 21 bits each), or kEmpty when a coordinate is out of range.
    static std::uint64_t code(const Key& k);
    std::uint32_t find(std::uint64_t code) const;
    std::uint32_t find_or_add(std::uint64_t code);  // a new row counts 0 faces
    std::size_t rows() const { return count_.size(); }
    void count(std::uint32_t row) { ++count_[row]; }
    void finish_counts();  // rows from counts; then fill() every counted face once
    void fill(std::uint32_t row, int face) { faces_[cursor_[row]++] = face; }
    void end_fill() { cursor_ = {}; }
    const int* begin(std::uint32_t row) const { return faces_.data() + start_[row]; }
    const int* end(std::uint32_t row) const { return faces_.data() + start_[row + 1]; }
    const std::vector<int>& faces() const { return faces_; }

   private:
    static std::size_t slot(std::uint64_t code, std::size_t mask) {  // the code's first slot
      const std::uint64_t h = code * 0x9E3779B97F4A7C15ull;
      return static_cast<std::size_t>(h ^ (h >> 29)) & mask;
    }
    void rehash(std::size_t slots);
    std::vector<std::uint64_t> slot_code_;
    std::vector<std::uint32_t> slot_row_;
    std::vector<std::uint32_t> count_, start_, cursor_;
    std::vector<int> faces_;
  };
  template <class Faces>
  void build_static(const Mesh& mesh, const Faces& faces);
  bool erased(int f) const { return f < static_cast<int>(erased_.size()) && erased_[f]; }
  // Grid faces that triangle (ids, p) intersects improperly (at most 1 with first_only).
  std::size_t grid_hits(const Mesh& mesh, const std::array<int, 3>& ids, const std::array<Vec3, 3>& p,
                        bool first_only) const;
  static constexpr long long kMaxCellsPerFace = 512;
  double cell_;
  StaticCells static_;
  std::vector<std::uint8_t> erased_;  // per face id: erase()d (its static entries hidden) until insert()ed again
  std::unordered_map<Key, std::vector<int>, KeyHash> cells_;  // faces insert()ed after the constructor
  std::vector<int> big_;  // faces spanning more than kMaxCellsPerFace cells (each once)
  std::unordered_set<int> big_set_;
};

}  // namespace cf
