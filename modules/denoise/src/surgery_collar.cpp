// Collar caps of cut_and_cap() (step 7b of the Surgery, surgery_steps.h).
//
// A cap without interior vertices starts out along the chords of its ring. Where the loop runs
// over a wall in the wall's own tangent plane (the failing loops of the real CT surface, issue 26:
// a 7.6 mm loop with 6 vertices on a sheet facing one way and 5 on a sheet facing the other, and
// 65.8-165 mm loops whose minimum-area disk leaves the ring along the surface of one side), every
// such cap grazes or crosses the wall next to the loop. A collar cap first lifts each ring off
// the wall: a strip from ring vertex p_i to q_i = p_i + h_i s n_i (n_i the unit normal of the
// ring's own side, s = -1 into the solid the surface encloses, +1 out of it) and then spans the
// lifted ring q by its minimum-area triangulation (no grid query: O(k^3) arithmetic only, 0.03 s
// at 200 vertices). h_i is a fraction of the free distance measured along that direction, so a
// collar never reaches the sheet opposite. The left cap is the right one's mirror (the same
// triangles on the left copies, reversed), lifted by a different fraction of its own heights, so
// that the two caps are separated along the normal as well as by the ring pull. Every triangle is
// checked on the guard grid (against the surface and the other cap) before the caps are added.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_debug.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
constexpr double kPi = 3.14159265358979323846;
// Fraction of the free distance along the lift direction a collar may take: two collars lifted
// from facing walls into the same gap (this cut's and a later one's) stay apart (1/3 + 1/3 < 1),
// and a collar leaves 2/3 of the gap between its lifted ring and the opposite sheet.
constexpr double kGapFraction = 1.0 / 3.0;
// Highest lift, in mean ring edges: the relief of a marching-cubes wall (voxel staircase and
// noise) is about one voxel, about one edge; two clear it.
constexpr double kMaxLiftEdges = 2.0;
}  // namespace

std::vector<Vec3> Surgery::unit_normals(const std::vector<Mesh::VertexHandle>& ring) const {
  std::vector<Vec3> out;
  for (auto v : ring) {
    Vec3 n = vertex_area_normal(mesh_, v);
    out.push_back(n.norm() > 0 ? n / n.norm() : n);
  }
  return out;
}

// h_i = min(kGapFraction x free distance along sign x n_i, the highest lift): the highest lift is
// kMaxLiftEdges mean ring edges, and at most a quarter of the loop's radius (length / 2 pi), so
// that on a tube the lifted ring stays a ring and does not reach the axis.
std::vector<double> Surgery::collar_heights(const std::vector<Mesh::VertexHandle>& ring, const std::vector<Vec3>& normals,
                                            double sign) const {
  double length = 0;
  for (std::size_t i = 0; i < k_; ++i) length += (original_[(i + 1) % k_] - original_[i]).norm();
  const double lift = std::min(kMaxLiftEdges * length / double(k_), 0.25 * length / (2 * kPi));
  std::vector<double> h(k_, 0.0);
  for (std::size_t i = 0; i < k_; ++i) {
    if (normals[i].norm() == 0) continue;
    const double free =
        opts_.guard->free_distance(mesh_, mesh_.point(ring[i]), sign * normals[i], lift / kGapFraction, ring[i].idx());
    h[i] = std::min(kGapFraction * free, lift);
  }
  return h;
}

// The right cap of the lifted ring `collar` (ring order, collar[i] above right_ring[i]): the strip
// p_i p_(i+1) q_(i+1), p_i q_(i+1) q_i, then the lifted ring's minimum-area triangulation, in ear
// order. Empty when the lifted ring has none (near-collinear everywhere).
std::vector<std::array<int, 3>> Surgery::collar_right_triangles(const std::vector<Mesh::VertexHandle>& collar) {
  const auto& p = result_.right_ring;
  std::vector<std::array<int, 3>> tris;
  for (std::size_t i = 0; i < k_; ++i) {
    const std::size_t j = (i + 1) % k_;
    tris.push_back({p[i].idx(), p[j].idx(), collar[j].idx()});
    tris.push_back({p[i].idx(), collar[j].idx(), collar[i].idx()});
  }
  const auto disk = triangulate_ring(mesh_, collar, [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; });
  if (disk.empty()) return {};
  tris.insert(tris.end(), disk.begin(), disk.end());
  return tris;
}

// True when no triangle of `tris` (not in the mesh) meets the grid's faces or an earlier one.
bool Surgery::clean(const std::vector<std::array<int, 3>>& tris) const {
  std::vector<std::array<int, 3>> done;
  done.reserve(tris.size());
  for (const auto& t : tris) {
    if (opts_.guard->hits(mesh_, t, done)) {
      if (denoise_debug())
        std::fprintf(stderr, "denoise debug: collar k=%zu: triangle %zu of %zu hits %s\n", k_, done.size(), tris.size(),
                     opts_.guard->hits(mesh_, t, {}) ? "the surface" : "the caps");
      return false;
    }
    done.push_back(t);
  }
  return true;
}

// One collar shape: adds the lifted rings' vertices, builds both caps, and keeps them (added to
// the mesh and the grid) when they intersect nothing; otherwise removes the added vertices.
bool Surgery::collar_caps(const CollarShape& shape, const std::vector<double>& h_right,
                          const std::vector<double>& h_left) {
  const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
  std::vector<Mesh::VertexHandle> collar_right(k_), collar_left(k_);
  std::unordered_map<int, int> mirror;  // right-cap vertex -> its left-cap counterpart
  for (std::size_t i = 0; i < k_; ++i) {
    const Vec3 pr = mesh_.point(result_.right_ring[i]), pl = mesh_.point(result_.left_ring[i]);
    collar_right[i] = mesh_.add_vertex(pr + shape.right_frac * h_right[i] * shape.sign * normal_right_[i]);
    collar_left[i] = mesh_.add_vertex(pl + shape.left_frac * h_left[i] * shape.sign * normal_left_[i]);
    mirror[result_.right_ring[i].idx()] = result_.left_ring[i].idx();
    mirror[collar_right[i].idx()] = collar_left[i].idx();
  }
  std::vector<std::array<int, 3>> right = collar_right_triangles(collar_right), left;
  for (const auto& t : right) left.push_back({mirror.at(t[0]), mirror.at(t[2]), mirror.at(t[1])});
  std::vector<std::array<int, 3>> all = right;
  all.insert(all.end(), left.begin(), left.end());
  if (right.empty() || !clean(all)) {
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  add_cap(mesh_, right, opts_.guard, "surgery (collar)");
  add_cap(mesh_, left, opts_.guard, "surgery (collar)");
  set_collar_classes(result_.right_ring, collar_right);
  set_collar_classes(left_cap_order(result_.left_ring), left_cap_order(collar_left));
  result_.right_cap = result_.right_ring[0];
  result_.left_cap = result_.left_ring[0];
  result_.intersections = 0;
  return true;
}

// Classes of a collar cap's new edges: lifted vertex i takes ring vertex i's potential (prefix XOR
// of the ring's edge classes), and each new edge (a, b) the class P(a) ^ P(b), so every strip and
// disk triangle sums to zero (the closing one to the loop's class, which the caller quotients
// out). Every new edge has a lifted end.
void Surgery::set_collar_classes(const std::vector<Mesh::VertexHandle>& ring,
                                 const std::vector<Mesh::VertexHandle>& collar) {
  if (!homology_) return;
  auto potential = ring_potentials(ring);
  for (std::size_t i = 0; i < ring.size(); ++i) potential[collar[i].idx()] = potential[ring[i].idx()];
  std::vector<std::uint64_t> cls(words_);
  for (auto v : collar)
    for (auto he : mesh_.voh_range(v)) {
      const auto& a = potential.at(v.idx());
      const auto& b = potential.at(mesh_.to_vertex_handle(he).idx());
      for (int w = 0; w < words_; ++w) cls[w] = a[w] ^ b[w];
      homology_->set_edge_class(mesh_.edge_handle(he), cls.data());
    }
}

// The side of the surface where a disk of the loop lies first: -1 (against the normals, into the
// enclosed solid) for a handle loop (sum of n_i . (p_i - centroid) > 0: the normals point away
// from the loop's centre), +1 for a tunnel loop. Precondition: normal_right_ is set.
double Surgery::disk_side() const {
  Vec3 centre(0, 0, 0);
  for (auto v : result_.right_ring) centre += mesh_.point(v);
  centre /= double(k_);
  double spread = 0;
  for (std::size_t i = 0; i < k_; ++i) spread += OpenMesh::dot(normal_right_[i], mesh_.point(result_.right_ring[i]) - centre);
  return spread > 0 ? -1.0 : 1.0;
}

// 7b. Collar caps in the current placement: lifted into the side where a disk of the loop lies
//     first (against the normals for a handle loop, whose disk is inside the enclosed solid:
//     sum of n_i . (p_i - centroid) > 0; along them for a tunnel loop), then the other way; each
//     with the right cap lifted fully and the left one half, then the other way round (which cap
//     must be higher depends on the side the disk extends over).
bool Surgery::try_collar_caps() {
  normal_right_ = unit_normals(result_.right_ring);
  normal_left_ = unit_normals(result_.left_ring);
  const double first = disk_side();
  for (double sign : {first, -first}) {
    const std::vector<double> h_right = collar_heights(result_.right_ring, normal_right_, sign);
    const std::vector<double> h_left = collar_heights(result_.left_ring, normal_left_, sign);
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: collar k=%zu sign %+.0f: heights %.3f-%.3f mm (right), %.3f-%.3f (left)\n", k_,
                   sign, *std::min_element(h_right.begin(), h_right.end()), *std::max_element(h_right.begin(), h_right.end()),
                   *std::min_element(h_left.begin(), h_left.end()), *std::max_element(h_left.begin(), h_left.end()));
    for (const auto& [fr, fl] : {std::pair{1.0, 0.5}, std::pair{0.5, 1.0}})
      if (collar_caps({sign, fr, fl}, h_right, h_left)) return true;
  }
  return false;
}

}  // namespace cf::detail
