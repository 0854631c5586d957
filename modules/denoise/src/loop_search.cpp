#include "colonflat/denoise/loop_search.h"

#include <algorithm>

namespace cf {

FundamentalCycleSearch::FundamentalCycleSearch(const Mesh& mesh, const HomologyBasis& homology,
                                               const Z2Span& cut_classes)
    : mesh_(mesh), hom_(homology), span_(cut_classes), W_(homology.words()) {
  tmp_.resize(W_);
}

void FundamentalCycleSearch::grow() {
  const std::size_t n = mesh_.n_vertices();
  // Boundary flags: vertices created by surgery are interior, so only new entries are computed.
  for (std::size_t v = blocked_.size(); v < n; ++v) blocked_.push_back(mesh_.is_boundary(Mesh::VertexHandle(static_cast<int>(v))));
  if (stamp_.size() >= n) return;
  const std::size_t cap = std::max(n, stamp_.size() * 5 / 4);
  stamp_.resize(cap, 0);
  settled_flag_.resize(cap, 0);
  dist_.resize(cap, 0);
  parent_.resize(cap, -1);
  slot_.resize(cap, -1);
  mark_.resize(cap, 0);
}

CycleCandidate FundamentalCycleSearch::run(Mesh::VertexHandle s, double limit, const Accept* accept, bool frontier) {
  grow();
  ++run_id_;
  if (run_id_ == 0) {  // wrapped: reset stamps
    std::fill(stamp_.begin(), stamp_.end(), 0);
    run_id_ = 1;
  }
  CycleCandidate best;
  best.source = s;
  settled_count_ = 0;
  acc_.clear();
  heap_.clear();
  const std::greater<Item> cmp;
  auto push = [&](double d, int v) {
    heap_.emplace_back(d, v);
    std::push_heap(heap_.begin(), heap_.end(), cmp);
  };
  auto touch = [&](int v, double d, int parent) {
    stamp_[v] = run_id_;
    settled_flag_[v] = 0;
    dist_[v] = d;
    parent_[v] = parent;
  };
  touch(s.idx(), 0.0, -1);
  push(0.0, s.idx());
  std::vector<Mesh::VertexHandle> loop;
  while (!heap_.empty()) {
    const auto [d, vi] = heap_.front();
    if (d > 0.5 * std::min(limit, best.value)) {
      best.truncated = true;
      if (!best.found && frontier) best.frontier_bound = frontier_bound();
      break;
    }
    std::pop_heap(heap_.begin(), heap_.end(), cmp);
    heap_.pop_back();
    if (settled_flag_[vi] || d > dist_[vi]) continue;
    settled_flag_[vi] = 1;
    ++settled_count_;
    const auto v = Mesh::VertexHandle(vi);
    // Class of path(s, v).
    slot_[vi] = static_cast<int>(acc_.size() / W_);
    acc_.resize(acc_.size() + W_, 0);
    if (parent_[vi] >= 0) {
      const auto ph = Mesh::HalfedgeHandle(parent_[vi]);
      const int pu = mesh_.from_vertex_handle(ph).idx();
      std::uint64_t* mine = &acc_[std::size_t(slot_[vi]) * W_];
      const std::uint64_t* theirs = &acc_[std::size_t(slot_[pu]) * W_];
      const std::uint64_t* e = hom_.edge_class(mesh_.edge_handle(ph));
      for (int i = 0; i < W_; ++i) mine[i] = theirs[i] ^ e[i];
    }
    const Vec3& pv = mesh_.point(v);
    const auto h0 = mesh_.halfedge_handle(v);
    auto h = h0;
    do {
      const auto w = mesh_.to_vertex_handle(h);
      const int wi = w.idx();
      const auto this_h = h;
      h = mesh_.cw_rotated_halfedge_handle(h);
      if (blocked_[wi]) continue;
      const double len = (mesh_.point(w) - pv).norm();
      if (stamp_[wi] == run_id_ && settled_flag_[wi]) {
        // Non-tree edge between two settled vertices: a fundamental cycle.
        if (parent_[vi] >= 0 && mesh_.edge_handle(Mesh::HalfedgeHandle(parent_[vi])) == mesh_.edge_handle(this_h)) continue;
        const double value = d + len + dist_[wi];
        if (value >= best.value || value > limit) continue;
        const std::uint64_t* a = &acc_[std::size_t(slot_[vi]) * W_];
        const std::uint64_t* b = &acc_[std::size_t(slot_[wi]) * W_];
        const std::uint64_t* e = hom_.edge_class(mesh_.edge_handle(this_h));
        bool zero = true;
        for (int i = 0; i < W_; ++i) {
          tmp_[i] = a[i] ^ b[i] ^ e[i];
          zero = zero && tmp_[i] == 0;
        }
        if (zero || span_.reduce(tmp_.data())) continue;
        CycleCandidate c = best;
        c.found = true;
        c.value = value;
        c.u = v;
        c.v = w;
        if (accept) {
          loop = extract(c);
          if (!(*accept)(loop)) continue;
        }
        best = c;
        continue;
      }
      const double nd = d + len;
      if (stamp_[wi] != run_id_) {
        touch(wi, nd, this_h.idx());
        push(nd, wi);
      } else if (nd < dist_[wi]) {
        dist_[wi] = nd;
        parent_[wi] = this_h.idx();
        push(nd, wi);
      }
    } while (h != h0);
  }
  return best;
}

double FundamentalCycleSearch::frontier_bound() {
  // Unsettled vertices with a tentative distance are in the heap (possibly several times).
  double bound = std::numeric_limits<double>::infinity();
  std::vector<std::uint64_t> cls(W_);
  for (const auto& [dw, wi] : heap_) {
    // Each unsettled vertex once: its current entry (stale duplicates carry a larger distance).
    if (settled_flag_[wi] || stamp_[wi] != run_id_ || parent_[wi] < 0 || dw != dist_[wi]) continue;
    const auto w = Mesh::VertexHandle(wi);
    const auto ph = Mesh::HalfedgeHandle(parent_[wi]);
    const int p = mesh_.from_vertex_handle(ph).idx();
    // Class of path(s, w) through its tentative parent.
    const std::uint64_t* ap = &acc_[std::size_t(slot_[p]) * W_];
    const std::uint64_t* ae = hom_.edge_class(mesh_.edge_handle(ph));
    for (auto h : mesh_.voh_range(w)) {
      const int u = mesh_.to_vertex_handle(h).idx();
      if (u == p || stamp_[u] != run_id_ || !settled_flag_[u]) continue;
      const double value = dist_[wi] + (mesh_.point(Mesh::VertexHandle(u)) - mesh_.point(w)).norm() + dist_[u];
      if (value >= bound) continue;
      const std::uint64_t* au = &acc_[std::size_t(slot_[u]) * W_];
      const std::uint64_t* eu = hom_.edge_class(mesh_.edge_handle(h));
      bool zero = true;
      for (int i = 0; i < W_; ++i) {
        cls[i] = ap[i] ^ ae[i] ^ au[i] ^ eu[i];
        zero = zero && cls[i] == 0;
      }
      if (!zero && !span_.reduce(cls.data())) bound = value;
    }
  }
  return bound;
}

std::vector<Mesh::VertexHandle> FundamentalCycleSearch::extract(const CycleCandidate& c) {
  ++mark_id_;
  if (mark_id_ == 0) {
    std::fill(mark_.begin(), mark_.end(), 0);
    mark_id_ = 1;
  }
  // Ancestors of u (u itself included).
  std::vector<Mesh::VertexHandle> up_u, up_v;
  for (int x = c.u.idx();;) {
    mark_[x] = mark_id_;
    up_u.push_back(Mesh::VertexHandle(x));
    if (parent_[x] < 0) break;
    x = mesh_.from_vertex_handle(Mesh::HalfedgeHandle(parent_[x])).idx();
  }
  int lca = c.v.idx();
  while (mark_[lca] != mark_id_) {
    up_v.push_back(Mesh::VertexHandle(lca));
    lca = mesh_.from_vertex_handle(Mesh::HalfedgeHandle(parent_[lca])).idx();
  }
  // Cycle: lca -> ... -> u, then v -> ... -> (child of lca on v's side).
  std::vector<Mesh::VertexHandle> loop;
  std::size_t i = 0;
  while (up_u[i].idx() != lca) ++i;
  for (std::size_t j = i + 1; j-- > 0;) loop.push_back(up_u[j]);
  for (auto x : up_v) loop.push_back(x);
  return loop;
}

std::vector<std::uint64_t> FundamentalCycleSearch::cycle_class(const std::vector<Mesh::VertexHandle>& loop) const {
  std::vector<std::uint64_t> c(W_, 0);
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const auto h = mesh_.find_halfedge(loop[i], loop[(i + 1) % loop.size()]);
    xor_into(c.data(), hom_.edge_class(mesh_.edge_handle(h)), W_);
  }
  return c;
}

double loop_length(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop) {
  double L = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) L += (mesh.point(loop[(i + 1) % loop.size()]) - mesh.point(loop[i])).norm();
  return L;
}

LoopType classify_loop(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop) {
  Vec3 c(0, 0, 0);
  for (auto v : loop) c += mesh.point(v);
  c /= double(loop.size());
  double s = 0;
  for (auto v : loop) {
    Vec3 n(0, 0, 0);
    for (auto f : mesh.vf_range(v)) {
      auto it = mesh.cfv_iter(f);
      const Vec3 a = mesh.point(*it), b = mesh.point(*++it), d = mesh.point(*++it);
      n += OpenMesh::cross(b - a, d - a);  // area-weighted face normal
    }
    s += OpenMesh::dot(n, mesh.point(v) - c);
  }
  return s > 0 ? LoopType::kHandle : LoopType::kTunnel;
}

const char* loop_type_name(LoopType t) { return t == LoopType::kHandle ? "handle" : "tunnel"; }

}  // namespace cf
