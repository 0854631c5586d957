// The seed paper's method, as published (Algorithms 1-4), for comparison.
#include <algorithm>
#include <limits>
#include <queue>
#include <unordered_map>

#include "colonflat/core/bucket_slots.h"
#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/loop_search.h"
#include "denoise_internal.h"

namespace cf::detail {
namespace {

// Algorithm 2's disk: the mesh sliced along the pruned cut graph. Its vertices are wedges
// (copies of mesh vertices: one per side of the cut at a cut-graph vertex, else one).
struct SlicedDisk {
  std::vector<int> wedge_of;      // per outgoing halfedge: the wedge of corner (from, face)
  std::vector<int> wedge_vertex;  // wedge -> mesh vertex
  std::unordered_map<int, std::vector<int>> copies;  // cut-graph vertex -> its wedges
  std::vector<int> start, adj;    // CSR adjacency of the disk's graph
  std::vector<double> weight;

  void build_wedges(const Mesh& mesh, const std::vector<std::uint8_t>& cut, const std::vector<int>& cut_vertices);
  void build_graph(const Mesh& mesh);
  std::vector<int> shortest_copy_path(const std::vector<int>& cut_vertices, long long& dijkstras) const;
};

void SlicedDisk::build_wedges(const Mesh& mesh, const std::vector<std::uint8_t>& cut, const std::vector<int>& cut_vertices) {
  wedge_of.assign(mesh.n_halfedges(), -1);
  std::vector<std::uint8_t> is_cut_vertex(mesh.n_vertices(), 0);
  for (int v : cut_vertices) is_cut_vertex[v] = 1;
  for (auto v : mesh.vertices()) {
    if (mesh.is_isolated(v)) continue;
    std::vector<Mesh::HalfedgeHandle> ring;
    const auto h0 = mesh.halfedge_handle(v);
    auto h = h0;
    do {
      ring.push_back(h);
      h = mesh.ccw_rotated_halfedge_handle(h);
    } while (h != h0);
    const bool on_cut = is_cut_vertex[v.idx()];
    std::size_t first = 0;
    if (on_cut)
      for (std::size_t i = 0; i < ring.size(); ++i)
        if (cut[mesh.edge_handle(ring[i]).idx()]) {
          first = i;
          break;
        }
    int wid = -1;
    for (std::size_t t = 0; t < ring.size(); ++t) {
      const auto hh = ring[(first + t) % ring.size()];
      if (wid < 0 || (on_cut && cut[mesh.edge_handle(hh).idx()])) {
        wid = static_cast<int>(wedge_vertex.size());
        wedge_vertex.push_back(v.idx());
        if (on_cut) copies[v.idx()].push_back(wid);
      }
      wedge_of[hh.idx()] = wid;
    }
  }
}

// Graph of the disk: wedge(a, f) -- wedge(b, f) for every edge ab of every face f.
void SlicedDisk::build_graph(const Mesh& mesh) {
  const std::size_t n = wedge_vertex.size();
  BucketSlots<int> slots(n);
  for (auto f : mesh.faces())
    for (auto h : mesh.fh_range(f)) {
      slots.count(std::size_t(wedge_of[h.idx()]));
      slots.count(std::size_t(wedge_of[mesh.next_halfedge_handle(h).idx()]));
    }
  slots.close();
  adj.resize(std::size_t(slots.total()));
  weight.resize(std::size_t(slots.total()));
  for (auto f : mesh.faces())
    for (auto h : mesh.fh_range(f)) {
      const int a = wedge_of[h.idx()], b = wedge_of[mesh.next_halfedge_handle(h).idx()];
      const double len = mesh.calc_edge_length(h);
      const auto i = std::size_t(slots.place(std::size_t(a))), j = std::size_t(slots.place(std::size_t(b)));
      adj[i] = b, weight[i] = len;
      adj[j] = a, weight[j] = len;
    }
  start = std::move(slots).take_starts();
}

// Dijkstra from each copy; the globally shortest copy-to-copy path (early stop at it), as mesh
// vertices from the far copy back to the source copy.
std::vector<int> SlicedDisk::shortest_copy_path(const std::vector<int>& cut_vertices, long long& dijkstras) const {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double best = kInfinity;
  std::vector<int> best_path;
  std::vector<double> dist(wedge_vertex.size(), kInfinity);
  std::vector<int> parent(wedge_vertex.size(), -1), touched;
  using Item = std::pair<double, int>;
  for (int v : cut_vertices) {
    const auto found = copies.find(v);
    if (found == copies.end()) continue;
    const auto& cp = found->second;
    for (std::size_t j = 0; j + 1 < cp.size(); ++j) {
      ++dijkstras;
      for (int t : touched) {
        dist[t] = kInfinity;
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
          const double nd = d + weight[i];
          if (nd < dist[adj[i]]) {
            if (dist[adj[i]] == kInfinity) touched.push_back(adj[i]);
            dist[adj[i]] = nd;
            parent[adj[i]] = x;
            q.push({nd, adj[i]});
          }
        }
      }
    }
  }
  return best_path;
}

// In the mesh the path may revisit a vertex (two copies of it); keep it simple by cutting out
// the sub-loop between repeats (the part through the base vertex stays).
std::vector<Mesh::VertexHandle> simple_loop(std::vector<int> path) {
  path.pop_back();  // the path starts and ends at v: keep one copy
  std::vector<int> simple;
  std::unordered_map<int, std::size_t> pos;
  for (int x : path) {
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

// Algorithm 2: slice along the pruned cut graph into a disk and return the shortest path
// between two copies of one cut-graph vertex, as a loop of the mesh.
std::vector<Mesh::VertexHandle> paper_shortest_loop(const Mesh& mesh, const std::vector<std::uint8_t>& cut,
                                                    const std::vector<int>& cut_vertices, long long& dijkstras) {
  SlicedDisk disk;
  disk.build_wedges(mesh, cut, cut_vertices);
  disk.build_graph(mesh);
  const std::vector<int> path = disk.shortest_copy_path(cut_vertices, dijkstras);
  if (path.empty()) return {};
  return simple_loop(path);
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
