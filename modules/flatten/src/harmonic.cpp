// The conformal map of an annulus: harmonic u between the two ends, its conjugate v with a
// period around the tube (a holomorphic 1-form, Hong et al. 2006, Zeng et al. 2010), and the
// embedding of the annulus on the periodic cylinder.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <future>
#include <queue>

#include "colonflat/core/error.h"
#include "flatten_internal.h"
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
SpMat laplacian_lower(const Edges& E, const std::vector<double>& w, const std::vector<int>& unknown_of, int n) {
  std::vector<double> diagonal(n, 0.0);
  std::vector<int> below(n, 0);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int ia = unknown_of[E.ev[e][0]], ib = unknown_of[E.ev[e][1]];
    if (ia >= 0) diagonal[ia] += w[e];
    if (ib >= 0) diagonal[ib] += w[e];
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
    const int ia = unknown_of[E.ev[e][0]], ib = unknown_of[E.ev[e][1]];
    if (ia < 0 || ib < 0) continue;
    const int slot = below[ia]++;
    sorted = sorted && rows[slot - 1] < ib;
    rows[slot] = ib, values[slot] = -w[e];
  }
  if (!sorted) A = SpMat(SpMat(A.transpose()).transpose());  // transposing sorts the rows
  return A;
}

// u: harmonic, 0 on loop A (mark 1), 1 on loop B (mark 2); unknowns: the other vertices.
LinearSystem u_system(const Edges& E, const std::vector<double>& w, const std::vector<char>& mark) {
  const int nv = int(mark.size());
  LinearSystem sys;
  std::vector<int>& idx = sys.unknown_of;
  idx.resize(nv);
  int n = 0;
  for (int v = 0; v < nv; ++v) idx[v] = mark[v] == 0 ? n++ : -1;
  sys.A = laplacian_lower(E, w, idx, n);
  sys.rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int a = E.ev[e][0], b = E.ev[e][1];
    if (idx[a] >= 0 && mark[b] == 2) sys.rhs[idx[a]] += w[e];
    if (idx[b] >= 0 && mark[a] == 2) sys.rhs[idx[b]] += w[e];
  }
  return sys;
}

// v: minimises sum w (v_b - v_a + eta_ab)^2 with v pinned at vertex 0; unknown v - 1 of vertex v.
LinearSystem v_system(const Edges& E, const std::vector<double>& w, const std::vector<signed char>& eta, int nv) {
  LinearSystem sys;
  sys.unknown_of.resize(nv);
  for (int v = 0; v < nv; ++v) sys.unknown_of[v] = v - 1;
  sys.A = laplacian_lower(E, w, sys.unknown_of, nv - 1);
  sys.rhs = Eigen::VectorXd::Zero(nv - 1);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    if (!eta[e]) continue;
    const int a = E.ev[e][0], b = E.ev[e][1];
    if (a > 0) sys.rhs[a - 1] += w[e] * eta[e];
    if (b > 0) sys.rhs[b - 1] -= w[e] * eta[e];
  }
  return sys;
}

// The elimination order of a system's unknowns induced by a vertex order (vertices that are not
// unknowns skipped, the relative order kept).
std::vector<int> restrict_order(const std::vector<int>& vertex_order, const std::vector<int>& unknown_of) {
  std::vector<int> order;
  order.reserve(vertex_order.size());
  for (int v : vertex_order)
    if (v >= 0 && v < int(unknown_of.size()) && unknown_of[v] >= 0) order.push_back(unknown_of[v]);
  return order;
}

Eigen::VectorXd factorize_and_solve(SpdSolver& solver, const LinearSystem& sys) {
  if (!solver.factorize(sys.A)) throw Error("sparse Cholesky factorisation failed (degenerate surface?)");
  return solver.solve(sys.rhs);
}

// Solves the u and v systems, u on a second thread; one fill-reducing order for both (the given
// vertex order, else AMD on the v system, which holds all vertices but one). Returns the vertex
// order used (empty when the solver gives none).
std::vector<int> solve_uv(const LinearSystem& us, const LinearSystem& vs, const std::vector<int>* vertex_order,
                          Eigen::VectorXd& xu, Eigen::VectorXd& xv) {
  SpdSolver v_solver;
  std::vector<int> order;
  if (vertex_order) {
    const std::vector<int> v_order = restrict_order(*vertex_order, vs.unknown_of);
    v_solver.analyze(vs.A, &v_order);
    order = *vertex_order;
  } else {
    v_solver.analyze(vs.A);
    order = v_solver.order();
    for (int& k : order) k += 1;  // unknown k is vertex k + 1
    if (!order.empty()) order.push_back(0);
  }
  const std::vector<int> u_order = restrict_order(order, us.unknown_of);
  auto u_done = std::async(std::launch::async, [&] {
    SpdSolver u_solver;
    u_solver.analyze(us.A, u_order.empty() ? nullptr : &u_order);
    return factorize_and_solve(u_solver, us);
  });
  xv = factorize_and_solve(v_solver, vs);
  xu = u_done.get();
  return order;
}

double eta_dir(const std::vector<signed char>& eta, const Edges& E, int e, int from) {
  return E.ev[e][0] == from ? eta[e] : -eta[e];
}

}  // namespace

Harmonic solve_harmonic(const Surface& s, const Edges& E, const std::vector<int>& loop_a,
                        const std::vector<int>& loop_b, bool clamp, const std::vector<int>* vertex_order) {
  Harmonic h;
  h.weights = clamp ? "clamped" : "cotan";
  const int nv = int(s.p.size());
  const std::vector<double> w = cot_weights(s, E, clamp);
  std::vector<char> mark(nv, 0);
  for (int v : loop_a) mark[v] = 1;
  for (int v : loop_b) mark[v] = 2;
  h.eta = cut_cocycle(s, E, mark);
  const LinearSystem us = u_system(E, w, mark), vs = v_system(E, w, h.eta, nv);
  Eigen::VectorXd xu, xv;
  h.vertex_order = solve_uv(us, vs, vertex_order, xu, xv);
  h.u.resize(nv);
  for (int v = 0; v < nv; ++v) h.u[v] = mark[v] == 0 ? xu[us.unknown_of[v]] : mark[v] == 1 ? 0.0 : 1.0;
  h.v.resize(nv);
  h.v[0] = 0;
  h.v.tail(nv - 1) = xv;
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

void normalise_corner_offsets(const Surface& s, Embedding& emb) {
  const double P = emb.period;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const auto c = emb.corners(s, int(f));
    const double shift = std::floor((c[0].y() + c[1].y() + c[2].y()) / 3 / P) * P;
    for (int k = 0; k < 3; ++k) emb.dy[f][k] -= shift;
  }
}

Embedding embed_conformal(const Surface& s, const Edges& E, const Harmonic& h, double sign, double scale) {
  Embedding emb;
  emb.period = h.period * scale;
  const double ys = sign * emb.period;
  emb.pos.resize(s.p.size());
  for (std::size_t v = 0; v < s.p.size(); ++v) emb.pos[v] = V2(h.u[v] * scale, h.v[v] * ys);
  emb.dy.resize(s.t.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const Tri& t = s.t[f];
    // corner k (k = 1, 2) reached from corner 0 along the edge opposite corner 3 - k
    emb.dy[f] = {0.0, ys * eta_dir(h.eta, E, E.fe[f][2], t[0]), ys * eta_dir(h.eta, E, E.fe[f][1], t[0])};
  }
  normalise_corner_offsets(s, emb);
  return emb;
}

}  // namespace cf::flat_detail
