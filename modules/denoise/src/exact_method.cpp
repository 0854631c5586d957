#include <algorithm>
#include <memory>
#include <queue>
#include <thread>
#include <unordered_map>

#include "colonflat/core/error.h"
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
  r.type = loop_type_name(classify_loop(mesh, loop));
  r.separating = separating;
  loops.push_back(std::move(r));
  return loops.back();
}

std::vector<int> vertices_within(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& seeds, double radius,
                                 std::vector<double>* distances) {
  std::unordered_map<int, double> dist;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  for (auto s : seeds) {
    dist[s.idx()] = 0;
    q.push({0, s.idx()});
  }
  std::vector<int> out;
  while (!q.empty()) {
    auto [d, v] = q.top();
    q.pop();
    if (d > dist[v]) continue;
    out.push_back(v);
    if (distances) distances->push_back(d);
    const Vec3& p = mesh.point(Mesh::VertexHandle(v));
    for (auto w : mesh.vv_range(Mesh::VertexHandle(v))) {
      const double nd = d + (mesh.point(w) - p).norm();
      if (nd > radius) continue;
      auto it = dist.find(w.idx());
      if (it == dist.end() || nd < it->second) {
        dist[w.idx()] = nd;
        q.push({nd, w.idx()});
      }
    }
  }
  return out;
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

std::string run_exact(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                       double mean_edge, nlohmann::json& stats) {
  HomologyBasis hb;
  Z2Span span;
  std::unique_ptr<FundamentalCycleSearch> search;
  std::vector<std::uint8_t> is_source;
  std::vector<int> sources;
  const bool want_type = o.policy != "shortest";
  const LoopType wanted = o.policy == "cut" ? LoopType::kHandle : LoopType::kTunnel;
  FundamentalCycleSearch::Accept accept = [&](const std::vector<Mesh::VertexHandle>& loop) {
    return classify_loop(st.mesh, loop) == wanted;
  };
  const FundamentalCycleSearch::Accept* accept_ptr = want_type ? &accept : nullptr;

  struct Entry {
    double key;
    int v;
    std::uint32_t ver;
    bool exact;
    bool operator>(const Entry& e) const { return key > e.key; }
  };
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> pq;
  std::vector<std::uint32_t> ver;
  double R = o.initial_radius > 0 ? o.initial_radius : 10.0 * mean_edge;
  if (std::isfinite(o.max_loop_length)) R = std::min(R, o.max_loop_length);
  bool truncated_any = false;
  double next_radius_hint = kInf;  // min frontier bound seen since the last sweep
  double sweep_time = 0;
  int sweeps = 0;
  long long searches = 0, settled = 0;
  int rebuilds = 0, cuts_since_build = 0;

  auto add_source = [&](int v) {
    if (v >= static_cast<int>(is_source.size())) is_source.resize(st.mesh.n_vertices(), 0);
    if (is_source[v] || st.mesh.is_boundary(Mesh::VertexHandle(v))) return;
    is_source[v] = 1;
    sources.push_back(v);
  };
  auto rebuild = [&]() {
    Stopwatch sw;
    hb.build(st.mesh);
    span.reset(hb.words());
    search = std::make_unique<FundamentalCycleSearch>(st.mesh, hb, span);
    is_source.assign(st.mesh.n_vertices(), 0);
    sources.clear();
    for (int v : hb.pruned_cut_graph_vertices()) add_source(v);
    st.t.homology += sw.seconds();
    ++rebuilds;
    cuts_since_build = 0;
  };
  // Queues a source's search result: an exact value, or the lower bound R when the search hit the
  // radius (a source whose whole reachable part has no loop is dropped until a surgery nears it).
  auto queue_result = [&](int v, const CycleCandidate& c) {
    if (v >= static_cast<int>(ver.size())) ver.resize(st.mesh.n_vertices() + 1024, 0);
    ++ver[v];
    truncated_any = truncated_any || c.truncated;
    next_radius_hint = std::min(next_radius_hint, c.frontier_bound);
    if (c.found) pq.push({c.value, v, ver[v], true});
    else if (c.truncated) pq.push({R, v, ver[v], false});
  };
  auto compute = [&](int v) {
    Stopwatch sw;
    queue_result(v, search->run(Mesh::VertexHandle(v), R, accept_ptr));
    ++searches;
    settled += static_cast<long long>(search->last_settled());
    st.t.search += sw.seconds();
  };
  // Full sweeps over all sources run on every core: searches only read the mesh, the classes
  // and the span, and each thread has its own search state; results are queued in source order,
  // so the outcome does not depend on the thread count.
  const unsigned n_threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  auto compute_all = [&]() {
    Stopwatch sw;
    while (!pq.empty()) pq.pop();
    truncated_any = false;
    next_radius_hint = kInf;
    std::vector<CycleCandidate> results(sources.size());
    std::vector<long long> settled_by(n_threads, 0);
    auto work = [&](unsigned t) {
      FundamentalCycleSearch local(st.mesh, hb, span);
      for (std::size_t i = t; i < sources.size(); i += n_threads) {
        results[i] = local.run(Mesh::VertexHandle(sources[i]), R, accept_ptr, /*frontier=*/true);
        settled_by[t] += static_cast<long long>(local.last_settled());
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < n_threads; ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& th : pool) th.join();
    for (std::size_t i = 0; i < sources.size(); ++i) queue_result(sources[i], results[i]);
    searches += static_cast<long long>(sources.size());
    for (long long x : settled_by) settled += x;
    sweep_time += sw.seconds();
    ++sweeps;
    st.t.search += sw.seconds();
  };

  rebuild();
  compute_all();
  int cuts = 0;
  std::string reason = "target genus reached";
  while (cuts < needed) {
    if (pq.empty()) {
      reason = want_type ? "no further " + std::string(o.policy == "cut" ? "handle" : "tunnel") + " loops found"
                         : "no further non-separating loops found";
      break;
    }
    const Entry top = pq.top();
    pq.pop();
    if (top.ver != ver[top.v]) continue;
    if (!top.exact) {
      // Every remaining loop is longer than R.
      if (R >= o.max_loop_length) {
        reason = "no loop shorter than --max-loop-length remains";
        break;
      }
      if (!truncated_any) {
        reason = "no further loops found";
        break;
      }
      // Next radius: the shortest non-separating closed walk seen across search frontiers
      // bounds the next loop from above, so searching to it finds that loop; never less than
      // 1.05 R nor more than 2 R.
      R = std::min({2 * R, std::max(1.05 * R, next_radius_hint * (1 + 1e-9)), o.max_loop_length});
      if (cuts_since_build > 0) rebuild();
      compute_all();
      continue;
    }
    if (top.key > o.max_loop_length) {
      reason = "no loop shorter than --max-loop-length remains";
      break;
    }
    // Re-run from the source on the current mesh: the entry is the global minimum if it is
    // still exact (all other keys are lower bounds of their sources' current values).
    Stopwatch sw;
    const CycleCandidate c = search->run(Mesh::VertexHandle(top.v), R, accept_ptr);
    ++searches;
    st.t.search += sw.seconds();
    if (!c.found || c.value > top.key + 1e-12 * (1.0 + top.key)) {
      queue_result(top.v, c);  // changed since it was queued: back in line with its new value
      continue;
    }
    ++ver[top.v];  // consumed by this cut
    const std::vector<Mesh::VertexHandle> loop = search->extract(c);
    const std::vector<std::uint64_t> cls = search->cycle_class(loop);
    if (!span.insert(cls.data())) throw Error("denoise: internal error: a chosen loop's class was already cut");
    const int comp = st.component[loop.front().idx()];
    st.record(loop, cuts + 1, false);
    SurgeryResult sr;
    if (!cut_loop(st, loop, o, &hb, &sr))
      throw Error("denoise: surgery along loop " + std::to_string(cuts) + " (length " +
                  format_number(st.loops.back().length) + " mm) split component " + std::to_string(comp) +
                  " - the loop was separating; refusing to continue");
    --st.genus_left[comp];
    ++cuts;
    ++cuts_since_build;
    if (progress) progress(cuts, needed);
    // New sources: every non-separating cycle of the new mesh meets the old sources or the new
    // rings/caps. Sources whose search ball reached the surgery are recomputed now.
    std::vector<Mesh::VertexHandle> seeds = sr.left_ring;
    seeds.insert(seeds.end(), sr.right_ring.begin(), sr.right_ring.end());
    seeds.push_back(sr.left_cap);
    seeds.push_back(sr.right_cap);
    for (auto v : seeds) add_source(v.idx());
    double slack = 0;
    for (auto v : seeds)
      for (auto w : st.mesh.vv_range(v)) slack = std::max(slack, (st.mesh.point(w) - st.mesh.point(v)).norm());
    for (int v : vertices_within(st.mesh, seeds, 0.5 * R + 2 * slack))
      if (v < static_cast<int>(is_source.size()) && is_source[v]) compute(v);
  }
  stats["searches"] = searches;
  stats["sweeps"] = sweeps;
  stats["sweep_time_s"] = sweep_time;
  stats["threads"] = n_threads;
  stats["settled_vertices"] = settled;
  stats["homology_rebuilds"] = rebuilds;
  stats["final_search_radius_mm"] = R;
  stats["radius_schedule"] = "frontier bound, 1.05x..2x";
  stats["sources_last"] = sources.size();
  return reason;
}

}  // namespace cf::detail
