// The minimum-cut caps' wall widening (step 7f, surgery_mincut.cpp; issue 26, session 33 "rawden").
//
// A hole of the free-space cut's disk is where a left-side and a right-side wall come within a
// cell: on the raw CT mask's loop 91 three air passages 0.21-0.38 mm thin, which no fill of the
// hole's rim threads (sessions 31-32). Here the surface itself is moved: every vertex of a
// right-side face near a hole moves along the disk's normal there (towards the right side), every
// vertex of a left-side face the other way, by `shift` mm within the hole's radius and less
// further out (none beyond it + kFalloff), so the passage grows by twice the shift and the cut
// made again finds free cells through it. A geometric change of the input surface, local and
// bounded by `shift`; kept only when no moved face meets anything new, and put back when the caps
// are not clean after all (SurgeryResult::widened gives the largest move kept).
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/denoise/face_grid.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
// mm beyond a hole's radius over which the move falls to nothing.
constexpr double kFalloff = 1.0;
constexpr double kPi = 3.14159265358979323846;

struct HoleFrame {
  Vec3 centre, normal;  // normal: the disk's, towards the right side
  double radius = 0;
};

std::vector<HoleFrame> hole_frames(const CutDisk& disk) {
  std::vector<HoleFrame> out;
  for (const auto& rim : disk.holes) {
    HoleFrame h;
    h.centre = Vec3(0, 0, 0);
    h.normal = Vec3(0, 0, 0);
    for (int v : rim) h.centre += disk.points[v], h.normal += disk.normals[v];
    h.centre /= static_cast<double>(rim.size());
    if (h.normal.norm() == 0) continue;
    h.normal.normalize();
    for (int v : rim) h.radius = std::max(h.radius, (disk.points[v] - h.centre).norm());
    out.push_back(h);
  }
  return out;
}

// 1 within the radius, a half cosine down to 0 at radius + kFalloff.
double falloff(double dist, double radius) {
  if (dist <= radius) return 1.0;
  if (dist >= radius + kFalloff) return 0.0;
  return 0.5 * (1.0 + std::cos(kPi * (dist - radius) / kFalloff));
}
}  // namespace

// Each vertex of the sided faces (`ids`: their mesh face ids) whose faces there are all on one
// side, 1 left or 2 right; the vertices of the faces round the rings are left out (the rings
// move with the placements).
std::unordered_map<int, int> Surgery::vertex_sides(const std::vector<SidedTriangle>& sided, const std::vector<int>& ids) const {
  std::unordered_map<int, int> side;
  for (std::size_t i = 0; i < sided.size(); ++i)
    for (auto v : mesh_.fv_range(Mesh::FaceHandle(ids[i]))) {
      const int s = (sided[i].side == 1 || sided[i].side == 2) ? sided[i].side : 0;
      auto [it, fresh] = side.emplace(v.idx(), s);
      if (!fresh && it->second != s) it->second = 0;
    }
  for (auto f : faces_around_rings())
    for (auto v : mesh_.fv_range(f)) side.erase(v.idx());
  return side;
}

// The moves: per sided vertex near a hole, `shift` times the falloff-weighted sum of the holes'
// normals (at most unit length), signed by its side.
std::vector<std::pair<Mesh::VertexHandle, Vec3>> Surgery::widening_moves(const CutDisk& disk,
                                                                          const std::unordered_map<int, int>& side,
                                                                          double shift) const {
  const std::vector<HoleFrame> holes = hole_frames(disk);
  std::vector<std::pair<Mesh::VertexHandle, Vec3>> moves;
  for (const auto& [v, s] : side) {
    if (s == 0) continue;
    const Vec3 p = mesh_.point(Mesh::VertexHandle(v));
    Vec3 d(0, 0, 0);
    for (const auto& h : holes) d += falloff((p - h.centre).norm(), h.radius) * h.normal;
    if (d.norm() == 0) continue;
    if (d.norm() > 1) d.normalize();
    moves.push_back({Mesh::VertexHandle(v), (s == 2 ? shift : -shift) * d});
  }
  std::sort(moves.begin(), moves.end(), [](const auto& a, const auto& b) { return a.first.idx() < b.first.idx(); });
  return moves;
}

// Sets the vertices' points (their faces taken out of the guard before and put back after);
// returns those faces.
std::vector<Mesh::FaceHandle> Surgery::set_points(const std::vector<std::pair<Mesh::VertexHandle, Vec3>>& points) {
  std::unordered_set<int> seen;
  std::vector<Mesh::FaceHandle> faces;
  for (const auto& [v, p] : points)
    for (auto f : mesh_.vf_range(v))
      if (seen.insert(f.idx()).second) faces.push_back(f);
  std::sort(faces.begin(), faces.end());
  for (auto f : faces) opts_.guard->erase(mesh_, f);
  for (const auto& [v, p] : points) mesh_.set_point(v, p);
  for (auto f : faces) opts_.guard->insert(mesh_, f);
  return faces;
}

// Moves the walls apart at the disk's holes (see the top of the file); true when the moved faces
// meet nothing they did not meet before (*before then gets the moved vertices' points before
// their first move), false with nothing moved. *largest: the largest move so far, mm.
bool Surgery::widen_at_holes(const CutDisk& disk, const std::vector<SidedTriangle>& sided, const std::vector<int>& ids,
                             double shift, std::vector<std::pair<Mesh::VertexHandle, Vec3>>* before, double* largest) {
  const auto moves = widening_moves(disk, vertex_sides(sided, ids), shift);
  if (moves.empty()) return false;
  std::vector<std::pair<Mesh::VertexHandle, Vec3>> old, moved;
  for (const auto& [v, d] : moves) old.push_back({v, mesh_.point(v)}), moved.push_back({v, mesh_.point(v) + d});
  if (new_pairs(set_points(moved), 1) > 0) {
    set_points(old);
    return false;
  }
  std::unordered_set<int> known;
  for (const auto& [v, p] : *before) known.insert(v.idx());
  for (const auto& [v, p] : old)
    if (!known.count(v.idx())) before->push_back({v, p});
  for (const auto& [v, p] : *before) *largest = std::max(*largest, (mesh_.point(v) - p).norm());
  return true;
}

}  // namespace cf::detail
