// Cap placement of cut_and_cap(): steps 6-8 of the Surgery (surgery_steps.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_debug.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
// Loops up to this many vertices get triangulated caps (O(k^3) time, O(k^2) memory: about 10 s
// and 0.7 GB at 2000 vertices); longer ones get concentric-ring caps in one placement.
constexpr std::size_t kMaxTriangulatedLoop = 2000;
// Grid queries (candidate triangles tested against the surface) the restricted triangulations of
// one surgery may make in all: each costs 0.1-0.3 ms on long rings (their triangles span many
// grid cells), so this bounds a surgery's restricted triangulations to about 20-60 s of CPU,
// where they used to take up to 96 s (issue 26). A ring that needs more has had most of its
// triangles refused: it crosses the surface nearly everywhere. On the real CT surface a
// successful 96-vertex cap took 76,000 queries over 5 placements, a failing 211-vertex pair
// 120,000 per placement.
constexpr long long kMaxGridQueries = 200000;
// The same for a trial (an alternative loop of the fallback, kept only when clean): half of it. A
// trial whose right ring has a clean triangulation and whose left one has none repeats that in
// every placement (the real CT surface's 211-vertex trial: 30 K + 2-15 K queries per placement,
// 5 placements, 12-27 s, never clean); the trial pairs that were capped cleanly there needed up
// to 96 K queries (right 24 K + left 72 K, first placement).
constexpr long long kMaxTrialGridQueries = 100000;
// Relaxation sweeps per ring of a concentric disk (uniform Laplacian, ring fixed): enough for the
// rings to settle into a minimal surface over a non-convex ring.
constexpr int kSweepsPerRing = 20;

Vec3 area_normal(const Mesh& mesh, Mesh::FaceHandle f) {
  auto it = mesh.cfv_iter(f);
  const Vec3 a = mesh.point(*it), b = mesh.point(*++it), d = mesh.point(*++it);
  return OpenMesh::cross(b - a, d - a);
}
}  // namespace

void loop_radius_and_edge(const std::vector<Vec3>& p, double* radius, double* edge, Vec3* centroid) {
  const std::size_t n = p.size();
  Vec3 c(0, 0, 0);
  for (const auto& q : p) c += q / double(n);
  *radius = *edge = 0;
  for (std::size_t i = 0; i < n; ++i) {
    *radius += (p[i] - c).norm() / double(n);
    *edge += (p[(i + 1) % n] - p[i]).norm() / double(n);
  }
  if (centroid) *centroid = c;
}

std::vector<std::vector<Vec3>> concentric_disk_rows(const std::vector<Vec3>& p, int m) {
  const std::size_t n = p.size();
  double radius = 0, edge = 0;
  Vec3 c(0, 0, 0);
  loop_radius_and_edge(p, &radius, &edge, &c);
  std::vector<std::vector<Vec3>> rows(m, std::vector<Vec3>(n));
  for (int j = 0; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i) rows[j][i] = (1.0 - double(j) / m) * p[i] + (double(j) / m) * c;
  rows.push_back({c});
  std::vector<std::vector<Vec3>> next = rows;  // row 0 stays p in both buffers
  for (int sweep = 0; sweep < kSweepsPerRing * m; ++sweep) {
    for (int j = 1; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t a = (i + 1) % n, b = (i + n - 1) % n;
        const Vec3 in = j + 1 < m ? rows[j + 1][i] + rows[j + 1][a] : 2.0 * rows[m][0];
        next[j][i] = (rows[j][a] + rows[j][b] + rows[j - 1][i] + rows[j - 1][b] + in) / 6.0;
      }
    Vec3 centre(0, 0, 0);
    for (std::size_t i = 0; i < n; ++i) centre += rows[m - 1][i] / double(n);
    next[m][0] = centre;
    rows.swap(next);
  }
  return rows;
}

Vec3 vertex_area_normal(const Mesh& mesh, Mesh::VertexHandle v) {
  Vec3 nrm(0, 0, 0);
  for (auto f : mesh.vf_range(v)) nrm += area_normal(mesh, f);
  return nrm;
}

// 6. Side targets: after the split, a ring vertex's non-ring neighbours are exactly its own
//    side's; a ring is pulled towards the centroid of those (face barycentres as a fallback),
//    projected on the tangent plane.
std::vector<Vec3> Surgery::side_targets(const std::vector<Mesh::VertexHandle>& ring) const {
  std::unordered_set<int> in_ring;
  for (auto v : ring) in_ring.insert(v.idx());
  std::vector<Vec3> target(ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) {
    Vec3 c(0, 0, 0);
    int n = 0;
    for (auto w : mesh_.vv_range(ring[i]))
      if (!in_ring.count(w.idx())) {
        c += mesh_.point(w);
        ++n;
      }
    if (n == 0) {
      for (auto f : mesh_.vf_range(ring[i])) {
        Vec3 b(0, 0, 0);
        for (auto w : mesh_.fv_range(f)) b += mesh_.point(w);
        c += b / 3.0;
        ++n;
      }
    }
    target[i] = n ? c / double(n) : mesh_.point(ring[i]);
    Vec3 nrm = vertex_area_normal(mesh_, ring[i]);
    if (nrm.norm() > 0) {
      nrm /= nrm.norm();
      const Vec3 move = target[i] - mesh_.point(ring[i]);
      target[i] = mesh_.point(ring[i]) + move - OpenMesh::dot(move, nrm) * nrm;
    }
  }
  return target;
}

// Edge targets: the far end of the side edge most across the ring (direction least aligned
// with the ring's tangent). A ring vertex moved along an edge of its own side stays on the old
// surface, which keeps the faces around it from folding where the surface is creased
// (marching-cubes junctions) and the averaged normal of the tangential target misleads.
std::vector<Vec3> Surgery::edge_targets(const std::vector<Mesh::VertexHandle>& ring) const {
  std::unordered_set<int> in_ring;
  for (auto v : ring) in_ring.insert(v.idx());
  std::vector<Vec3> target(ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec3 p = mesh_.point(ring[i]);
    Vec3 tangent = mesh_.point(ring[(i + 1) % k_]) - mesh_.point(ring[(i + k_ - 1) % k_]);
    if (tangent.norm() > 0) tangent /= tangent.norm();
    target[i] = p;
    double best = 2;
    for (auto w : mesh_.vv_range(ring[i])) {
      if (in_ring.count(w.idx())) continue;
      const Vec3 d = mesh_.point(w) - p;
      const double len = d.norm();
      if (len == 0) continue;
      const double align = std::fabs(OpenMesh::dot(d / len, tangent));
      if (align < best) {
        best = align;
        target[i] = mesh_.point(w);
      }
    }
  }
  return target;
}

void Surgery::place_rings(double pull, const std::vector<Vec3>& left_target, const std::vector<Vec3>& right_target) {
  for (std::size_t i = 0; i < k_; ++i) {
    mesh_.point(result_.left_ring[i]) = original_[i] + pull * (left_target[i] - original_[i]);
    mesh_.point(result_.right_ring[i]) = original_[i] + pull * (right_target[i] - original_[i]);
  }
}

std::vector<Mesh::FaceHandle> Surgery::faces_around_rings() const {
  std::vector<Mesh::FaceHandle> faces;
  for (const auto* ring : {&result_.left_ring, &result_.right_ring})
    for (auto v : *ring)
      for (auto f : mesh_.vf_range(v)) faces.push_back(f);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

// The ring placements tried, in order: pulls 0.25 (ring-pull), 0.4 and 0.15 towards the side
// targets and along a side edge each, then 0.08 along the edge.
std::vector<Surgery::Placement> Surgery::placements() const {
  std::vector<Placement> out;
  for (const Placement tr : {Placement{opts_.ring_pull, false}, Placement{opts_.ring_pull, true}, Placement{0.4, false},
                             Placement{0.4, true}, Placement{0.15, false}, Placement{0.15, true}, Placement{0.08, true}})
    if (tr.pull > 0) out.push_back(tr);
  return out;
}

// Moves the rings to placement `tr`; true when the faces around them then intersect nothing.
bool Surgery::place_checked(const Placement& tr) {
  place_rings(tr.pull, tr.along_edge ? edge_left_ : target_left_, tr.along_edge ? edge_right_ : target_right_);
  for (auto f : ring_faces_) opts_.guard->insert(mesh_, f);
  return new_pairs(ring_faces_, 1) == 0;
}

// 7a. With a guard, loops up to kMaxTriangulatedLoop vertices first try minimum-area
//     triangulations of the pulled rings (no interior vertex: on an elongated loop around a thin
//     curved band they join opposite sides and follow the band) in every placement; then collar
//     caps (surgery_collar.cpp: the rings lifted off the wall first) in the first clean
//     placement; then, in
//     every placement, minimum-area triangulations restricted to triangles that intersect
//     nothing (a grid query per candidate triangle: the expensive step, so it comes last, within
//     kMaxGridQueries, and stops once the right ring has none; not with opts_.restricted off).
//     Kept when neither the caps nor the faces around the pulled rings intersect anything.
bool Surgery::try_triangulated_caps() {
  if (!opts_.guard || k_ > kMaxTriangulatedLoop) return false;
  edge_left_ = edge_targets(result_.left_ring);
  edge_right_ = edge_targets(result_.right_ring);
  ring_faces_ = faces_around_rings();
  query_budget_ = opts_.trial ? kMaxTrialGridQueries : kMaxGridQueries;
  std::vector<std::array<int, 3>> tri_right, tri_left;
  for (const char* kind : {"plain", "collar", "front", "restricted"}) {
    const bool avoid = kind[0] == 'r', lifted = kind[0] == 'c' || kind[0] == 'f';
    if (avoid && !opts_.restricted) break;
    if (kind[0] == 'f' && !opts_.front) continue;
    const std::vector<Placement> tried = placements();
    for (std::size_t index = 0; index < tried.size(); ++index) {
      const Placement& tr = tried[index];
      if (gave_up_ || !place_checked(tr)) continue;
      const bool done = kind[0] == 'c'   ? try_collar_caps()
                        : kind[0] == 'f' ? try_front_caps()
                                         : triangulate_both(avoid, &tri_right, &tri_left);
      if (lifted && !done) break;  // the first clean placement only: a lift moves the rings far more than a placement
      if (!done) continue;
      if (!lifted) add_triangulated_caps(tri_right, tri_left);
      cap_kind_ = kind;
      result_.placement = static_cast<int>(index);
      return true;
    }
  }
  return false;
}

void Surgery::add_triangulated_caps(const std::vector<std::array<int, 3>>& right,
                                    const std::vector<std::array<int, 3>>& left) {
  add_cap(mesh_, right, opts_.guard, "surgery");  // ear order: each face joins the hole's boundary
  add_cap(mesh_, left, opts_.guard, "surgery");
  set_chord_classes(result_.right_ring);
  set_chord_classes(left_cap_order(result_.left_ring));
  result_.right_cap = result_.right_ring[0];
  result_.left_cap = result_.left_ring[0];
  result_.intersections = 0;
}

// Classes of a triangulated cap's chords: ring vertex i gets the potential P_i (prefix XOR of
// the ring's edge classes) and chord (i, j) the class P_i ^ P_j, so every cap triangle sums to zero.
std::unordered_map<int, std::vector<std::uint64_t>> Surgery::ring_potentials(
    const std::vector<Mesh::VertexHandle>& ring) const {
  std::unordered_map<int, std::vector<std::uint64_t>> potential;
  std::vector<std::uint64_t> acc(words_, 0);
  for (std::size_t i = 0; i < ring.size(); ++i) {
    potential[ring[i].idx()] = acc;
    const auto he = mesh_.find_halfedge(ring[i], ring[(i + 1) % ring.size()]);
    xor_into(acc.data(), homology_->edge_class(mesh_.edge_handle(he)), words_);
  }
  return potential;
}

std::vector<Mesh::VertexHandle> Surgery::left_cap_order(const std::vector<Mesh::VertexHandle>& ring) {
  std::vector<Mesh::VertexHandle> order{ring[0]};
  for (std::size_t i = ring.size() - 1; i >= 1; --i) order.push_back(ring[i]);
  return order;
}

void Surgery::set_chord_classes(const std::vector<Mesh::VertexHandle>& ring) {
  if (!homology_) return;
  auto potential = ring_potentials(ring);
  std::vector<std::uint64_t> cls(words_);
  for (std::size_t i = 0; i < k_; ++i)
    for (auto he : mesh_.voh_range(ring[i])) {
      const auto w = mesh_.to_vertex_handle(he);
      auto it = potential.find(w.idx());
      if (it == potential.end()) continue;                                   // not a chord of this ring
      const std::size_t j = static_cast<std::size_t>(std::find(ring.begin(), ring.end(), w) - ring.begin());
      if (j == (i + 1) % k_ || i == (j + 1) % k_) continue;                 // a ring edge (old)
      for (int b = 0; b < words_; ++b) cls[b] = potential[ring[i].idx()][b] ^ it->second[b];
      homology_->set_edge_class(mesh_.edge_handle(he), cls.data());
    }
}

// 7. Concentric caps (topology): a disk spanning each ring, made of m concentric rings around a
//    centre vertex (m = 1: the paper's fan).
ConcentricCap Surgery::make_concentric_cap(const std::vector<Mesh::HalfedgeHandle>& ring_halfedges) {
  ConcentricCap cap;
  const std::size_t n = ring_halfedges.size();
  std::vector<Mesh::VertexHandle> first(n);
  for (std::size_t i = 0; i < n; ++i) first[i] = mesh_.from_vertex_handle(ring_halfedges[i]);
  const int m = std::max(1, std::min(opts_.cap_rings, static_cast<int>(n) / 4));
  cap.rings.push_back(first);
  for (int j = 1; j < m; ++j) {
    std::vector<Mesh::VertexHandle> rj(n);
    for (std::size_t i = 0; i < n; ++i) rj[i] = mesh_.add_vertex(Vec3(0, 0, 0));
    cap.rings.push_back(std::move(rj));
  }
  cap.centre = mesh_.add_vertex(Vec3(0, 0, 0));
  auto add = [&](Mesh::VertexHandle a, Mesh::VertexHandle b, Mesh::VertexHandle c) {
    const auto f = mesh_.add_face(a, b, c);
    if (!f.is_valid()) throw Error("surgery: could not add a cap triangle");
    cap.faces.push_back(f);
  };
  for (int j = 0; j + 1 < m; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t i1 = (i + 1) % n;
      add(cap.rings[j][i], cap.rings[j][i1], cap.rings[j + 1][i1]);
      add(cap.rings[j][i], cap.rings[j + 1][i1], cap.rings[j + 1][i]);
    }
  for (std::size_t i = 0; i < n; ++i) add(cap.rings[m - 1][i], cap.rings[m - 1][(i + 1) % n], cap.centre);
  set_concentric_classes(cap, ring_halfedges);
  return cap;
}

// Both caps, already added with interior vertices (front caps, minimum-cut caps): their new edges'
// classes (the left ring in the left cap's order, along the new opposite halfedges) and the result's caps.
void Surgery::finish_caps_with_interior(const std::vector<Mesh::VertexHandle>& right_inner,
                                        const std::vector<Mesh::VertexHandle>& left_inner) {
  set_cap_classes(result_.right_ring, loop_halfedges_, right_inner);
  set_cap_classes(left_cap_order(result_.left_ring),
                  std::vector<Mesh::HalfedgeHandle>(new_opposites_.rbegin(), new_opposites_.rend()), left_inner);
  result_.right_cap = result_.right_ring[0];
  result_.left_cap = result_.left_ring[0];
  result_.intersections = 0;
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

void Surgery::set_concentric_classes(const ConcentricCap& cap, const std::vector<Mesh::HalfedgeHandle>& ring_halfedges) {
  std::vector<Mesh::VertexHandle> inner;
  for (std::size_t j = 1; j < cap.rings.size(); ++j) inner.insert(inner.end(), cap.rings[j].begin(), cap.rings[j].end());
  inner.push_back(cap.centre);
  set_cap_classes(cap.rings[0], ring_halfedges, inner);
}

// 8. Geometry of one concentric cap: interior rings interpolated towards the ring centroid and
//    relaxed to a discrete minimal surface (concentric_disk_rows(), ring fixed), then bulged by
//    `dome` (x mean ring edge) against the cap's normal, i.e. into its own side.
void Surgery::shape_concentric_cap(ConcentricCap& cap, double dome) {
  const auto& first = cap.rings[0];
  const std::size_t n = first.size();
  const int m = static_cast<int>(cap.rings.size());
  std::vector<Vec3> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = mesh_.point(first[i]);
  const std::vector<std::vector<Vec3>> rows = concentric_disk_rows(p, m);
  for (int j = 1; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i) mesh_.point(cap.rings[j][i]) = rows[j][i];
  mesh_.point(cap.centre) = rows[m][0];
  if (dome == 0) return;
  double radius = 0, edge = 0;
  loop_radius_and_edge(p, &radius, &edge);
  Vec3 nrm(0, 0, 0);
  for (auto f : cap.faces) nrm += area_normal(mesh_, f);
  if (nrm.norm() > 0) nrm /= nrm.norm();
  for (int j = 1; j < m; ++j) {
    const double t = double(j) / m;
    for (auto v : cap.rings[j]) mesh_.point(v) -= dome * edge * (1 - (1 - t) * (1 - t)) * nrm;
  }
  mesh_.point(cap.centre) -= dome * edge * nrm;
}

// A placement = ring pull (towards the side targets) + cap shape.
void Surgery::place_concentric(double pull, double dome) {
  place_rings(pull, target_left_, target_right_);
  shape_concentric_cap(cap_left_, dome);
  shape_concentric_cap(cap_right_, dome);
}

void Surgery::concentric_caps() {
  cap_right_ = make_concentric_cap(loop_halfedges_);  // h_0 -> h_1 -> ...
  cap_left_ = make_concentric_cap(std::vector<Mesh::HalfedgeHandle>(new_opposites_.rbegin(), new_opposites_.rend()));
  result_.right_cap = cap_right_.centre;
  result_.left_cap = cap_left_.centre;
  place_concentric(opts_.ring_pull, 0.0);
  if (opts_.guard) search_concentric_placement();
}

// With a guard: the placement with the fewest intersecting pairs among pulls x domes (each a
// full check of the faces it moves); loops above kMaxTriangulatedLoop keep the first one. Domes
// of 0.25-1 ring edge (a wall's staircase next to the loop) and of 0.15-0.8 times the loop's
// radius: where the loop runs round a window in a thin wall and the wall's remnants lie in the
// window, in the loop's own plane, only a dome well out of that plane passes over them (issue 26:
// the real CT surface's 65.8 mm loop, 1068 pairs with the low domes, 292 with the high ones).
void Surgery::search_concentric_placement() {
  std::vector<Mesh::FaceHandle> moving = cap_left_.faces;
  moving.insert(moving.end(), cap_right_.faces.begin(), cap_right_.faces.end());
  const std::vector<Mesh::FaceHandle> around = faces_around_rings();
  moving.insert(moving.end(), around.begin(), around.end());
  std::sort(moving.begin(), moving.end());
  moving.erase(std::unique(moving.begin(), moving.end()), moving.end());
  auto refresh = [&]() {
    for (auto f : moving) opts_.guard->insert(mesh_, f);
  };
  refresh();
  // A trial is kept only when clean, so its count stops at the first pair (a 241-vertex trial's
  // 4 294 pairs cost 0.5 s to count); every other cut reports its full count.
  std::size_t best = new_pairs(moving, opts_.trial ? 1 : SIZE_MAX);
  double best_pull = opts_.ring_pull, best_dome = 0;
  if (best > 0 && k_ <= kMaxTriangulatedLoop && !opts_.trial) {
    double radius = 0, edge = 0;
    loop_radius_and_edge(original_, &radius, &edge);
    const double r = radius / edge;  // the loop's radius in ring edges
    for (double pull : {opts_.ring_pull, 0.4, 0.15})
      for (double dome : {0.25, 0.5, 1.0, 0.0, -0.25, 0.15 * r, 0.3 * r, 0.5 * r, 0.8 * r}) {
        if (pull <= 0 && dome == 0) continue;
        place_concentric(pull, dome);
        refresh();
        // Only n < best matters; probing, only n == 0 (the first pair ends the count).
        const std::size_t n = new_pairs(moving, opts_.probe_concentric ? 1 : best);
        if (n < best && (n == 0 || !opts_.probe_concentric)) {
          best = n;
          best_pull = pull;
          best_dome = dome;
        }
        if (best == 0) break;
      }
    place_concentric(best_pull, best_dome);
    refresh();
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: concentric k=%zu: pull %.2f, dome %.2f edges, %zu pairs\n", k_, best_pull, best_dome, best);
  }
  result_.intersections = best;
}

}  // namespace cf::detail
