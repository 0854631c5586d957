// The minimum-cut caps' hole fills (step 7f, surgery_mincut.cpp; issue 26, session 32): a disk of
// the free-space cut has holes where a left-side and a right-side wall come within a cell; each is
// closed in both caps by one restricted triangulation of its rim and that fill's mirror, so the
// two caps' fills run side by side as their squares do (fills made apart for each cap crossed the
// other cap's squares on the raw CT mask's loop 91).
#include <algorithm>
#include <unordered_map>

#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "surgery_steps.h"

namespace cf::detail {

// Closes a hole of the disk (rim: disk point ids in the squares' direction; id: their mesh ids)
// with the least-area triangulation of its rim whose triangles meet no grid face and none of
// `others` (cap_triangulation.h); false when there is none.
bool Surgery::close_hole(const std::vector<int>& rim, const std::vector<int>& id, bool flip,
                         const std::vector<std::array<int, 3>>& others, std::vector<std::array<int, 3>>* tris) const {
  std::vector<Mesh::VertexHandle> ring;  // the hole's boundary as the fill sees it: against the squares
  for (auto it = rim.rbegin(); it != rim.rend(); ++it) ring.push_back(Mesh::VertexHandle(id[*it]));
  if (flip) std::reverse(ring.begin(), ring.end());
  auto none = [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; };
  const std::vector<std::array<int, 3>> fill = triangulate_ring(mesh_, ring, none, opts_.guard, others);
  tris->insert(tris->end(), fill.begin(), fill.end());
  return !fill.empty();
}

// The squares of both caps (their first `squares` triangles) with a corner within `margin` mm of
// the box round the hole's rim (right cap's points).
static std::vector<std::array<int, 3>> squares_near(const Mesh& mesh, const std::vector<int>& rim_ids, double margin,
                                                    const std::vector<const std::vector<std::array<int, 3>>*>& caps,
                                                    std::size_t squares) {
  Vec3 lo = mesh.point(Mesh::VertexHandle(rim_ids[0])), hi = lo;
  for (int v : rim_ids) lo.minimize(mesh.point(Mesh::VertexHandle(v))), hi.maximize(mesh.point(Mesh::VertexHandle(v)));
  const Vec3 m(margin, margin, margin);
  lo -= m;
  hi += m;
  std::vector<std::array<int, 3>> out;
  for (const auto* tris : caps)
    for (std::size_t t = 0; t < squares; ++t)
      for (int v : (*tris)[t]) {
        const Vec3 p = mesh.point(Mesh::VertexHandle(v));
        if (p[0] >= lo[0] && p[1] >= lo[1] && p[2] >= lo[2] && p[0] <= hi[0] && p[1] <= hi[1] && p[2] <= hi[2]) {
          out.push_back((*tris)[t]);
          break;
        }
      }
  return out;
}

// A hole's fill on one cap (`from`, its disk point ids; `own`: that cap's squares near the hole)
// and its mirror on the other (`to`); true when the fill exists and its mirror meets neither the
// surface nor `all` (both caps' squares near the hole) nor the fill.
bool Surgery::mirrored_fill(const std::vector<int>& rim, const std::vector<int>& from, const std::vector<int>& to, bool flip,
                            const std::vector<std::array<int, 3>>& own, const std::vector<std::array<int, 3>>& all,
                            std::vector<std::array<int, 3>>* fill, std::vector<std::array<int, 3>>* mirrored) const {
  fill->clear();
  mirrored->clear();
  if (!close_hole(rim, from, flip, own, fill)) return false;
  std::unordered_map<int, int> to_id;
  for (int v : rim) to_id[from[v]] = to[v];
  std::vector<std::array<int, 3>> others = all;
  others.insert(others.end(), fill->begin(), fill->end());
  for (const auto& t : *fill) {
    mirrored->push_back({to_id.at(t[0]), to_id.at(t[2]), to_id.at(t[1])});
    if (opts_.guard->hits(mesh_, mirrored->back(), others)) return false;
  }
  for (const auto& t : *fill)  // the fill against the other cap's squares
    if (opts_.guard->hits(mesh_, t, all)) return false;
  return true;
}

// Closes the disk's holes in both caps, after their squares, with one fill and its mirror (two
// fills of one hole made apart crossed each other on the raw CT mask's loop 91): made on the right
// cap and mirrored, else made on the left and mirrored. False when neither is clean.
bool Surgery::close_mincut_holes(const CutDisk& disk, bool flip, double cell, FrontCap* right, FrontCap* left) const {
  const std::size_t squares = right->tris.size();
  std::vector<int> rid, lid;
  for (std::size_t i = 0; i < right->inner.size(); ++i) rid.push_back(right->inner[i].idx()), lid.push_back(left->inner[i].idx());
  for (const auto& rim : disk.holes) {
    std::vector<int> rim_ids;
    for (int v : rim) rim_ids.push_back(rid[v]);
    const double margin = 2 * cell;
    const auto all = squares_near(mesh_, rim_ids, margin, {&right->tris, &left->tris}, squares);
    std::vector<std::array<int, 3>> r_fill, l_fill;
    if (!mirrored_fill(rim, rid, lid, flip, squares_near(mesh_, rim_ids, margin, {&right->tris}, squares), all, &r_fill, &l_fill) &&
        !mirrored_fill(rim, lid, rid, !flip, squares_near(mesh_, rim_ids, margin, {&left->tris}, squares), all, &l_fill, &r_fill))
      return false;
    right->tris.insert(right->tris.end(), r_fill.begin(), r_fill.end());
    left->tris.insert(left->tris.end(), l_fill.begin(), l_fill.end());
  }
  return true;
}

}  // namespace cf::detail
