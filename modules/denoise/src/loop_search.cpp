#include "colonflat/denoise/loop_search.h"

#include <algorithm>

#include "colonflat/core/huge_pages.h"

namespace cf {

FundamentalCycleSearch::FundamentalCycleSearch(const Mesh& mesh, const HomologyBasis& homology,
                                               const Z2Span& cut_classes)
    : mesh_(mesh), hom_(homology), span_(cut_classes), W_(homology.words()) {
  tmp_.resize(W_);
}

void FundamentalCycleSearch::grow() {
  const std::size_t n = mesh_.n_vertices();
  if (node_.size() < n) {
    // Room for what surgery adds (as the mesh copy reserves), then 25 % more at a time.
    const std::size_t cap = node_.empty() ? n + n / 16 + 4096 : std::max(n, node_.size() * 5 / 4);
    resize_huge(node_, cap);
    mark_.resize(cap, 0);
  }
  // Boundary flags: vertices created by surgery are interior, so only new entries are computed.
  for (; blocked_known_ < n; ++blocked_known_)
    node_[blocked_known_].blocked = mesh_.is_boundary(Mesh::VertexHandle(static_cast<int>(blocked_known_)));
}

void FundamentalCycleSearch::reset_run() {
  grow();
  ++run_id_;
  if (run_id_ == 0) {  // wrapped: reset stamps
    for (Node& node : node_) node.stamp = 0;
    run_id_ = 1;
  }
  settled_count_ = 0;
  settled_order_.clear();
  acc_.assign(W_, 0);  // row 0: the zero class, shared by every path whose class is zero
  heap_.clear();
}

void FundamentalCycleSearch::start(Mesh::VertexHandle s) {
  reset_run();
  relax(s.idx(), 0.0, -1, -1);
}

// Every root at distance 0 with its tree parent, so that expanding one never re-parents another.
void FundamentalCycleSearch::start_roots(const std::vector<int>& roots, const std::vector<int>& root_parent) {
  reset_run();
  for (std::size_t i = 0; i < roots.size(); ++i) {
    Node& node = node_[roots[i]];
    node.stamp = run_id_;
    node.settled = 0;
    copy_list(node, roots[i]);
    node.dist = 0.0;
    node.parent = root_parent[i];
    node.from = root_parent[i] < 0 ? -1 : mesh_.from_vertex_handle(Mesh::HalfedgeHandle(root_parent[i])).idx();
  }
}

void FundamentalCycleSearch::copy_list(Node& node, int v) const {
  if (!adj_) return;
  const auto [first, last] = adj_->span(v);
  node.first = first;
  node.count = last - first < kLongList ? static_cast<std::uint16_t>(last - first) : kLongList;
}

// A hint only: vi's list (its first and last entry) is fetched while the heap pops.
void FundamentalCycleSearch::prefetch_list(int vi) const {
  if (!adj_) return;
  const Node& node = node_[vi];
  const VertexAdjacency::Out* first = adj_->entries() + node.first;
  __builtin_prefetch(first);
  if (node.count > 1 && node.count != kLongList) __builtin_prefetch(first + node.count - 1);
}

// Tentative distance d for w through parent halfedge `parent` (-1 at the source) from vertex `from`.
void FundamentalCycleSearch::relax(int w, double d, int parent, int from) {
  Node& node = node_[w];
  if (node.stamp != run_id_) {
    node.stamp = run_id_;
    node.settled = 0;
    copy_list(node, w);
  } else if (!(d < node.dist)) {
    return;
  }
  node.dist = d;
  node.parent = parent;
  node.from = from;
  heap_.push(d, w);
}

// Marks v settled and stores the class of path(s, v) (the parent's XOR the tree edge's).
void FundamentalCycleSearch::settle(int v) {
  Node& node = node_[v];
  node.settled = 1;
  ++settled_count_;
  settled_order_.push_back(v);
  node.slot = 0;
  if (node.parent < 0) return;
  const auto ph = Mesh::HalfedgeHandle(node.parent);
  const int pu = node.from;
  if (node_[pu].slot == 0 && edge_zero(mesh_.edge_handle(ph))) return;  // most paths: no vector work
  node.slot = static_cast<int>(acc_.size() / W_);
  acc_.resize(acc_.size() + W_, 0);
  std::uint64_t* mine = &acc_[std::size_t(node.slot) * W_];
  const std::uint64_t* theirs = &acc_[std::size_t(node_[pu].slot) * W_];
  const std::uint64_t* e = edge_bits(mesh_.edge_handle(ph));
  for (int i = 0; i < W_; ++i) mine[i] = theirs[i] ^ e[i];
}

// The fundamental cycle of the non-tree edge h (v -> w, both settled): kept in `best` when it is
// shorter, within the limit, outside the span and accepted.
void FundamentalCycleSearch::try_cycle(int vi, int wi, int hi, double value, double limit, const Accept* accept,
                                       CycleCandidate& best) {
  if (value >= best.value || value > limit) return;
  const auto h = Mesh::HalfedgeHandle(hi);  // vi -> wi
  if (node_[vi].slot == 0 && node_[wi].slot == 0 && edge_zero(mesh_.edge_handle(h))) return;  // class zero
  const std::uint64_t* a = &acc_[std::size_t(node_[vi].slot) * W_];
  const std::uint64_t* b = &acc_[std::size_t(node_[wi].slot) * W_];
  const std::uint64_t* e = edge_bits(mesh_.edge_handle(h));
  for (int i = 0; i < W_; ++i) tmp_[i] = a[i] ^ b[i] ^ e[i];
  if (!wanted(tmp_.data())) return;
  CycleCandidate c = best;
  c.found = true;
  c.value = value;
  c.u = Mesh::VertexHandle(vi);
  c.v = Mesh::VertexHandle(wi);
  if (accept && !(*accept)(extract(c))) return;
  best = c;
}

void FundamentalCycleSearch::set_cochain(const std::vector<std::uint8_t>* cochain) {
  cochain_ = cochain;
  W_ = cochain_ ? 1 : hom_.words();
  tmp_.assign(W_, 0);
}

bool FundamentalCycleSearch::wanted(std::uint64_t* cls) const {
  if (cochain_) return (cls[0] & 1) != 0;
  return !is_zero(cls, W_) && !span_.reduce(cls);
}

CycleCandidate FundamentalCycleSearch::run(Mesh::VertexHandle s, double limit, const Accept* accept, bool frontier) {
  start(s);
  CycleCandidate best;
  best.source = s;
  drain(limit, accept, frontier, best);
  return best;
}

CycleCandidate FundamentalCycleSearch::run_group(const std::vector<int>& roots, const std::vector<int>& root_parent,
                                                 double limit) {
  start_roots(roots, root_parent);
  CycleCandidate best;
  best.source = Mesh::VertexHandle(roots.front());
  for (int r : roots) {  // parents first: each root's class is its parent's XOR the tree edge's
    settle(r);
    expand(r, 0.0, limit, nullptr, best);
  }
  drain(limit, nullptr, false, best);
  return best;
}

// Dijkstra until the queue is empty or the nearest unsettled vertex is beyond half the limit or
// half the best cycle found.
void FundamentalCycleSearch::drain(double limit, const Accept* accept, bool frontier, CycleCandidate& best) {
  while (!heap_.empty()) {
    const auto [d, vi] = heap_.top();
    if (d > 0.5 * std::min(limit, best.value)) {
      best.truncated = true;
      if (!best.found && frontier) best.frontier_bound = frontier_bound();
      break;
    }
    prefetch_list(vi);
    heap_.pop();
    if (!heap_.empty()) prefetch_list(heap_.top().second);  // most often the next one settled
    if (node_[vi].settled || d > node_[vi].dist) continue;
    settle(vi);
    expand(vi, d, limit, accept, best);
  }
}

// The neighbours of vi in voh_range() order: from the compact adjacency when there is one, from
// the halfedges otherwise (the same ids, order and lengths).
template <class Visit>
void FundamentalCycleSearch::for_each_out(int vi, Visit&& visit) const {
  if (adj_) {
    const Node& node = node_[vi];
    const VertexAdjacency::Range r = node.count == kLongList ? adj_->out(vi)
        : VertexAdjacency::Range{adj_->entries() + node.first, adj_->entries() + node.first + node.count};
    for (const VertexAdjacency::Out& o : r) visit(o.to, o.halfedge, o.length);
    return;
  }
  const auto v = Mesh::VertexHandle(vi);
  const Vec3& pv = mesh_.point(v);
  for (auto h : mesh_.voh_range(v)) {
    const auto w = mesh_.to_vertex_handle(h);
    visit(w.idx(), h.idx(), (mesh_.point(w) - pv).norm());
  }
}

// The edges out of the settled vertex vi (distance d): non-tree edges to settled vertices close
// fundamental cycles, the others relax their end.
void FundamentalCycleSearch::expand(int vi, double d, double limit, const Accept* accept, CycleCandidate& best) {
  const int parent = node_[vi].parent;
  const int parent_edge = parent >= 0 ? mesh_.edge_handle(Mesh::HalfedgeHandle(parent)).idx() : -1;
  for_each_out(vi, [&](int wi, int h, double len) {
    const Node& w = node_[wi];
    if (w.blocked || (avoid_ && wi < static_cast<int>(avoid_->size()) && (*avoid_)[wi])) return;
    if (w.stamp == run_id_ && w.settled) {  // non-tree edge between settled vertices
      if (mesh_.edge_handle(Mesh::HalfedgeHandle(h)).idx() != parent_edge)
        try_cycle(vi, wi, h, d + len + w.dist, limit, accept, best);
      return;
    }
    relax(wi, d + len, h, vi);
  });
}

double FundamentalCycleSearch::frontier_bound() {
  // Unsettled vertices with a tentative distance are in the heap (possibly several times).
  double bound = std::numeric_limits<double>::infinity();
  std::vector<std::uint64_t> cls(W_);
  for (const auto& [dw, wi] : heap_.items()) {
    // Each unsettled vertex once: its current entry (stale duplicates carry a larger distance).
    const Node& node = node_[wi];
    if (node.settled || node.stamp != run_id_ || node.parent < 0 || dw != node.dist) continue;
    const auto w = Mesh::VertexHandle(wi);
    const auto ph = Mesh::HalfedgeHandle(node.parent);
    const int p = node.from;
    // Class of path(s, w) through its tentative parent.
    const std::uint64_t* ap = &acc_[std::size_t(node_[p].slot) * W_];
    const std::uint64_t* ae = edge_bits(mesh_.edge_handle(ph));
    for (auto h : mesh_.voh_range(w)) {
      const int u = mesh_.to_vertex_handle(h).idx();
      if (u == p || !settled(u)) continue;
      const double value = node.dist + (mesh_.point(Mesh::VertexHandle(u)) - mesh_.point(w)).norm() + node_[u].dist;
      if (value >= bound) continue;
      const std::uint64_t* au = &acc_[std::size_t(node_[u].slot) * W_];
      const std::uint64_t* eu = edge_bits(mesh_.edge_handle(h));
      for (int i = 0; i < W_; ++i) cls[i] = ap[i] ^ ae[i] ^ au[i] ^ eu[i];
      if (wanted(cls.data())) bound = value;
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
    if (node_[x].parent < 0) break;
    x = node_[x].from;
  }
  int lca = c.v.idx();
  while (mark_[lca] != mark_id_) {
    up_v.push_back(Mesh::VertexHandle(lca));
    lca = node_[lca].from;
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
  std::vector<std::uint64_t> c(hom_.words(), 0);
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const auto h = mesh_.find_halfedge(loop[i], loop[(i + 1) % loop.size()]);
    xor_into(c.data(), hom_.edge_class(mesh_.edge_handle(h)), hom_.words());
  }
  return c;
}

std::vector<std::uint8_t> crossing_cochain(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop,
                                           bool closed) {
  std::vector<std::uint8_t> bits(mesh.n_edges(), 0);
  const std::size_t k = loop.size();
  for (std::size_t i = closed ? 0 : 1; i + (closed ? 0 : 1) < k; ++i) {
    const auto out = mesh.find_halfedge(loop[i], loop[(i + 1) % k]);
    const auto back = mesh.find_halfedge(loop[i], loop[(i + k - 1) % k]);
    for (auto h = mesh.ccw_rotated_halfedge_handle(out); h != back; h = mesh.ccw_rotated_halfedge_handle(h))
      bits[mesh.edge_handle(h).idx()] ^= 1;
  }
  return bits;
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
