// The nested dissection order split at one top-level METIS vertex separator, its two sides ordered
// by METIS_NodeND side by side, and the per-thread rand() that makes that deterministic
// (see metis_order.h).
#include "metis_order.h"

#include "spd_solver.h"

#include "colonflat/core/bucket_slots.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "factor_schedule.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>

#if defined(COLONFLAT_HAVE_METIS) && defined(COLONFLAT_HAVE_CHOLMOD)
#include <cholmod.h>
#include <metis.h>
#endif

namespace cf::flat_detail {
namespace {

// glibc's rand() state, one per thread: TYPE_3 (additive feedback, 31 words) in a 128-byte state,
// seeded 1 until srand() - what glibc's own rand()/srand() compute on their one process-wide state
// (rand() is random()), so a single METIS call draws exactly the numbers it drew before.
struct ThreadRand {
  random_data data;
  char state[128];
  std::uint64_t calls = 0;
  ThreadRand() {
    std::memset(&data, 0, sizeof data);  // initstate_r reads data.state before setting it
    initstate_r(1, state, sizeof state, &data);
  }
};

ThreadRand& thread_rand() {
  thread_local ThreadRand r;
  return r;
}

}  // namespace

std::uint64_t metis_rand_calls() { return thread_rand().calls; }

// Each corner's two neighbours bucketed by vertex (a counting sort), each bucket sorted and its
// duplicates (an edge's second face) dropped in place.
VertexGraph vertex_graph(const std::vector<std::array<int, 3>>& t, int nv) {
  BucketSlots<int> slots{std::size_t(nv)};
  for (const auto& tri : t)
    for (int v : tri) slots.count(std::size_t(v), 2);
  slots.close();
  std::vector<int> nbr(std::size_t(slots.total()));
  for (const auto& tri : t)
    for (int k = 0; k < 3; ++k) {
      const auto v = std::size_t(tri[std::size_t(k)]);
      nbr[std::size_t(slots.place(v))] = tri[std::size_t((k + 1) % 3)];
      nbr[std::size_t(slots.place(v))] = tri[std::size_t((k + 2) % 3)];
    }
  const std::vector<int>& start = slots.starts();
  VertexGraph g;
  g.xadj.reserve(std::size_t(nv) + 1);
  g.adjncy.reserve(nbr.size() / 2 + 1);
  for (int v = 0; v < nv; ++v) {
    const auto first = nbr.begin() + start[std::size_t(v)], last = nbr.begin() + start[std::size_t(v) + 1];
    std::sort(first, last);
    g.adjncy.insert(g.adjncy.end(), first, std::unique(first, last));
    g.xadj.push_back(int(g.adjncy.size()));
  }
  return g;
}

}  // namespace cf::flat_detail

#if defined(COLONFLAT_HAVE_METIS) && defined(COLONFLAT_HAVE_CHOLMOD)

// libmetis 5.1 calls the C library's rand()/srand() (nm -D libmetis.so.5: U rand, U srand). These
// definitions in the executable take precedence over glibc's for every shared library of the process,
// so that two METIS calls on two threads each draw from their own thread's state: each order is the
// order it is alone, whatever runs beside it (the tests count the calls that arrive here).
extern "C" int rand() noexcept {
  auto& r = cf::flat_detail::thread_rand();
  std::int32_t out = 0;
  random_r(&r.data, &out);
  ++r.calls;
  return int(out);
}

extern "C" void srand(unsigned seed) noexcept { srandom_r(seed, &cf::flat_detail::thread_rand().data); }

namespace cf::flat_detail {
namespace {

// A graph in METIS's CSR form (each adjacency list ascending, no self loop).
static_assert(sizeof(idx_t) == sizeof(int), "METIS built with 32-bit idx_t");
using Graph = VertexGraph;

// The adjacency graph of A (both triangles, no diagonal), as cholmod_copy builds it for cholmod_metis.
Graph graph_of(const MetisSpMat& A) {
  const Eigen::Index n = A.cols();
  Graph g;
  g.xadj.assign(std::size_t(n) + 1, 0);
  for (Eigen::Index j = 0; j < n; ++j)
    for (MetisSpMat::InnerIterator it(A, j); it; ++it)
      if (it.row() > j) ++g.xadj[std::size_t(j) + 1], ++g.xadj[std::size_t(it.row()) + 1];
  for (Eigen::Index j = 0; j < n; ++j) g.xadj[std::size_t(j) + 1] += g.xadj[std::size_t(j)];
  g.adjncy.resize(std::size_t(g.xadj[std::size_t(n)]));
  std::vector<idx_t> next(g.xadj.begin(), g.xadj.end() - 1);
  for (Eigen::Index j = 0; j < n; ++j)
    for (MetisSpMat::InnerIterator it(A, j); it; ++it)
      if (it.row() > j) {
        g.adjncy[std::size_t(next[std::size_t(j)]++)] = idx_t(it.row());
        g.adjncy[std::size_t(next[std::size_t(it.row())]++)] = idx_t(j);
      }
  return g;
}

// METIS's default options, 0-based numbering.
void default_options(idx_t (&options)[METIS_NOPTIONS]) {
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
}

// part[v] in {0, 1, 2} (2: the separator) by METIS_ComputeVertexSeparator; empty on failure.
std::vector<idx_t> top_separator(Graph& g) {
  idx_t n = g.size(), separator = 0, options[METIS_NOPTIONS];
  default_options(options);
  std::vector<idx_t> part(std::size_t(n), 0);
  if (g.adjncy.empty()) return part;
  if (METIS_ComputeVertexSeparator(&n, g.xadj.data(), g.adjncy.data(), nullptr, options, &separator,
                                   part.data()) != METIS_OK)
    return {};
  return part;
}

// The subgraph induced by the vertices with part[v] == side, numbered in ascending v (global[]).
Graph side_graph(const Graph& g, const std::vector<idx_t>& part, idx_t side, std::vector<int>& global) {
  std::vector<idx_t> local(part.size(), -1);
  for (std::size_t v = 0; v < part.size(); ++v)
    if (part[v] == side) local[v] = idx_t(global.size()), global.push_back(int(v));
  Graph s;
  for (int v : global) {
    for (idx_t k = g.xadj[std::size_t(v)]; k < g.xadj[std::size_t(v) + 1]; ++k)
      if (const idx_t u = local[std::size_t(g.adjncy[std::size_t(k)])]; u >= 0) s.adjncy.push_back(u);
    s.xadj.push_back(idx_t(s.adjncy.size()));
  }
  return s;
}

// METIS_NodeND's order of g (place -> vertex), identity when g has no edge; false on failure.
bool node_nd(Graph& g, std::vector<idx_t>& perm) {
  idx_t n = g.size(), options[METIS_NOPTIONS];
  perm.resize(std::size_t(n));
  for (idx_t k = 0; k < n; ++k) perm[std::size_t(k)] = k;
  if (g.adjncy.empty()) return true;
  default_options(options);
  std::vector<idx_t> iperm(perm.size());
  return METIS_NodeND(&n, g.xadj.data(), g.adjncy.data(), nullptr, options, perm.data(), iperm.data()) == METIS_OK;
}

// The order of one side in global ids (empty and `ok` false on failure).
struct SideOrder {
  std::vector<int> global, order;
  bool ok = false;
  double cpu = 0;  // thread CPU s (COLONFLAT_FLATTEN_DEBUG)
};

void order_side(const Graph& g, const std::vector<idx_t>& part, idx_t side, SideOrder& out) {
  const double start = thread_cpu_seconds();
  Graph s = side_graph(g, part, side, out.global);
  std::vector<idx_t> perm;
  out.ok = node_nd(s, perm);
  if (!out.ok) return;
  out.order.reserve(perm.size());
  for (idx_t p : perm) out.order.push_back(out.global[std::size_t(p)]);
  out.cpu = thread_cpu_seconds() - start;
}

// order followed by the postorder of the elimination tree of the symmetric matrix whose lower
// triangle is `lower` permuted by it (cholmod_metis's `postorder`): same fill, each subtree's
// columns contiguous.
bool postorder(cholmod_sparse& lower, std::vector<int>& order) {
  const std::size_t n = order.size();
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  std::vector<int> parent(n), post(n);
  const bool ok = cholmod_analyze_ordering(&lower, CHOLMOD_GIVEN, order.data(), nullptr, 0, parent.data(), post.data(),
                                           nullptr, nullptr, nullptr, &common) &&
                  common.status == CHOLMOD_OK;
  cholmod_finish(&common);
  if (!ok) return false;
  std::vector<int> combined(n);
  for (std::size_t k = 0; k < n; ++k) combined[k] = order[std::size_t(post[k])];
  order.swap(combined);
  return true;
}

// The lower triangle of g's adjacency (no diagonal: the elimination tree does not read it) as a
// CHOLMOD pattern; `p`, `i`: its storage.
cholmod_sparse lower_pattern(const Graph& g, std::vector<int>& p, std::vector<int>& i) {
  const int n = g.size();
  p.assign(1, 0);
  i.clear();
  i.reserve(g.adjncy.size() / 2);
  for (int j = 0; j < n; ++j) {
    for (int k = g.xadj[std::size_t(j)]; k < g.xadj[std::size_t(j) + 1]; ++k)
      if (g.adjncy[std::size_t(k)] > j) i.push_back(g.adjncy[std::size_t(k)]);
    p.push_back(int(i.size()));
  }
  return view_columns(std::size_t(n), std::size_t(n), p.data(), i.data(), nullptr, -1);
}

// COLONFLAT_FLATTEN_DEBUG: what the split order's parts cost.
void print_split_debug(double separator_s, const SideOrder (&sides)[2], double sides_s) {
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr,
                 "flatten debug split order: separator %.2f s, sides %zu / %zu vertices (CPU %.2f / %.2f s, "
                 "wall %.2f s)\n",
                 separator_s, sides[0].global.size(), sides[1].global.size(), sides[0].cpu, sides[1].cpu, sides_s);
}

// metis_split_order of the graph g.
SplitOrder split_order(Graph& g) {
  const Stopwatch sw;
  const std::vector<idx_t> part = top_separator(g);
  if (part.empty()) return {};
  const double separator_s = sw.seconds();
  SideOrder sides[2];
  cf::parallel_tasks({[&] { order_side(g, part, 0, sides[0]); }, [&] { order_side(g, part, 1, sides[1]); }});
  print_split_debug(separator_s, sides, sw.seconds() - separator_s);
  if (!sides[0].ok || !sides[1].ok) return {};
  SplitOrder out;
  out.order = sides[0].order;
  out.first_side = int(out.order.size());
  out.order.insert(out.order.end(), sides[1].order.begin(), sides[1].order.end());
  const std::size_t sides_size = out.order.size();
  for (std::size_t v = 0; v < part.size(); ++v)
    if (part[v] == 2) out.order.push_back(int(v));
  out.separator = int(out.order.size() - sides_size);
  return out;
}

}  // namespace

bool metis_direct_available() { return true; }

SplitOrder metis_split_order(const MetisSpMat& A) {
  if (A.rows() != A.cols() || A.rows() == 0 || !A.isCompressed()) return {};
  Graph g = graph_of(A);
  return split_order(g);
}

std::vector<int> metis_split_dissection_order(const MetisSpMat& A) {
  std::vector<int> order = metis_split_order(A).order;
  cholmod_sparse view = view_lower(A);
  if (order.empty() || !postorder(view, order)) return {};
  return order;
}

std::vector<int> metis_split_dissection_order(VertexGraph g) {
  if (g.size() <= 0) return {};
  std::vector<int> order = split_order(g).order;
  std::vector<int> p, i;
  cholmod_sparse lower = lower_pattern(g, p, i);
  if (order.empty() || !postorder(lower, order)) return {};
  return order;
}

}  // namespace cf::flat_detail

#else  // no libmetis-dev (or no CHOLMOD): SpdSolver orders through CHOLMOD's METIS wrapper or AMD

namespace cf::flat_detail {

bool metis_direct_available() { return false; }
SplitOrder metis_split_order(const MetisSpMat&) { return {}; }
std::vector<int> metis_split_dissection_order(const MetisSpMat&) { return {}; }
std::vector<int> metis_split_dissection_order(VertexGraph) { return {}; }

}  // namespace cf::flat_detail

#endif
