// The seed paper's method, as published (Algorithms 1-4), for comparison.
#include <algorithm>
#include <queue>
#include <unordered_map>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/loop_search.h"
#include "denoise_internal.h"

namespace cf::detail {
namespace {

// Algorithm 2: slice along the pruned cut graph into a disk (wedges = copies of vertices) and
// return the shortest path between two copies of one cut-graph vertex, as a loop of the mesh.
std::vector<Mesh::VertexHandle> paper_shortest_loop(const Mesh& mesh, const std::vector<std::uint8_t>& cut,
                                                    const std::vector<int>& cut_vertices, long long& dijkstras) {
  const std::size_t H = mesh.n_halfedges();
  std::vector<int> wedge_of(H, -1);  // per outgoing halfedge: the wedge of corner (from, face)
  std::vector<int> wedge_vertex;
  std::vector<std::uint8_t> is_cut_vertex(mesh.n_vertices(), 0);
  for (int v : cut_vertices) is_cut_vertex[v] = 1;
  std::unordered_map<int, std::vector<int>> copies;
  for (auto v : mesh.vertices()) {
    if (mesh.is_isolated(v)) continue;
    std::vector<Mesh::HalfedgeHandle> ring;
    const auto h0 = mesh.halfedge_handle(v);
    auto h = h0;
    do {
      ring.push_back(h);
      h = mesh.ccw_rotated_halfedge_handle(h);
    } while (h != h0);
    std::size_t start = 0;
    if (is_cut_vertex[v.idx()])
      for (std::size_t i = 0; i < ring.size(); ++i)
        if (cut[mesh.edge_handle(ring[i]).idx()]) {
          start = i;
          break;
        }
    int wid = -1;
    for (std::size_t t = 0; t < ring.size(); ++t) {
      const auto hh = ring[(start + t) % ring.size()];
      if (wid < 0 || (is_cut_vertex[v.idx()] && cut[mesh.edge_handle(hh).idx()])) {
        wid = static_cast<int>(wedge_vertex.size());
        wedge_vertex.push_back(v.idx());
        if (is_cut_vertex[v.idx()]) copies[v.idx()].push_back(wid);
      }
      wedge_of[hh.idx()] = wid;
    }
  }
  const std::size_t NW = wedge_vertex.size();
  // Graph of the disk: wedge(a, f) -- wedge(b, f) for every edge ab of every face f.
  std::vector<int> start(NW + 1, 0), adj;
  std::vector<double> w;
  for (auto f : mesh.faces())
    for (auto h : mesh.fh_range(f)) {
      ++start[wedge_of[h.idx()] + 1];
      ++start[wedge_of[mesh.next_halfedge_handle(h).idx()] + 1];
    }
  for (std::size_t i = 0; i < NW; ++i) start[i + 1] += start[i];
  adj.resize(start[NW]);
  w.resize(start[NW]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (auto f : mesh.faces())
    for (auto h : mesh.fh_range(f)) {
      const int a = wedge_of[h.idx()], b = wedge_of[mesh.next_halfedge_handle(h).idx()];
      const double len = mesh.calc_edge_length(h);
      adj[fill[a]] = b;
      w[fill[a]++] = len;
      adj[fill[b]] = a;
      w[fill[b]++] = len;
    }
  // Dijkstra from each copy; keep the globally shortest copy-to-copy path (early stop at it).
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> best_path;
  std::vector<double> dist(NW, std::numeric_limits<double>::infinity());
  std::vector<int> parent(NW, -1), touched;
  using Item = std::pair<double, int>;
  for (int v : cut_vertices) {
    const auto& cp = copies[v];
    for (std::size_t j = 0; j + 1 < cp.size(); ++j) {
      ++dijkstras;
      for (int t : touched) {
        dist[t] = std::numeric_limits<double>::infinity();
        parent[t] = -1;
      }
      touched.clear();
      std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
      dist[cp[j]] = 0;
      touched.push_back(cp[j]);
      q.push({0, cp[j]});
      while (!q.empty()) {
        auto [d, x] = q.top();
        q.pop();
        if (d >= best) break;
        if (d > dist[x]) continue;
        if (x != cp[j] && wedge_vertex[x] == v) {
          // Another copy of v: a loop. (Copies before j were sources already.)
          if (std::find(cp.begin() + j + 1, cp.end(), x) != cp.end()) {
            best = d;
            best_path.clear();
            for (int y = x; y >= 0; y = parent[y]) best_path.push_back(wedge_vertex[y]);
            break;
          }
          continue;
        }
        for (int i = start[x]; i < start[x + 1]; ++i) {
          const double nd = d + w[i];
          if (nd < dist[adj[i]]) {
            if (dist[adj[i]] == std::numeric_limits<double>::infinity()) touched.push_back(adj[i]);
            dist[adj[i]] = nd;
            parent[adj[i]] = x;
            q.push({nd, adj[i]});
          }
        }
      }
    }
  }
  if (best_path.empty()) return {};
  best_path.pop_back();  // the path starts and ends at v: keep one copy
  // In the mesh the loop may revisit a vertex (two copies of it); keep it simple by cutting out
  // the sub-loop between repeats (the part through the base vertex stays).
  std::vector<int> simple;
  std::unordered_map<int, std::size_t> pos;
  for (int x : best_path) {
    auto it = pos.find(x);
    if (it != pos.end()) {
      for (std::size_t k = it->second + 1; k < simple.size(); ++k) pos.erase(simple[k]);
      simple.resize(it->second + 1);
      continue;
    }
    pos[x] = simple.size();
    simple.push_back(x);
  }
  std::vector<Mesh::VertexHandle> loop;
  for (int x : simple) loop.push_back(Mesh::VertexHandle(x));
  return loop;
}

}  // namespace

std::string run_paper(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                      nlohmann::json& stats) {
  long long dijkstras = 0;
  int separating = 0;
  std::string reason = "g iterations done (Algorithm 4)";
  for (int it = 1; it <= needed; ++it) {
    Stopwatch sw;
    HomologyBasis hb;  // Algorithm 1: dual BFS spanning tree, cut graph, pruning
    hb.build(st.mesh);
    st.t.homology += sw.seconds();
    if (hb.pruned_cut_graph_vertices().empty()) {
      reason = "the cut graph is empty (genus 0 everywhere)";
      break;
    }
    sw.restart();
    const auto loop = paper_shortest_loop(st.mesh, hb.pruned_cut_graph_edges(), hb.pruned_cut_graph_vertices(), dijkstras);
    st.t.search += sw.seconds();
    if (loop.size() < 3) {
      reason = "Algorithm 2 found no loop";
      break;
    }
    LoopRecord& rec = st.record(loop, it, false);
    const std::size_t rec_index = st.loops.size() - 1;
    (void)rec;
    SurgeryResult sr;
    const bool connected = cut_loop(st, loop, o, nullptr, &sr);
    st.loops[rec_index].separating = !connected;
    if (!connected) ++separating;
    if (progress) progress(it, needed);
  }
  stats["dijkstra_runs"] = dijkstras;
  stats["separating_loops_cut"] = separating;
  return reason;
}

}  // namespace cf::detail
