// Sheet caps of cut_and_cap() (step 7b of the Surgery, surgery_steps.h): both caps are copies of
// one disk spanning the loop, each pushed to its own side of it.
#include <algorithm>
#include <cmath>
#include <deque>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/denoise/face_grid.h"
#include "colonflat/denoise/spanning_disk.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
// Offsets of the sheets from the disk, as fractions of the rings' own distance from it: the full
// distance first (the caps meet their rings without a kink), then a quarter (room for the caps
// between earlier caps or walls closer than the rings' separation).
constexpr double kSheetOffsets[] = {1.0, 0.25};
// Lifts of the disk off the surface along the surface normal at the loop, in mean ring edges, both
// ways (into the solid for a handle, out of it for a tunnel; which one is free is left to the
// check): where the loop runs over a flat stretch of surface, the spanning disk lies in the
// surface's plane on one side of the loop and has to be raised above it.
constexpr double kSheetLifts[] = {0, 1, -1, 3, -3, 6, -6};
// Sheet caps are tried in the first placements only (pull towards the side targets and along a
// side edge): the lifts and offsets, not the pull, decide whether a sheet is clean.
constexpr std::size_t kSheetPlacements = 2;
}  // namespace

// 7b. Sheet caps. D = spanning_disk() of the loop's original positions (minimum-area
//     triangulation refined to the ring's mean edge and faired; every edge has an interior
//     end), lifted off the surface by l (kSheetLifts; the lift rises over the first two edges
//     from the ring, along the surface normal at the nearest loop vertex). The right cap is D
//     with its interior vertices moved delta along D's normal towards the side the right ring
//     was pulled to, the left cap the same moved the other way, delta = the rings' mean
//     distance from D (kSheetOffsets). The caps lie on the two sides of D, so they cannot cross
//     each other where D is smooth on the scale of delta; the exact check decides, for each
//     placement, lift and offset (a failing one stops at the first crossing pair, nearest the
//     ring first). When none is clean the caps are removed again (the mesh and the guard are as
//     before) and the caller goes on with the restricted triangulations.
bool Surgery::try_sheet_caps() {
  double edge = 0;
  for (std::size_t i = 0; i < k_; ++i) edge += (original_[(i + 1) % k_] - original_[i]).norm();
  edge /= double(k_);
  const SpanningDisk disk = spanning_disk(original_, edge);
  if (disk.triangles.empty()) return false;
  const std::size_t nv = mesh_.n_vertices(), ne = mesh_.n_edges(), nf = mesh_.n_faces();
  sheet_right_.assign(result_.right_ring.begin(), result_.right_ring.end());
  sheet_left_.assign(result_.left_ring.begin(), result_.left_ring.end());
  for (std::size_t j = k_; j < disk.points.size(); ++j) {
    sheet_right_.push_back(mesh_.add_vertex(disk.points[j]));
    sheet_left_.push_back(mesh_.add_vertex(disk.points[j]));
  }
  std::vector<Mesh::FaceHandle> moving = ring_faces_;  // breadth-first from the rings: near ones first
  for (std::size_t t = 0; t < disk.triangles.size(); ++t)
    for (int side = 0; side < 2; ++side) {
      const auto& map = side == 0 ? sheet_right_ : sheet_left_;
      const auto& c = disk.triangles[t];
      const auto f = side == 0 ? mesh_.add_face(map[c[0]], map[c[1]], map[c[2]]) : mesh_.add_face(map[c[0]], map[c[2]], map[c[1]]);
      if (!f.is_valid()) {
        remove_caps(nv, ne, nf);
        return false;
      }
      moving.push_back(f);
    }
  sheet_lift_setup(disk);
  if (std::getenv("COLONFLAT_DENOISE_DEBUG")) debug_sheet(disk, nf, moving);
  const bool clean = sheet_search(disk, edge, moving);
  if (!clean) {
    remove_caps(nv, ne, nf);
    return false;
  }
  std::vector<Mesh::VertexHandle> order_left{result_.left_ring[0]};
  for (std::size_t i = k_ - 1; i >= 1; --i) order_left.push_back(result_.left_ring[i]);
  set_cap_classes(result_.right_ring, loop_halfedges_,
                  std::vector<Mesh::VertexHandle>(sheet_right_.begin() + k_, sheet_right_.end()));
  set_cap_classes(order_left, std::vector<Mesh::HalfedgeHandle>(new_opposites_.rbegin(), new_opposites_.rend()),
                  std::vector<Mesh::VertexHandle>(sheet_left_.begin() + k_, sheet_left_.end()));
  result_.right_cap = result_.right_ring[0];
  result_.left_cap = result_.left_ring[0];
  result_.intersections = 0;
  return true;
}

// The first (placement, lift, offset) whose sheets and ring faces intersect nothing: a quick
// yes/no test per face (FaceGrid::hits, first hit ends it), then the exact count to confirm.
bool Surgery::sheet_search(const SpanningDisk& disk, double edge, const std::vector<Mesh::FaceHandle>& moving) {
  const std::vector<Placement> all = placements();
  for (std::size_t p = 0; p < std::min(kSheetPlacements, all.size()); ++p) {
    if (!place_checked(all[p])) continue;
    for (double lift : kSheetLifts)
      for (double scale : kSheetOffsets) {
        position_sheet(disk, lift * edge, scale);
        for (auto f : moving) opts_.guard->insert(mesh_, f);
        const bool hit = std::any_of(moving.begin(), moving.end(), [&](Mesh::FaceHandle f) {
          std::array<int, 3> ids;
          int i = 0;
          for (auto v : mesh_.fv_range(f)) ids[i++] = v.idx();
          return opts_.guard->hits(mesh_, ids);
        });
        if (!hit && opts_.guard->count_intersections(mesh_, moving) == 0) return true;
      }
  }
  return false;
}

// Per disk point: the nearest ring vertex and the distance in edges (breadth-first over the
// disk); per ring vertex: the unit surface normal (faces around both of its copies).
void Surgery::sheet_lift_setup(const SpanningDisk& disk) {
  const std::size_t n = disk.points.size();
  std::vector<std::vector<int>> adj(n);
  for (const auto& t : disk.triangles)
    for (int e = 0; e < 3; ++e) adj[t[e]].push_back(t[(e + 1) % 3]), adj[t[(e + 1) % 3]].push_back(t[e]);
  sheet_hops_.assign(n, -1);
  sheet_nearest_.assign(n, 0);
  std::deque<int> queue;
  for (std::size_t i = 0; i < k_; ++i) sheet_hops_[i] = 0, sheet_nearest_[i] = static_cast<int>(i), queue.push_back(static_cast<int>(i));
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    for (int w : adj[v])
      if (sheet_hops_[w] < 0) sheet_hops_[w] = sheet_hops_[v] + 1, sheet_nearest_[w] = sheet_nearest_[v], queue.push_back(w);
  }
  sheet_normal_.assign(k_, Vec3(0, 0, 0));
  for (std::size_t i = 0; i < k_; ++i) {
    for (auto v : {result_.right_ring[i], result_.left_ring[i]})
      for (auto f : mesh_.vf_range(v)) {
        if (f.idx() >= static_cast<int>(result_.undo.faces)) continue;  // a cap face, not the surface
        auto it = mesh_.cfv_iter(f);
        const Vec3 a = mesh_.point(*it), b = mesh_.point(*++it), c = mesh_.point(*++it);
        sheet_normal_[i] += OpenMesh::cross(b - a, c - a);
      }
    if (sheet_normal_[i].norm() > 0) sheet_normal_[i] /= sheet_normal_[i].norm();
  }
}

// COLONFLAT_DENOISE_DEBUG: what the sheet caps of the first placement intersect.
void Surgery::debug_sheet(const SpanningDisk& disk, std::size_t first_cap_face, const std::vector<Mesh::FaceHandle>& moving) {
  place_checked(placements().front());
  position_sheet(disk, 0.0, 1.0);
  for (auto f : moving) opts_.guard->insert(mesh_, f);
  const auto pairs = opts_.guard->intersecting_pairs(mesh_, moving);
  std::unordered_set<int> ring_face(ring_faces_.size());
  for (auto f : ring_faces_) ring_face.insert(f.idx());
  const int half = static_cast<int>(disk.triangles.size());
  auto kind = [&](int f) {
    if (f >= static_cast<int>(first_cap_face)) return (f - static_cast<int>(first_cap_face)) % 2;
    return ring_face.count(f) ? 2 : 3;
  };
  auto dist_to_loop = [&](int f) {
    Vec3 c(0, 0, 0);
    for (auto v : mesh_.fv_range(Mesh::FaceHandle(f))) c += mesh_.point(v) / 3.0;
    double d = 1e300;
    for (const auto& p : original_) d = std::min(d, (p - c).norm());
    return d;
  };
  int count[4][4] = {};
  std::vector<double> far;
  for (auto [a, b] : pairs) {
    const int ka = kind(a), kb = kind(b);
    ++count[std::min(ka, kb)][std::max(ka, kb)];
    if (std::max(ka, kb) == 3) far.push_back(dist_to_loop(ka == 3 ? b : a));
  }
  std::sort(far.begin(), far.end());
  // Directions at each ring vertex: into the disk (u, towards its centroid of interior
  // neighbours), to each side (the side targets); histogram of the side-side and disk-side cosines.
  std::vector<Vec3> inward(k_, Vec3(0, 0, 0));
  for (const auto& t : disk.triangles)
    for (int c = 0; c < 3; ++c)
      if (t[c] < static_cast<int>(k_))
        for (int o = 0; o < 3; ++o)
          if (t[o] >= static_cast<int>(k_)) inward[t[c]] += disk.points[t[o]] - disk.points[t[c]];
  int hist[3][5] = {};
  for (std::size_t i = 0; i < k_; ++i) {
    auto unit = [](Vec3 v) { return v.norm() > 0 ? v / v.norm() : v; };
    const Vec3 u = unit(inward[i]), r = unit(target_right_[i] - original_[i]), l = unit(target_left_[i] - original_[i]);
    const double c[3] = {OpenMesh::dot(r, l), OpenMesh::dot(u, r), OpenMesh::dot(u, l)};
    for (int q = 0; q < 3; ++q) ++hist[q][std::min(4, static_cast<int>((c[q] + 1) * 2.5))];
  }
  for (int q = 0; q < 3; ++q)
    std::fprintf(stderr, "denoise debug:   cos(%s) histogram [-1..1 in 5]: %d %d %d %d %d\n",
                 q == 0 ? "right, left" : q == 1 ? "disk, right" : "disk, left", hist[q][0], hist[q][1], hist[q][2],
                 hist[q][3], hist[q][4]);
  std::fprintf(stderr, "denoise debug: sheet of %zu vertices (%zu disk points, %d faces each): %zu pairs: R-R %d R-L %d L-L %d "
               "R-ring %d L-ring %d ring-ring %d R-surface %d L-surface %d ring-surface %d; cap faces hitting the surface "
               "at %.2f / %.2f / %.2f mm from the loop (min / median / max)\n", k_, disk.points.size(), half, pairs.size(),
               count[0][0], count[0][1], count[1][1], count[0][2], count[1][2], count[2][2], count[0][3], count[1][3], count[2][3],
               far.empty() ? 0 : far.front(), far.empty() ? 0 : far[far.size() / 2], far.empty() ? 0 : far.back());
}

// Interior vertices of the two sheets for the current ring placement: D lifted by `lift` mm
// (full height two edges from the ring), then moved +-scale * delta along the lifted disk's
// normals (the sign puts the right sheet on the right ring's side).
void Surgery::position_sheet(const SpanningDisk& disk, double lift, double scale) {
  const std::size_t n = disk.points.size();
  std::vector<Vec3> pts(n), nrm(n, Vec3(0, 0, 0));
  for (std::size_t j = 0; j < n; ++j)
    pts[j] = disk.points[j] + lift * std::min(1.0, 0.5 * sheet_hops_[j]) * sheet_normal_[sheet_nearest_[j]];
  for (const auto& t : disk.triangles) {
    const Vec3 a = OpenMesh::cross(pts[t[1]] - pts[t[0]], pts[t[2]] - pts[t[0]]);
    for (int c : t) nrm[c] += a;
  }
  for (auto& v : nrm)
    if (v.norm() > 0) v /= v.norm();
  double side = 0, delta = 0;
  for (std::size_t i = 0; i < k_; ++i) {
    const double r = OpenMesh::dot(mesh_.point(result_.right_ring[i]) - original_[i], nrm[i]);
    const double l = OpenMesh::dot(mesh_.point(result_.left_ring[i]) - original_[i], nrm[i]);
    side += r - l;
    delta += 0.5 * std::fabs(r - l);
  }
  const double d = (side >= 0 ? 1.0 : -1.0) * scale * delta / double(k_);
  for (std::size_t j = k_; j < n; ++j) {
    mesh_.point(sheet_right_[j]) = pts[j] + d * nrm[j];
    mesh_.point(sheet_left_[j]) = pts[j] - d * nrm[j];
  }
}

// Drops the elements added since (vertices, edges, faces) - caps added to the open rings - and
// re-links the two rings as boundaries (add_face only rewired the rings' halfedges and vertices).
void Surgery::remove_caps(std::size_t vertices, std::size_t edges, std::size_t faces) {
  mesh_.resize(vertices, edges, faces);
  link_boundary_rings();
  opts_.guard->forget_faces_from(static_cast<int>(faces));
}

// Classes of a cap's new edges: ring vertex i gets the potential P_i (prefix XOR of the ring's
// edge classes), interior vertices 0, and each new edge (a, b) the class P(a) ^ P(b), so every
// cap triangle sums to zero (the closing one to the loop's class, which the caller quotients
// out). Every new edge has an interior end.
void Surgery::set_cap_classes(const std::vector<Mesh::VertexHandle>& ring,
                              const std::vector<Mesh::HalfedgeHandle>& ring_halfedges,
                              const std::vector<Mesh::VertexHandle>& inner) {
  if (!homology_) return;
  std::unordered_map<int, std::vector<std::uint64_t>> potential;
  std::vector<std::uint64_t> acc(words_, 0);
  for (std::size_t i = 0; i < ring_halfedges.size(); ++i) {
    potential[ring[i].idx()] = acc;
    xor_into(acc.data(), homology_->edge_class(mesh_.edge_handle(ring_halfedges[i])), words_);
  }
  const std::vector<std::uint64_t> zero(words_, 0);
  auto pot = [&](Mesh::VertexHandle v) -> const std::vector<std::uint64_t>& {
    auto it = potential.find(v.idx());
    return it == potential.end() ? zero : it->second;
  };
  std::vector<std::uint64_t> cls(words_);
  for (auto v : inner)
    for (auto he : mesh_.voh_range(v)) {
      const auto& q0 = pot(v);
      const auto& q1 = pot(mesh_.to_vertex_handle(he));
      for (int i = 0; i < words_; ++i) cls[i] = q0[i] ^ q1[i];
      homology_->set_edge_class(mesh_.edge_handle(he), cls.data());
    }
}

}  // namespace cf::detail
