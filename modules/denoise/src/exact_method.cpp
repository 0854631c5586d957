// The exact method: at every step the shortest non-separating edge cycle of the current mesh,
// found by bounded Dijkstra searches from a source set, with per-source lower bounds shared
// between nearby sources (docs/denoise.md, "How it is fast").
#include <algorithm>
#include <cmath>
#include <memory>
#include <queue>

#include "colonflat/core/error.h"
#include "colonflat/core/geodesic_ball.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/loop_search.h"
#include "denoise_internal.h"

namespace cf::detail {

void DenoiseState::extend_vertices(const std::vector<Mesh::VertexHandle>& copies_of,
                                   const std::vector<Mesh::VertexHandle>& copies, int comp) {
  origin.resize(mesh.n_vertices(), -1);
  component.resize(mesh.n_vertices(), comp);
  for (std::size_t i = 0; i < copies.size(); ++i) origin[copies[i].idx()] = origin[copies_of[i].idx()];
}

LoopRecord& DenoiseState::record(const std::vector<Mesh::VertexHandle>& loop, int iteration, bool separating) {
  LoopRecord r;
  r.id = static_cast<int>(loops.size());
  r.iteration = iteration;
  r.component = component[loop.front().idx()];
  for (auto v : loop) {
    r.vertex_ids.push_back(origin[v.idx()]);
    r.points.push_back(mesh.point(v));
  }
  r.length = loop_length(mesh, loop);
  describe_cross_section(&r);
  r.type = loop_type_name(classify_loop(mesh, loop));
  r.separating = separating;
  loops.push_back(std::move(r));
  return loops.back();
}

bool cut_loop(DenoiseState& st, const std::vector<Mesh::VertexHandle>& loop, const DenoiseOptions& o,
              HomologyBasis* hb, SurgeryResult* out) {
  const int comp = st.component[loop.front().idx()];
  Stopwatch sw;
  SurgeryOptions so;
  so.ring_pull = o.ring_pull;
  so.cap_rings = o.method == "paper" && o.ring_pull == 0 ? 1 : so.cap_rings;
  if (o.check_caps) {
    if (!st.guard) st.guard = std::make_unique<FaceGrid>(st.mesh, 2.0 * st.mean_edge);
    so.guard = st.guard.get();
  }
  *out = cut_and_cap(st.mesh, loop, so, hb);
  st.loops.back().cap_intersections = out->intersections;
  st.extend_vertices(out->right_ring, out->left_ring, comp);
  st.cap_rings.push_back(out->left_ring);
  st.cap_rings.push_back(out->right_ring);
  st.t.surgery += sw.seconds();
  sw.restart();
  const bool connected = vertices_connected(st.mesh, out->left_cap, out->right_cap);
  st.t.verify += sw.seconds();
  return connected;
}

namespace {

// What is known of one source's shortest fundamental cycle value F(s) (the minimum over the
// fundamental cycles of its shortest-path tree whose class is outside the cut span):
// F(s) == value when exact, F(s) >= value otherwise. `centre` is the source whose search gave
// it (-1: none, or lowered after a surgery).
struct SourceBound {
  double value = 0;
  bool exact = false;
  int centre = -1;
  std::uint32_t version = 0;
};

struct QueueEntry {
  double key;
  int vertex;
  std::uint32_t version;
  bool exact;
  // Min-heap order: smaller key first; at equal keys exact values before lower bounds.
  bool operator>(const QueueEntry& e) const { return key != e.key ? key > e.key : (!exact && e.exact); }
};

// The greedy loop of the exact method. Invariant: every source is in the queue with its current
// bound (or dropped with F = inf), and min over the queue of F(s) is the shortest non-separating
// cycle of the current mesh. Lower bounds spread from each search: a closed walk W through s
// gives one through any vertex t at distance d, of length |W| + 2d, so F(s) >= F(c) - 2 d(c, s)
// for every source s the search from c settled (F(c) > limit when it found nothing).
class ExactGreedy {
 public:
  ExactGreedy(DenoiseState& st, const DenoiseOptions& o, double mean_edge)
      : st_(st), opts_(o), first_radius_(o.initial_radius > 0 ? o.initial_radius : 10.0 * mean_edge) {
    want_type_ = o.policy != "shortest";
    wanted_ = o.policy == "cut" ? LoopType::kHandle : LoopType::kTunnel;
    accept_ = [this](const std::vector<Mesh::VertexHandle>& loop) { return classify_loop(st_.mesh, loop) == wanted_; };
  }
  std::string run(int needed, const DenoiseProgress& progress);
  void write_stats(nlohmann::json& stats) const;

 private:
  void build_homology();
  void maybe_rebuild(int cuts);
  void add_source(int v);
  void set_bound(int v, const SourceBound& b);
  double search_limit(int v);
  double best_exact_value();
  int farthest_pending(double best);
  CycleCandidate search_from(int v, double limit);
  void spread_bounds(int centre, double bound);
  bool stop_before(const QueueEntry& top, std::string* reason) const;
  void cut(const CycleCandidate& c, int iteration);
  void add_surgery_sources(const SurgeryResult& sr);
  void lower_bounds_near(const SurgeryResult& sr);

  DenoiseState& st_;
  const DenoiseOptions& opts_;
  const double first_radius_;  // mm: limit of a source's first search
  bool want_type_ = false;
  LoopType wanted_ = LoopType::kHandle;
  FundamentalCycleSearch::Accept accept_;
  HomologyBasis homology_;
  Z2Span span_;
  std::unique_ptr<FundamentalCycleSearch> search_;
  std::vector<std::uint8_t> is_source_;
  std::vector<int> sources_;
  std::vector<SourceBound> bound_;  // per vertex (sources only)
  std::vector<double> own_limit_;    // per vertex: limit of its last own search (the next one doubles it)
  std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>> queue_;
  std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>> exact_queue_;
  long long searches_ = 0, settled_ = 0, bounds_spread_ = 0, bounds_reset_ = 0;
  int builds_ = 0, cuts_at_build_ = 0, genus_at_build_ = 0;
  // Sources to certify against the best known loop, farthest from its source first.
  int far_anchor_ = -1;
  double far_value_ = 0;
  std::vector<std::pair<double, int>> far_order_;  // (distance from the anchor, source), a max-heap
  long long far_searches_ = 0;
  double build_time_ = 0, search_time_at_build_ = 0;
  double largest_limit_ = 0;
};

// Homology of the current mesh and its pruned cut graph as the source set (every
// non-separating cycle meets it). Bounds are kept: F(s) is the same quantity whatever the
// annotations (the shortest non-separating fundamental cycle of s's tree on the current mesh).
void ExactGreedy::build_homology() {
  Stopwatch sw;
  homology_.build(st_.mesh);
  span_.reset(homology_.words());
  search_ = std::make_unique<FundamentalCycleSearch>(st_.mesh, homology_, span_);
  for (int v : sources_) {
    is_source_[v] = 0;
    ++bound_[v].version;  // its queue entries are stale
  }
  sources_.clear();
  for (int v : homology_.pruned_cut_graph_vertices()) add_source(v);
  for (int v : sources_) {  // kept bounds back in the queue
    if (bound_[v].value > 0) set_bound(v, bound_[v]);
  }
  build_time_ = sw.seconds();
  st_.t.homology += build_time_;
  search_time_at_build_ = st_.t.search;
  ++builds_;
}

// A fresh cut graph of the lower-genus mesh is much smaller than the old one plus every ring,
// and searches start only from it; rebuilt once half the genus is gone, if searching has cost
// more than two builds since the last one.
void ExactGreedy::maybe_rebuild(int cuts) {
  const int genus_left = genus_at_build_ - (cuts - cuts_at_build_);
  if (genus_left < 1 || cuts - cuts_at_build_ < std::max(1, genus_at_build_ / 2)) return;
  if (st_.t.search - search_time_at_build_ < 2 * build_time_) return;
  build_homology();
  cuts_at_build_ = cuts;
  genus_at_build_ = genus_left;
}

void ExactGreedy::add_source(int v) {
  const std::size_t n = std::max<std::size_t>(st_.mesh.n_vertices(), v + 1);
  if (is_source_.size() < n) {
    is_source_.resize(n, 0);
    bound_.resize(n);
    own_limit_.resize(n, 0);
  }
  if (is_source_[v] || st_.mesh.is_boundary(Mesh::VertexHandle(v))) return;
  is_source_[v] = 1;
  sources_.push_back(v);
  if (bound_[v].value == 0) set_bound(v, SourceBound{});
}

void ExactGreedy::set_bound(int v, const SourceBound& b) {
  const std::uint32_t version = bound_[v].version + 1;
  bound_[v] = b;
  bound_[v].version = version;
  if (!std::isfinite(b.value)) return;  // no loop through this source's part of the mesh
  queue_.push({b.value, v, version, b.exact});
  if (b.exact) exact_queue_.push({b.value, v, version, true});
}

// The smallest exact value still queued (an upper bound of the shortest loop), or inf.
double ExactGreedy::best_exact_value() {
  while (!exact_queue_.empty()) {
    const QueueEntry& e = exact_queue_.top();
    if (e.version == bound_[e.vertex].version) return e.key;
    exact_queue_.pop();
  }
  return kInf;
}

// Limit of the next search from v (lower bound m): without a known loop, twice m (at least the
// first radius, at least twice its previous own limit); once a loop of value U is known, 2U:
// the search ends at the first loop found (value/2 from v), and when v has none up to 2U every
// source within U/2 of v gets a bound >= U, so one search covers a stretch of sources instead
// of each searching to U itself. Never above --max-loop-length.
double ExactGreedy::search_limit(int v) {
  const double m = bound_[v].value;
  double limit = std::max({first_radius_, 2.0 * m, 2.0 * own_limit_[v]});
  const double best = best_exact_value();
  if (std::isfinite(best) && best > m) limit = 2.0 * best;
  limit = std::max(limit, 1.05 * m);
  return std::min(limit, opts_.max_loop_length);
}

CycleCandidate ExactGreedy::search_from(int v, double limit) {
  Stopwatch sw;
  const CycleCandidate c = search_->run(Mesh::VertexHandle(v), limit, want_type_ ? &accept_ : nullptr);
  ++searches_;
  settled_ += static_cast<long long>(search_->last_settled());
  largest_limit_ = std::max(largest_limit_, limit);
  own_limit_[v] = limit;
  const double own = c.found ? c.value : c.truncated ? limit : kInf;
  set_bound(v, SourceBound{own, c.found, v, 0});
  if (!want_type_) spread_bounds(v, own);  // with a type filter F is no closed-walk minimum
  st_.t.search += sw.seconds();
  return c;
}

// While sources with a bound below the best known loop (value U, source u) remain, any order of
// searching them keeps the result exact. Farthest from u first: a source at distance D from the
// loop finds a walk of about U + 2D and then covers every source within D of it, so far sources
// certify the near ones, which could otherwise only search to U each. Returns -1 when the plain
// smallest-bound order should be used.
int ExactGreedy::farthest_pending(double best) {
  if (!std::isfinite(best)) return -1;
  const int anchor = exact_queue_.top().vertex;  // best_exact_value() left a valid top
  if (anchor != far_anchor_ || best != far_value_) {
    far_anchor_ = anchor;
    far_value_ = best;
    std::vector<double> dist;
    const std::vector<int> near = vertices_within(st_.mesh, {Mesh::VertexHandle(anchor)}, best, &dist);
    std::vector<double> from_anchor(st_.mesh.n_vertices(), kInf);
    for (std::size_t i = 0; i < near.size(); ++i) from_anchor[near[i]] = dist[i];
    far_order_.clear();
    for (int s : sources_)
      if (bound_[s].value < best && !bound_[s].exact) far_order_.push_back({from_anchor[s], s});
    std::make_heap(far_order_.begin(), far_order_.end());
  }
  while (!far_order_.empty()) {
    std::pop_heap(far_order_.begin(), far_order_.end());
    const int s = far_order_.back().second;
    far_order_.pop_back();
    if (!is_source_[s] || bound_[s].exact || !(bound_[s].value < best)) continue;  // done meanwhile
    ++far_searches_;
    return s;
  }
  return -1;
}

void ExactGreedy::spread_bounds(int centre, double bound) {
  for (int t : search_->last_settled_vertices()) {
    if (t == centre || t >= static_cast<int>(is_source_.size()) || !is_source_[t]) continue;
    const double lower = bound - 2.0 * search_->distance(t);
    const SourceBound& b = bound_[t];
    if (!(lower > b.value)) continue;  // also keeps dropped sources (inf) dropped
    set_bound(t, SourceBound{lower, false, centre, 0});
    ++bounds_spread_;
  }
}

bool ExactGreedy::stop_before(const QueueEntry& top, std::string* reason) const {
  const bool too_long = top.exact ? top.key > opts_.max_loop_length : top.key >= opts_.max_loop_length;
  if (too_long) *reason = "no loop shorter than --max-loop-length remains";
  return too_long;
}

std::string ExactGreedy::run(int needed, const DenoiseProgress& progress) {
  genus_at_build_ = needed;
  build_homology();
  int cuts = 0;
  while (cuts < needed) {
    if (queue_.empty())
      return want_type_ ? "no further " + std::string(opts_.policy == "cut" ? "handle" : "tunnel") + " loops found"
                        : "no further non-separating loops found";
    const QueueEntry top = queue_.top();
    queue_.pop();
    if (top.version != bound_[top.vertex].version) continue;
    std::string reason;
    if (stop_before(top, &reason)) return reason;
    if (!top.exact) {
      queue_.push(top);  // still pending; the order below does not change what is cut
      const int far = want_type_ ? -1 : farthest_pending(best_exact_value());
      const int v = far >= 0 ? far : top.vertex;
      search_from(v, search_limit(v));
      continue;
    }
    // Exact and the smallest key: the global minimum if the value still holds on the current
    // mesh (surgery elsewhere can only have raised it).
    const CycleCandidate c = search_from(top.vertex, top.key * (1 + 1e-12) + 1e-12);
    if (!c.found || c.value > top.key * (1 + 1e-12) + 1e-12) continue;  // re-queued with its new bound
    cut(c, ++cuts);
    if (progress) progress(cuts, needed);
    if (cuts < needed) maybe_rebuild(cuts);
  }
  return "target genus reached";
}

void ExactGreedy::cut(const CycleCandidate& c, int iteration) {
  set_bound(c.source.idx(), SourceBound{0, false, -1, 0});  // searched again after the surgery
  const std::vector<Mesh::VertexHandle> loop = search_->extract(c);
  const std::vector<std::uint64_t> cls = search_->cycle_class(loop);
  if (!span_.insert(cls.data())) throw Error("denoise: internal error: a chosen loop's class was already cut");
  const int comp = st_.component[loop.front().idx()];
  st_.record(loop, iteration, false);
  SurgeryResult sr;
  if (!cut_loop(st_, loop, opts_, &homology_, &sr))
    throw Error("denoise: surgery along loop " + std::to_string(iteration - 1) + " (length " +
                format_number(st_.loops.back().length) + " mm) split component " + std::to_string(comp) +
                " - the loop was separating; refusing to continue");
  --st_.genus_left[comp];
  Stopwatch sw;
  lower_bounds_near(sr);
  add_surgery_sources(sr);
  st_.t.search += sw.seconds();
}

// Every non-separating cycle of the new mesh meets the old sources or the new rings and caps.
void ExactGreedy::add_surgery_sources(const SurgeryResult& sr) {
  for (auto v : sr.left_ring) add_source(v.idx());
  for (auto v : sr.right_ring) add_source(v.idx());
  add_source(sr.left_cap.idx());
  add_source(sr.right_cap.idx());
}

// After a surgery: a closed walk through t shorter than twice t's distance to the new rings
// never reaches them, so it is a walk of the old mesh with the same class (only the span grew):
// F_new(t) >= min(F_old bound, 2 d(t, rings)). Bounds are lowered to that, nothing more; sources
// farther than half their bound from the rings keep it. (Bounds of inf are in genus-0
// components, where no surgery happens.)
void ExactGreedy::lower_bounds_near(const SurgeryResult& sr) {
  std::vector<Mesh::VertexHandle> seeds = sr.left_ring;
  seeds.insert(seeds.end(), sr.right_ring.begin(), sr.right_ring.end());
  double reach = 0;
  for (int s : sources_)
    if (std::isfinite(bound_[s].value)) reach = std::max(reach, 0.5 * bound_[s].value);
  std::vector<double> dist;
  const std::vector<int> near = vertices_within(st_.mesh, seeds, reach, &dist);
  for (std::size_t i = 0; i < near.size(); ++i) {
    const int t = near[i];
    if (t >= static_cast<int>(is_source_.size()) || !is_source_[t]) continue;
    const double cap = 2.0 * dist[i];
    if (!(cap < bound_[t].value)) continue;
    set_bound(t, SourceBound{cap, false, -1, 0});
    ++bounds_reset_;
  }
}

void ExactGreedy::write_stats(nlohmann::json& stats) const {
  stats["searches"] = searches_;
  stats["settled_vertices"] = settled_;
  stats["bounds_spread"] = bounds_spread_;
  stats["farthest_first_searches"] = far_searches_;
  stats["bounds_lowered_after_surgery"] = bounds_reset_;
  stats["homology_builds"] = builds_;
  stats["first_search_radius_mm"] = first_radius_;
  stats["largest_search_limit_mm"] = largest_limit_;
  stats["sources_last"] = sources_.size();
  stats["schedule"] = "per-source limits, bounds shared within each search ball";
}

}  // namespace

std::string run_exact(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                      double mean_edge, nlohmann::json& stats) {
  ExactGreedy greedy(st, o, mean_edge);
  const std::string reason = greedy.run(needed, progress);
  greedy.write_stats(stats);
  return reason;
}

}  // namespace cf::detail
