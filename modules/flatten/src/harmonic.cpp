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

Eigen::VectorXd solve_spd(const SpMat& A, const Eigen::VectorXd& rhs) {
  SpdSolver solver;
  if (!solver.compute(A)) throw Error("sparse Cholesky factorisation failed (degenerate surface?)");
  return solver.solve(rhs);
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

// u: harmonic, 0 on loop A (mark 1), 1 on loop B (mark 2).
Eigen::VectorXd solve_u(const Edges& E, const std::vector<double>& w, const std::vector<char>& mark) {
  const int nv = int(mark.size());
  std::vector<int> idx(nv);  // >= 0 unknown index; -1 loop A; -2 loop B
  int n = 0;
  for (int v = 0; v < nv; ++v) idx[v] = mark[v] == 1 ? -1 : mark[v] == 2 ? -2 : n++;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * E.ev.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int ia = idx[E.ev[e][0]], ib = idx[E.ev[e][1]];
    if (ia >= 0) trip.emplace_back(ia, ia, w[e]);
    if (ib >= 0) trip.emplace_back(ib, ib, w[e]);
    if (ia >= 0 && ib >= 0) trip.emplace_back(ia, ib, -w[e]), trip.emplace_back(ib, ia, -w[e]);
    if (ia >= 0 && ib == -2) rhs[ia] += w[e];
    if (ib >= 0 && ia == -2) rhs[ib] += w[e];
  }
  SpMat A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  const Eigen::VectorXd x = solve_spd(A, rhs);
  Eigen::VectorXd u(nv);
  for (int v = 0; v < nv; ++v) u[v] = idx[v] >= 0 ? x[idx[v]] : idx[v] == -1 ? 0.0 : 1.0;
  return u;
}

// v: minimises sum w (v_b - v_a + eta_ab)^2 with v pinned at vertex 0.
Eigen::VectorXd solve_v(const Edges& E, const std::vector<double>& w, const std::vector<signed char>& eta, int nv) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * E.ev.size());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nv - 1);
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int a = E.ev[e][0], b = E.ev[e][1];
    const double we = w[e];
    if (a > 0) trip.emplace_back(a - 1, a - 1, we);
    if (b > 0) trip.emplace_back(b - 1, b - 1, we);
    if (a > 0 && b > 0) trip.emplace_back(a - 1, b - 1, -we), trip.emplace_back(b - 1, a - 1, -we);
    if (eta[e]) {
      if (a > 0) rhs[a - 1] += we * eta[e];
      if (b > 0) rhs[b - 1] -= we * eta[e];
    }
  }
  SpMat A(nv - 1, nv - 1);
  A.setFromTriplets(trip.begin(), trip.end());
  const Eigen::VectorXd x = solve_spd(A, rhs);
  Eigen::VectorXd v(nv);
  v[0] = 0;
  v.tail(nv - 1) = x;
  return v;
}

double eta_dir(const std::vector<signed char>& eta, const Edges& E, int e, int from) {
  return E.ev[e][0] == from ? eta[e] : -eta[e];
}

}  // namespace

Harmonic solve_harmonic(const Surface& s, const Edges& E, const std::vector<int>& loop_a,
                        const std::vector<int>& loop_b, bool clamp) {
  Harmonic h;
  h.weights = clamp ? "clamped" : "cotan";
  const int nv = int(s.p.size());
  const std::vector<double> w = cot_weights(s, E, clamp);
  std::vector<char> mark(nv, 0);
  for (int v : loop_a) mark[v] = 1;
  for (int v : loop_b) mark[v] = 2;
  h.eta = cut_cocycle(s, E, mark);
  // u and v need one factorisation each; they are independent, so run them on two threads.
  auto u_done = std::async(std::launch::async, [&] { return solve_u(E, w, mark); });
  h.v = solve_v(E, w, h.eta, nv);
  h.u = u_done.get();
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
