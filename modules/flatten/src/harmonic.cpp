// The conformal map of an annulus: harmonic u between the two ends, its conjugate v with a
// period around the tube (a holomorphic 1-form, Hong et al. 2006, Zeng et al. 2010), and the
// embedding of the annulus on the periodic cylinder.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <queue>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "flatten_internal.h"
#include "conformal_factor.h"
#include "face_blocks.h"
#include "factor_schedule.h"
#include "metis_order.h"
#include "spd_solver.h"

namespace cf::flat_detail {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

std::vector<double> cot_weights(const Surface& s, const Edges& E, bool clamp) {
  std::vector<double> w(E.ev.size(), 0.0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const V3 a = s.p[s.t[f][(k + 1) % 3]] - s.p[s.t[f][k]];
      const V3 b = s.p[s.t[f][(k + 2) % 3]] - s.p[s.t[f][k]];
      const double c = a.cross(b).norm();
      double cot = a.dot(b) / std::max(c, 1e-12 * a.squaredNorm() + 1e-300);
      cot = std::clamp(cot, -1e4, 1e4);
      w[E.fe[f][k]] += 0.5 * cot;
    }
  if (clamp)
    for (double& x : w) x = std::max(x, 1e-3);
  return w;
}

// The cut cocycle: a shortest dual path of faces from loop A (mark 1) to loop B (mark 2); each
// edge it crosses gets +-1 (per edge, lo -> hi).
std::vector<signed char> cut_cocycle(const Surface& s, const Edges& E, const std::vector<char>& mark) {
  auto boundary_edge_on = [&](int f, int which) -> int {
    for (int k = 0; k < 3; ++k) {
      const int e = E.fe[f][k];
      if (E.ef[e][1] < 0 && mark[E.ev[e][0]] == which && mark[E.ev[e][1]] == which) return k;
    }
    return -1;
  };
  const std::size_t nf = s.t.size();
  std::vector<int> parent(nf, -2);
  std::queue<int> q;
  for (std::size_t f = 0; f < nf; ++f)
    if (boundary_edge_on(int(f), 1) >= 0) parent[f] = -1, q.push(int(f));
  int end_face = -1;
  while (!q.empty() && end_face < 0) {
    const int f = q.front();
    q.pop();
    if (boundary_edge_on(f, 2) >= 0) {
      end_face = f;
      break;
    }
    for (int e : E.fe[f]) {
      const int g = E.ef[e][0] == f ? E.ef[e][1] : E.ef[e][0];
      if (g >= 0 && parent[g] == -2) parent[g] = f, q.push(g);
    }
  }
  if (end_face < 0) throw Error("no path between the two ends of a segment");
  std::vector<signed char> eta(E.ev.size(), 0);
  auto set_eta = [&](int f, int k, int sign) {  // the halfedge opposite corner k of face f gets `sign`
    const int a = s.t[f][(k + 1) % 3], b = s.t[f][(k + 2) % 3];
    eta[E.fe[f][k]] = static_cast<signed char>(a < b ? sign : -sign);
  };
  set_eta(end_face, boundary_edge_on(end_face, 2), +1);
  int f0 = end_face;
  for (; parent[f0] >= 0; f0 = parent[f0]) {
    const int g = parent[f0];  // crossing from g into f0
    for (int k = 0; k < 3; ++k) {
      const int e = E.fe[g][k];
      if (E.ef[e][0] == f0 || E.ef[e][1] == f0) {
        set_eta(g, k, +1);
        break;
      }
    }
  }
  set_eta(f0, boundary_edge_on(f0, 1), -1);
  return eta;
}

// A sparse system A x = rhs over some vertices (A: lower triangle only, as SpdSolver reads it):
// unknown_of[v] = the unknown of vertex v, -1 when the vertex is not one.
struct LinearSystem {
  SpMat A;
  Eigen::VectorXd rhs;
  std::vector<int> unknown_of;
};

// The lower triangle (CSC) of the weighted graph Laplacian over the unknowns: column j holds the
// diagonal (the sum of the weights of all edges at unknown j's vertex, fixed neighbours included)
// and -w for each edge to an unknown of a higher vertex id. `unknown_of` increases with the vertex
// id, and E.ev is sorted by (lo, hi) (build_edges), so each column comes out with its rows sorted.
// `w(e)` is edge e's weight, `unknown_of(v)` vertex v's unknown (-1: fixed): read, not stored.
template <class Weight, class Unknown>
SpMat laplacian_lower(const Edges& E, Weight w, Unknown unknown_of, int n) {
  std::vector<double> diagonal(n, 0.0);
  std::vector<int> below(n, 0);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int ia = unknown_of(E.ev[e][0]), ib = unknown_of(E.ev[e][1]);
    if (ia >= 0) diagonal[ia] += w(e);
    if (ib >= 0) diagonal[ib] += w(e);
    if (ia >= 0 && ib >= 0) ++below[ia];
  }
  SpMat A(n, n);
  std::size_t nnz = 0;
  for (int j = 0; j < n; ++j) nnz += 1 + below[j];
  A.resizeNonZeros(Eigen::Index(nnz));
  int* outer = A.outerIndexPtr();
  int* rows = A.innerIndexPtr();
  double* values = A.valuePtr();
  outer[0] = 0;
  for (int j = 0; j < n; ++j) {
    outer[j + 1] = outer[j] + 1 + below[j];
    rows[outer[j]] = j, values[outer[j]] = diagonal[j];
    below[j] = outer[j] + 1;  // next free slot of column j
  }
  bool sorted = true;
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int ia = unknown_of(E.ev[e][0]), ib = unknown_of(E.ev[e][1]);
    if (ia < 0 || ib < 0) continue;
    const int slot = below[ia]++;
    sorted = sorted && rows[slot - 1] < ib;
    rows[slot] = ib, values[slot] = -w(e);
  }
  if (!sorted) A = SpMat(SpMat(A.transpose()).transpose());  // transposing sorts the rows
  return A;
}

// v's right-hand side over the unknowns `unknown_of` (n of them): sum_e w_e eta_e (e_a - e_b).
Eigen::VectorXd v_rhs(const Edges& E, const std::vector<double>& w, const std::vector<signed char>& eta,
                      const std::vector<int>& unknown_of, int n) {
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    if (!eta[e]) continue;
    const int a = unknown_of[E.ev[e][0]], b = unknown_of[E.ev[e][1]];
    if (a >= 0) rhs[a] += w[e] * eta[e];
    if (b >= 0) rhs[b] -= w[e] * eta[e];
  }
  return rhs;
}

// v: minimises sum w (v_b - v_a + eta_ab)^2 with v pinned (0) at vertex `pinned`, a vertex of
// loop A: then u's unknowns (the vertices off the loops) are some of v's, and u's matrix is the
// principal submatrix of v's on them. Unknown of vertex v: v, or v - 1 past `pinned`.
LinearSystem v_system(const Edges& E, const std::vector<double>& w, const std::vector<signed char>& eta, int nv,
                      int pinned) {
  LinearSystem sys;
  sys.unknown_of.resize(nv);
  for (int v = 0; v < nv; ++v) sys.unknown_of[v] = v < pinned ? v : v == pinned ? -1 : v - 1;
  sys.A = laplacian_lower(E, [&w](std::size_t e) { return w[e]; },
                         [&u = sys.unknown_of](int v) { return u[std::size_t(v)]; }, nv - 1);
  sys.rhs = v_rhs(E, w, eta, sys.unknown_of, nv - 1);
  return sys;
}

// u: harmonic, 0 on loop A (mark 1), 1 on loop B (mark 2); its unknowns are the other vertices.
// Its right-hand side over v's n unknowns (the loops' entries 0, not read by the leading solve).
Eigen::VectorXd u_rhs(const Edges& E, const std::vector<double>& w, const std::vector<char>& mark,
                      const std::vector<int>& unknown_of, int n) {
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int a = E.ev[e][0], b = E.ev[e][1];
    if (mark[a] == 0 && mark[b] == 2) rhs[unknown_of[a]] += w[e];
    if (mark[b] == 0 && mark[a] == 2) rhs[unknown_of[b]] += w[e];
  }
  return rhs;
}

// The elimination order of v's unknowns from a vertex order: the vertices off the loops first, then
// the loops' vertices (each group in the vertex order), so that u's unknowns are the leading block
// (SpdSolver::solve_leading). `leading`: their number.
std::vector<int> loops_last(const std::vector<int>& vertex_order, const std::vector<int>& unknown_of,
                            const std::vector<char>& mark, int& leading) {
  std::vector<int> order;
  order.reserve(vertex_order.size());
  for (int pass = 0; pass < 2; ++pass)
    for (int v : vertex_order)
      if (v >= 0 && v < int(unknown_of.size()) && unknown_of[v] >= 0 && (mark[v] != 0) == (pass == 1))
        order.push_back(unknown_of[v]);
  leading = int(std::count(mark.begin(), mark.end(), 0));
  return order;
}

// The vertices in the order of v's unknowns `order`, then the pinned vertex.
std::vector<int> vertex_order_of(const std::vector<int>& order, const std::vector<int>& unknown_of) {
  std::vector<int> vertex_of(order.size());
  int pinned = -1;
  for (std::size_t v = 0; v < unknown_of.size(); ++v)
    if (unknown_of[v] >= 0) vertex_of[unknown_of[v]] = int(v);
    else pinned = int(v);
  std::vector<int> vertices;
  vertices.reserve(unknown_of.size());
  for (int k : order) vertices.push_back(vertex_of[k]);
  vertices.push_back(pinned);
  return vertices;
}

// u and v per vertex (u 0 / 1 on the loops, v 0 at the pinned vertex), with the order and the
// factorisation that gave them.
struct UvSolution {
  Eigen::VectorXd u, v;
  std::vector<int> vertex_order;
  std::shared_ptr<ConformalFactor> factor;
};

// Solves v's system and u's (v's leading block, `f.leading` unknowns) with the factorisation f;
// `unknown_of`: each vertex's unknown in f's system.
void solve_with(const ConformalFactor& f, const Edges& E, const std::vector<double>& w,
                const std::vector<signed char>& eta, const std::vector<char>& mark,
                const std::vector<int>& unknown_of, UvSolution& sol) {
  const int n = int(f.unknown_of.size()) - 1;
  Eigen::VectorXd xv, xu;  // two solves with one factorisation, side by side
  parallel_tasks({[&] { xv = f.solver.solve(v_rhs(E, w, eta, unknown_of, n)); },
                  [&] { xu = f.solver.solve_leading(u_rhs(E, w, mark, unknown_of, n), f.leading); }});
  const std::size_t nv = mark.size();
  sol.u.resize(Eigen::Index(nv));
  sol.v.resize(Eigen::Index(nv));
  for (std::size_t v = 0; v < nv; ++v) {
    const int k = unknown_of[v];
    sol.u[Eigen::Index(v)] = mark[v] == 0 ? xu[k] : mark[v] == 1 ? 0.0 : 1.0;
    sol.v[Eigen::Index(v)] = k >= 0 ? xv[k] : 0.0;
  }
}

// The vertex order `prior` gives for a new factorisation (empty: none), waiting for it when it is
// still being computed.
std::vector<int> given_vertex_order(PriorSolve* prior) {
  if (!prior) return {};
  if (prior->vertex_order.empty() && prior->order_when_ready) {
    debug_clock("first conformal system assembled");
    prior->vertex_order = prior->order_when_ready();
    debug_clock("waited for the elimination order");
  }
  prior->order_when_ready = nullptr;
  return prior->vertex_order;
}

// A new factorisation of v's system (pinned at `pinned`), one fill-reducing order for u and v
// (the vertex order `prior` gives, asked for once the system is assembled, else AMD on v's
// system), loops last.
UvSolution solve_fresh(const Edges& E, const std::vector<double>& w, const std::vector<signed char>& eta,
                       const std::vector<char>& mark, int pinned, bool clamp, PriorSolve* prior) {
  const LinearSystem vs = v_system(E, w, eta, int(mark.size()), pinned);
  auto f = std::make_shared<ConformalFactor>();
  f->unknown_of = vs.unknown_of;
  f->mark = mark;
  f->clamp = clamp;
  f->edges = E.ev;
  f->weights = w;
  std::vector<int> by_vertex = given_vertex_order(prior);
  if (by_vertex.empty()) by_vertex = vertex_order_of(SpdSolver::fill_reducing_order(vs.A), vs.unknown_of);
  const std::vector<int> order = loops_last(by_vertex, vs.unknown_of, mark, f->leading);
  const Stopwatch sw;
  if (!f->solver.compute(vs.A, &order)) throw Error("sparse Cholesky factorisation failed (degenerate surface?)");
  if (prior) debug_clock("conformal factorisation");
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug conformal factorisation: %ld unknowns, %.3g flops, %.3g entries of L, dense root %d columns, %.2f s\n",
                 long(vs.A.rows()), f->solver.factor_flops(), double(f->solver.factor_entries()),
                 f->solver.dense_root_columns(), sw.seconds());
  UvSolution sol;
  solve_with(*f, E, w, eta, mark, vs.unknown_of, sol);
  sol.vertex_order = vertex_order_of(order, vs.unknown_of);
  sol.factor = std::move(f);
  return sol;
}

// The earlier solve's factorisation updated to this surface (the part of its surface that remains),
// when it has the same weights and loops; false otherwise.
bool solve_updated(PriorSolve& prior, const Edges& E, const std::vector<double>& w,
                   const std::vector<signed char>& eta, const std::vector<char>& mark, bool clamp, UvSolution& sol) {
  ConformalFactor& f = *prior.factor;
  if (f.clamp != clamp || prior.new_of_old.empty() || !restrict_factor(f, E, w, mark, prior.new_of_old)) return false;
  std::vector<int> unknown_of(mark.size(), -1);
  for (std::size_t v = 0; v < prior.new_of_old.size(); ++v)
    if (prior.new_of_old[v] >= 0) unknown_of[prior.new_of_old[v]] = f.unknown_of[v];
  solve_with(f, E, w, eta, mark, unknown_of, sol);
  sol.vertex_order = prior.vertex_order;
  return true;
}

double eta_dir(const std::vector<signed char>& eta, const Edges& E, int e, int from) {
  return E.ev[e][0] == from ? eta[e] : -eta[e];
}

}  // namespace

Harmonic solve_harmonic(const Surface& s, const Edges& E, const std::vector<int>& loop_a,
                        const std::vector<int>& loop_b, bool clamp, PriorSolve* prior) {
  Harmonic h;
  h.weights = clamp ? "clamped" : "cotan";
  const int nv = int(s.p.size());
  if (loop_a.empty() || loop_b.empty()) throw Error("a segment end without vertices");
  for (const std::vector<int>* loop : {&loop_a, &loop_b})  // (an index out of the band would write past `mark`)
    if (std::any_of(loop->begin(), loop->end(), [nv](int v) { return v < 0 || v >= nv; }))
      throw Error("a segment end with a vertex that is not the band's (internal error)");
  const std::vector<double> w = cot_weights(s, E, clamp);
  std::vector<char> mark(nv, 0);
  for (int v : loop_a) mark[v] = 1;
  for (int v : loop_b) mark[v] = 2;
  h.eta = cut_cocycle(s, E, mark);
  UvSolution sol;
  const bool updated = prior && prior->factor && solve_updated(*prior, E, w, h.eta, mark, clamp, sol);
  if (prior) prior->factor.reset();  // consumed (or of no use here): its memory back before a new one
  if (!updated) sol = solve_fresh(E, w, h.eta, mark, loop_a.front(), clamp, prior);
  h.u = std::move(sol.u);
  h.v = std::move(sol.v);
  h.vertex_order = std::move(sol.vertex_order);
  h.factor = std::move(sol.factor);
  h.v.array() -= h.v[0];  // v = 0 at vertex 0 (the constant is free; the layout keeps this one)
  double ev = 0;
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const double du = h.u[E.ev[e][1]] - h.u[E.ev[e][0]];
    const double dv = h.v[E.ev[e][1]] - h.v[E.ev[e][0]] + h.eta[e];
    h.energy_u += w[e] * du * du;
    ev += w[e] * dv * dv;
  }
  // Period minimising the conformal energy of (u, P v) (signed area of the unit map is 1).
  h.period = 1.0 / ev;
  return h;
}

namespace {

// The graph Laplacian (unit weights) of all nv vertices: the pattern the orders are computed on
// (no per-edge weight or per-vertex map allocated for it: ~28 MB on a 1M-vertex colon).
SpMat unit_laplacian(const Edges& E, int nv) {
  return laplacian_lower(E, [](std::size_t) { return 1.0; }, [](int v) { return v; }, nv);
}

}  // namespace

namespace {

// COLONFLAT_FLATTEN_DEBUG: what an order of the vertex graph cost.
void print_order_debug(const char* kind, int nv, const Stopwatch& sw) {
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug %s order: %d vertices, %.2f s\n", kind, nv, sw.seconds());
}

}  // namespace

std::vector<int> fill_reducing_vertex_order(const Edges& E, int nv) {
  const Stopwatch sw;
  std::vector<int> order = SpdSolver::fill_reducing_order(unit_laplacian(E, nv));
  print_order_debug("AMD", nv, sw);
  return order;
}

std::vector<int> nested_dissection_vertex_order(const std::vector<Tri>& t, int nv) {
  const Stopwatch sw;
  std::vector<int> order;
  if (metis_direct_available()) {
    const double cpu = thread_cpu_seconds();
    VertexGraph g = vertex_graph(t, nv);
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug order's graph: %.2f s CPU\n", thread_cpu_seconds() - cpu);
    order = metis_split_dissection_order(std::move(g));
  }
  if (order.empty()) order = SpdSolver::nested_dissection_order(unit_laplacian(build_edges(t), nv));
  print_order_debug("nested dissection", nv, sw);
  return order;
}

bool uses_dissection(std::size_t vertices, const std::string& map) {
  return vertices >= kNestedDissectionMinVertices && map == "area-balanced";
}

SegmentOrder small_segment_vertex_order(const Edges& E, int nv, bool measure) {
  SegmentOrder amd{fill_reducing_vertex_order(E, nv), false};
  if (!measure || nv <= 0) return amd;
  const Stopwatch sw;
  const SpMat A = unit_laplacian(E, nv);
  const double per_vertex = SpdSolver::order_flops(A, amd.order) / nv;
  const bool nested = per_vertex > kDissectionMinFlopsPerVertex;
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug order choice: %d vertices, AMD's factorisation %.3g operations per vertex (%.2f s): %s\n",
                 nv, per_vertex, sw.seconds(), nested ? "nested dissection" : "AMD");
  if (!nested) return amd;
  const Stopwatch nd;
  SegmentOrder out{SpdSolver::nested_dissection_order(A), true};
  print_order_debug("nested dissection", nv, nd);
  return out;
}

// Each face on its own (blocks of faces on the worker threads, face_blocks.h): the same bits for any
// thread count.
void normalise_corner_offsets(const Surface& s, Embedding& emb) {
  const double P = emb.period;
  for_each_block(s.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const auto c = emb.corners(s, int(f));
      const double shift = std::floor((c[0].y() + c[1].y() + c[2].y()) / 3 / P) * P;
      for (int k = 0; k < 3; ++k) emb.dy[f][k] -= shift;
    }
  });
}

// Each vertex and each face on its own, in blocks on the worker threads (as above).
Embedding embed_conformal(const Surface& s, const Edges& E, const Harmonic& h, double sign, double scale) {
  Embedding emb;
  emb.period = h.period * scale;
  const double ys = sign * emb.period;
  emb.pos.resize(s.p.size());
  for_each_block(s.p.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) emb.pos[v] = V2(h.u[Eigen::Index(v)] * scale, h.v[Eigen::Index(v)] * ys);
  });
  emb.dy.resize(s.t.size());
  for_each_block(s.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const Tri& t = s.t[f];
      // corner k (k = 1, 2) reached from corner 0 along the edge opposite corner 3 - k
      emb.dy[f] = {0.0, ys * eta_dir(h.eta, E, E.fe[f][2], t[0]), ys * eta_dir(h.eta, E, E.fe[f][1], t[0])};
    }
  });
  normalise_corner_offsets(s, emb);
  return emb;
}

}  // namespace cf::flat_detail
