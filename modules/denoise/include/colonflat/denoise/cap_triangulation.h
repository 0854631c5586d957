#pragma once
// Minimum-area triangulation of a closed 3D polygon (the caps of surgery).
#include <array>
#include <atomic>
#include <functional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/denoise/face_grid.h"

namespace cf {

// Minimum-area triangulation of a closed polygon (dynamic programming, O(n^3)); triangles
// (i, m, j) with i < m < j index `ring` and are oriented like the polygon, listed as ears: each
// triangle has two edges on the polygon left by removing the ones before it. Ties: the smallest
// apex m at each sub-polygon (i, j). With `allowed` (and `side_ok`, asked for sides (a, b), a < b,
// that are not ring edges), the lightest triangulation of triangles it accepts on sides it
// accepts, found lazily: the programme is solved with the refusals known so far, only the
// solution's triangles (and their sides) are asked, refused ones are left out and the programme
// solved again (same result as asking every candidate; each triangle and side asked at most
// once). Empty result when no such triangulation exists, or when give_up() (asked after each
// round) says so. Pre: `allowed` and `side_ok` are pure (the same answer for the same triangle).
std::vector<std::array<int, 3>> min_area_triangulation(const std::vector<Vec3>& ring,
                                                        const std::function<bool(int, int, int)>& allowed = {},
                                                        const std::function<bool()>& give_up = {},
                                                        const std::function<bool(int, int)>& side_ok = {});

// A cap for the closed ring `ring` (mesh vertices in boundary order; the triangles are oriented
// like it): its minimum-area triangulation without near-collinear triangles (height below 1e-4
// of the longest edge: they would leave a ring vertex on a neighbour's edge) and without a
// diagonal (a, b) for which blocked(a, b) holds. With `grid`, only triangles that intersect none
// of its faces and none of `others` (slower; for when the plain one intersects something).
// Returns mesh vertex ids in ear order (ready for add_face one by one), or nothing if no such
// triangulation exists or (with `grid` and `budget`) it took more grid queries (triangles
// tested) than *budget; *budget is lowered by the queries made.
// With `cache` (and `grid`): the grid's answers for this ring at its present position, by ring
// indices, are taken from it and added to it: triangles found clean (of the grid's faces: reused
// only when `others` is empty), triangles that hit the grid's faces (reused always) and sides that
// pierce it or not. A cached answer is the one the query would give, so the result is the same
// as without the cache, and it counts against *budget as the query it replaces. Pre: the same
// ring, mesh positions and grid faces in every call that shares a cache.
struct RingQueryCache {
  std::unordered_set<long long> clean, hits;      // triangles (i, m, j): key (i n + m) n + j
  std::unordered_map<long long, bool> sides_ok;  // sides (a, b), a < b: key a n + b
};
// With `cancel` (and `grid`): once *cancel is true, it gives up after the current round (another
// thread may set it; the caller then discards the result).
std::vector<std::array<int, 3>> triangulate_ring(
    const Mesh& mesh, const std::vector<Mesh::VertexHandle>& ring,
    const std::function<bool(Mesh::VertexHandle, Mesh::VertexHandle)>& blocked, const FaceGrid* grid = nullptr,
    const std::vector<std::array<int, 3>>& others = {}, long long* budget = nullptr, RingQueryCache* cache = nullptr,
    const std::atomic<bool>* cancel = nullptr);

// Adds the triangles of triangulate_ring (in its ear order) to the mesh, and to `grid` when given.
// Throws cf::Error naming `what` if OpenMesh refuses one (the ring was not a hole's boundary).
void add_cap(Mesh& mesh, const std::vector<std::array<int, 3>>& tris, FaceGrid* grid, const char* what);

}  // namespace cf
