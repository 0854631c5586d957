#include "colonflat/denoise/surgery.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <deque>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/vertex_stamps.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_debug.h"
#include "surgery_steps.h"

namespace cf {

namespace detail {

SurgeryResult Surgery::run() {
  check_loop();
  first_new_vertex_ = static_cast<int>(mesh_.n_vertices());
  first_new_face_ = static_cast<int>(mesh_.n_faces());
  gather_left_side();
  record_undo();
  add_left_copies();
  repoint_left_fans();
  relink_left_faces();
  link_boundary_rings();
  target_left_ = side_targets(result_.left_ring);
  target_right_ = side_targets(result_.right_ring);
  original_.resize(k_);
  for (std::size_t i = 0; i < k_; ++i) original_[i] = mesh_.point(loop_[i]);
  copy_loop_classes();
  Stopwatch sw;
  const bool triangulated = opts_.triangulated && try_triangulated_caps();
  const double t_tri = sw.seconds();
  const bool mincut = !triangulated && try_mincut_caps();
  if (!triangulated && !mincut) concentric_caps();
  result_.caps = cap_kind_;
  if (detail::denoise_debug() && (sw.seconds() > 0.2 || !triangulated))  // "concentric": mincut caps included
    std::fprintf(stderr, "denoise debug: surgery of %zu vertices: caps %s, %zu pairs; triangulated %.2f s, concentric %.2f s\n",
                 k_, cap_kind_, result_.intersections, t_tri, sw.seconds() - t_tri);
  return result_;
}

// Face f (older than the surgery) as it was before the cut: a left copy (ids from
// first_new_vertex_, in loop order) is the loop vertex it copies, and ring vertices are where the
// loop was; no other old vertex moves.
void Surgery::original_triangle(int f, std::array<int, 3>* ids, std::array<Vec3, 3>* p) const {
  int i = 0;
  for (auto v : mesh_.fv_range(Mesh::FaceHandle(f))) {
    int id = v.idx();
    std::size_t at = k_;
    if (id >= first_new_vertex_ && id < first_new_vertex_ + static_cast<int>(k_)) {
      at = static_cast<std::size_t>(id - first_new_vertex_);
      id = loop_[at].idx();
    } else {
      at = static_cast<std::size_t>(std::find(loop_.begin(), loop_.end(), v) - loop_.begin());
    }
    (*ids)[i] = id;
    (*p)[i++] = at < k_ ? original_[at] : mesh_.point(v);
  }
}

bool Surgery::intersected_before(int f, int g) const {
  if (f >= first_new_face_ || g >= first_new_face_) return false;
  std::array<int, 3> a, b;
  std::array<Vec3, 3> p, q;
  original_triangle(f, &a, &p);
  original_triangle(g, &b, &q);
  return triangles_intersect_improperly(a, p, b, q);
}

std::size_t Surgery::new_pairs(const std::vector<Mesh::FaceHandle>& faces, std::size_t stop_at) const {
  return opts_.guard->count_intersections(mesh_, faces, stop_at,
                                          [this](int f, int g) { return intersected_before(f, g); });
}

// Preconditions: simple, >= 3 vertices, no boundary vertex, consecutive vertices share an edge.
void Surgery::check_loop() {
  if (k_ < 3) throw PreconditionError("surgery: a loop needs at least 3 vertices (got " + std::to_string(k_) + ")");
  std::unordered_set<int> seen;
  for (auto v : loop_) {
    if (!seen.insert(v.idx()).second)
      throw PreconditionError("surgery: loop is not simple (vertex " + std::to_string(v.idx()) + " repeats)");
    if (mesh_.is_boundary(v))
      throw PreconditionError("surgery: loop vertex " + std::to_string(v.idx()) + " lies on the boundary");
  }
  loop_halfedges_.resize(k_);
  for (std::size_t i = 0; i < k_; ++i) {
    loop_halfedges_[i] = mesh_.find_halfedge(loop_[i], loop_[(i + 1) % k_]);
    if (!loop_halfedges_[i].is_valid())
      throw PreconditionError("surgery: loop vertices " + std::to_string(loop_[i].idx()) + " and " +
                              std::to_string(loop_[(i + 1) % k_].idx()) + " share no edge");
  }
}

// 1. Before any change: the interior outgoing halfedges of each left fan, and the left faces
//    (faces left of some h_i) with their halfedge cycles.
void Surgery::gather_left_side() {
  const auto& h = loop_halfedges_;
  fan_.assign(k_, {});
  for (std::size_t i = 0; i < k_; ++i) {
    const auto stop = mesh_.opposite_halfedge_handle(h[(i + k_ - 1) % k_]);
    auto o = mesh_.ccw_rotated_halfedge_handle(h[i]);
    std::size_t guard = 0;
    while (o != stop) {
      fan_[i].push_back(o);
      o = mesh_.ccw_rotated_halfedge_handle(o);
      if (++guard > 1000000) throw Error("surgery: corrupt vertex fan");
    }
  }
  for (std::size_t i = 0; i < k_; ++i) left_faces_.push_back(mesh_.face_handle(h[i]));
  for (std::size_t i = 0; i < k_; ++i)
    for (auto o : fan_[i]) left_faces_.push_back(mesh_.face_handle(o));
  std::sort(left_faces_.begin(), left_faces_.end());
  left_faces_.erase(std::unique(left_faces_.begin(), left_faces_.end()), left_faces_.end());
  face_cycle_.resize(left_faces_.size());
  for (std::size_t j = 0; j < left_faces_.size(); ++j) {
    auto a = mesh_.halfedge_handle(left_faces_[j]);
    face_cycle_[j] = {a, mesh_.next_halfedge_handle(a), mesh_.next_halfedge_handle(mesh_.next_halfedge_handle(a))};
  }
}

// What undo_surgery() restores: everything below only rewires the left fans and faces, the
// loop's halfedges and vertices, moves loop vertices and appends new elements.
void Surgery::record_undo() {
  SurgeryUndo& u = result_.undo;
  u.vertices = mesh_.n_vertices();
  u.edges = mesh_.n_edges();
  u.faces = mesh_.n_faces();
  for (std::size_t i = 0; i < k_; ++i) {
    for (auto o : fan_[i]) u.targets.push_back({mesh_.opposite_halfedge_handle(o), loop_[i]});
    u.vertex_halfedges.push_back({loop_[i], mesh_.halfedge_handle(loop_[i])});
    u.positions.push_back({loop_[i], mesh_.point(loop_[i])});
  }
  for (std::size_t j = 0; j < left_faces_.size(); ++j) u.face_cycles.push_back({left_faces_[j], face_cycle_[j]});
}

// 2. Left copies of the loop vertices and the new edges y_i: left^i -> left^(i+1) (x_i = opposite).
void Surgery::add_left_copies() {
  result_.right_ring = loop_;
  for (std::size_t i = 0; i < k_; ++i) {
    const Vec3 p = mesh_.point(loop_[i]);  // a copy: add_vertex may reallocate the point array
    result_.left_ring.push_back(mesh_.add_vertex(p));
  }
  new_halfedges_.resize(k_);
  new_opposites_.resize(k_);
  for (std::size_t i = 0; i < k_; ++i) {
    new_halfedges_[i] = mesh_.new_edge(result_.left_ring[i], result_.left_ring[(i + 1) % k_]);
    new_opposites_[i] = mesh_.opposite_halfedge_handle(new_halfedges_[i]);
    replaced_[loop_halfedges_[i].idx()] = new_halfedges_[i];
  }
}

// 3. The left fans now start at the left copies.
void Surgery::repoint_left_fans() {
  for (std::size_t i = 0; i < k_; ++i)
    for (auto o : fan_[i]) mesh_.set_vertex_handle(mesh_.opposite_halfedge_handle(o), result_.left_ring[i]);
}

// 4. Left faces with y_i in place of h_i.
void Surgery::relink_left_faces() {
  auto replace = [&](Mesh::HalfedgeHandle a) {
    auto it = replaced_.find(a.idx());
    return it == replaced_.end() ? a : it->second;
  };
  for (std::size_t j = 0; j < left_faces_.size(); ++j) {
    const auto& c = face_cycle_[j];
    for (int t = 0; t < 3; ++t) {
      mesh_.set_next_halfedge_handle(replace(c[t]), replace(c[(t + 1) % 3]));
      mesh_.set_face_handle(replace(c[t]), left_faces_[j]);
    }
    mesh_.set_halfedge_handle(left_faces_[j], replace(c[0]));
  }
}

// 5. Boundary rings: the right ring is h_0 -> h_1 -> ...; the left ring is x_i -> x_(i-1).
void Surgery::link_boundary_rings() {
  const auto& h = loop_halfedges_;
  const auto& x = new_opposites_;
  for (std::size_t i = 0; i < k_; ++i) {
    mesh_.set_face_handle(h[i], Mesh::FaceHandle());
    mesh_.set_face_handle(x[i], Mesh::FaceHandle());
  }
  for (std::size_t i = 0; i < k_; ++i) {
    mesh_.set_next_halfedge_handle(h[i], h[(i + 1) % k_]);
    mesh_.set_next_halfedge_handle(x[i], x[(i + k_ - 1) % k_]);
    mesh_.set_halfedge_handle(loop_[i], h[i]);
    mesh_.set_halfedge_handle(result_.left_ring[i], x[(i + k_ - 1) % k_]);
  }
}

// 6b. Classes of the left copies of the loop edges (needed by the caps): y_i copies h_i.
void Surgery::copy_loop_classes() {
  if (!homology_) return;
  for (std::size_t i = 0; i < k_; ++i) {
    const std::uint64_t* c = homology_->edge_class(mesh_.edge_handle(loop_halfedges_[i]));
    const std::vector<std::uint64_t> copy(c, c + words_);
    homology_->set_edge_class(mesh_.edge_handle(new_halfedges_[i]), copy.data());
  }
}

}  // namespace detail

SurgeryResult cut_and_cap(Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop, const SurgeryOptions& opts,
                          HomologyBasis* homology) {
  return detail::Surgery(mesh, loop, opts, homology).run();
}

void undo_surgery(Mesh& mesh, const SurgeryUndo& undo) {
  for (const auto& [h, v] : undo.targets) mesh.set_vertex_handle(h, v);
  for (const auto& [f, c] : undo.face_cycles) {
    for (int t = 0; t < 3; ++t) {
      mesh.set_next_halfedge_handle(c[t], c[(t + 1) % 3]);
      mesh.set_face_handle(c[t], f);
    }
    mesh.set_halfedge_handle(f, c[0]);
  }
  for (const auto& [v, h] : undo.vertex_halfedges) mesh.set_halfedge_handle(v, h);
  for (const auto& [v, p] : undo.positions) mesh.set_point(v, p);
  mesh.resize(undo.vertices, undo.edges, undo.faces);
}

namespace {

// Per-thread side marks by vertex id for vertices_connected(), stamped per call so that a call
// touches only the vertices it reaches (a hash map of them cost about 0.4 s of CPU over the 93
// cuts of the real CT surface, issue 26).
struct SideMarks {
  VertexStamps stamps;
  std::vector<std::uint8_t> sides;  // 0: reached from a, 1: from b (valid where stamped)

  void start(std::size_t vertices) {
    stamps.start(vertices);
    sides.resize(stamps.size(), 0);
  }
  int side(int v) const { return stamps.marked(v) ? sides[std::size_t(v)] : -1; }
  void mark(int v, int side) {
    stamps.mark(v);
    sides[std::size_t(v)] = static_cast<std::uint8_t>(side);
  }
};

}  // namespace

bool vertices_connected(const Mesh& mesh, Mesh::VertexHandle a, Mesh::VertexHandle b) {
  if (a == b) return true;
  thread_local SideMarks marks;
  marks.start(mesh.n_vertices());
  std::deque<Mesh::VertexHandle> qa{a}, qb{b};
  marks.mark(a.idx(), 0);
  marks.mark(b.idx(), 1);
  while (!qa.empty() && !qb.empty()) {
    const bool from_a = qa.size() <= qb.size();
    auto& q = from_a ? qa : qb;
    const int me = from_a ? 0 : 1;
    const std::size_t layer = q.size();
    for (std::size_t i = 0; i < layer; ++i) {
      const auto v = q.front();
      q.pop_front();
      for (auto w : mesh.vv_range(v)) {
        const int seen = marks.side(w.idx());
        if (seen < 0) {
          marks.mark(w.idx(), me);
          q.push_back(w);
        } else if (seen != me) {
          return true;
        }
      }
    }
  }
  return false;
}

}  // namespace cf
