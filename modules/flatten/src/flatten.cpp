#include "colonflat/flatten/flatten.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <future>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <numeric>
#include <queue>
#include <unordered_map>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/union_find.h"

namespace cf {
namespace {

using V3 = Eigen::Vector3d;
using Tri = std::array<int, 3>;

struct Surface {
  std::vector<V3> p;
  std::vector<Tri> t;
  std::vector<int> src;  // input vertex id of each local vertex
};

struct Edges {
  std::vector<std::array<int, 2>> ev;  // lo < hi
  std::vector<std::array<int, 2>> ef;  // faces; [1] = -1 on the boundary
  std::vector<std::array<int, 3>> fe;  // edge opposite corner k of each face
};

Edges build_edges(const std::vector<Tri>& t) {
  Edges E;
  std::vector<std::pair<std::uint64_t, int>> keys;
  keys.reserve(3 * t.size());
  for (std::size_t f = 0; f < t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      std::uint64_t a = t[f][(k + 1) % 3], b = t[f][(k + 2) % 3];
      if (a > b) std::swap(a, b);
      keys.push_back({(a << 32) | b, int(3 * f + k)});
    }
  std::sort(keys.begin(), keys.end());
  E.fe.assign(t.size(), {-1, -1, -1});
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j].first == keys[i].first) ++j;
    if (j - i > 2) throw PreconditionError("non-manifold edge in a colon segment; flatten needs a 2-manifold");
    const int e = int(E.ev.size());
    E.ev.push_back({int(keys[i].first >> 32), int(keys[i].first & 0xffffffffu)});
    E.ef.push_back({keys[i].second / 3, j - i == 2 ? keys[i + 1].second / 3 : -1});
    for (std::size_t q = i; q < j; ++q) E.fe[keys[q].second / 3][keys[q].second % 3] = e;
    i = j;
  }
  return E;
}

struct Csr {
  std::vector<int> start, nbr;
  std::vector<double> len;
};

Csr build_csr(const Surface& s, const Edges& E) {
  Csr g;
  const std::size_t nv = s.p.size();
  g.start.assign(nv + 1, 0);
  for (const auto& e : E.ev) ++g.start[e[0] + 1], ++g.start[e[1] + 1];
  for (std::size_t i = 0; i < nv; ++i) g.start[i + 1] += g.start[i];
  g.nbr.resize(g.start[nv]);
  g.len.resize(g.start[nv]);
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (const auto& e : E.ev) {
    const double l = (s.p[e[0]] - s.p[e[1]]).norm();
    g.nbr[fill[e[0]]] = e[1], g.len[fill[e[0]]++] = l;
    g.nbr[fill[e[1]]] = e[0], g.len[fill[e[1]]++] = l;
  }
  return g;
}

std::vector<double> dijkstra(const Csr& g, const std::vector<int>& sources) {
  std::vector<double> d(g.start.size() - 1, kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  for (int s : sources) d[s] = 0, q.push({0.0, s});
  while (!q.empty()) {
    auto [dv, v] = q.top();
    q.pop();
    if (dv > d[v]) continue;
    for (int k = g.start[v]; k < g.start[v + 1]; ++k) {
      const double nd = dv + g.len[k];
      if (nd < d[g.nbr[k]]) d[g.nbr[k]] = nd, q.push({nd, g.nbr[k]});
    }
  }
  return d;
}

int argmax_finite(const std::vector<double>& d) {
  int best = 0;
  for (std::size_t i = 0; i < d.size(); ++i)
    if (std::isfinite(d[i]) && (!std::isfinite(d[best]) || d[i] > d[best])) best = int(i);
  return best;
}

// Keeps the largest edge-connected set of faces among `keep`.
void keep_largest_component(const Edges& E, std::vector<char>& keep) {
  const std::size_t nf = keep.size();
  std::vector<int> comp(nf, -1);
  int best = -1;
  std::size_t best_size = 0;
  int ncomp = 0;
  std::vector<int> stack;
  for (std::size_t f0 = 0; f0 < nf; ++f0) {
    if (!keep[f0] || comp[f0] >= 0) continue;
    std::size_t size = 0;
    stack.push_back(int(f0));
    comp[f0] = ncomp;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      ++size;
      for (int e : E.fe[f])
        for (int g : E.ef[e])
          if (g >= 0 && keep[g] && comp[g] < 0) comp[g] = ncomp, stack.push_back(g);
    }
    if (size > best_size) best_size = size, best = ncomp;
    ++ncomp;
  }
  for (std::size_t f = 0; f < nf; ++f) keep[f] = keep[f] && comp[f] == best;
}

// Surface made of the kept faces, reindexed; `old_of_new` maps new vertex ids to old ones.
Surface sub_surface(const Surface& s, const std::vector<char>& keep) {
  Surface r;
  std::vector<int> map(s.p.size(), -1);
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (!keep[f]) continue;
    Tri t;
    for (int k = 0; k < 3; ++k) {
      int& m = map[s.t[f][k]];
      if (m < 0) {
        m = int(r.p.size());
        r.p.push_back(s.p[s.t[f][k]]);
        r.src.push_back(s.src[s.t[f][k]]);
      }
      t[k] = m;
    }
    r.t.push_back(t);
  }
  return r;
}

// Boundary vertex sets (one per loop) of a surface, via its boundary edges.
std::vector<std::vector<int>> boundary_loops(const Surface& s, const Edges& E) {
  UnionFind uf(s.p.size());
  std::vector<char> on(s.p.size(), 0);
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (E.ef[e][1] < 0) uf.unite(E.ev[e][0], E.ev[e][1]), on[E.ev[e][0]] = on[E.ev[e][1]] = 1;
  std::unordered_map<int, int> id;
  std::vector<std::vector<int>> loops;
  for (std::size_t v = 0; v < s.p.size(); ++v) {
    if (!on[v]) continue;
    const int r = int(uf.find(v));
    auto it = id.find(r);
    if (it == id.end()) it = id.emplace(r, int(loops.size())).first, loops.emplace_back();
    loops[it->second].push_back(int(v));
  }
  return loops;
}

// Removes caps around the ends of a segment with b boundary loops (b = 0 or 1) so that an annulus
// remains. Returns the annulus and which of its loops is end A.
struct Opened {
  Surface annulus;
  std::size_t removed = 0;
};

Opened open_ends(const Surface& s, const Edges& E, std::size_t nloops, double radius) {
  const Csr g = build_csr(s, E);
  std::vector<char> remove(s.t.size(), 0);
  auto cap = [&](const std::vector<double>& d, int apex, double r) {
    for (std::size_t f = 0; f < s.t.size(); ++f) {
      const Tri& t = s.t[f];
      const double m = (d[t[0]] + d[t[1]] + d[t[2]]) / 3;
      if (m < r || t[0] == apex || t[1] == apex || t[2] == apex) remove[f] = 1;
    }
  };
  if (nloops == 2) {
    // a tube: nothing to open, only the boundary clean-up below
  } else if (nloops == 0) {
    const auto d0 = dijkstra(g, {0});
    const int a = argmax_finite(d0);
    const auto da = dijkstra(g, {a});
    const int b = argmax_finite(da);
    const auto db = dijkstra(g, {b});
    const double r = std::min(radius, 0.1 * da[b]);
    cap(da, a, r);
    cap(db, b, r);
  } else {
    std::vector<int> bverts;
    for (const auto& e : E.ev) (void)e;
    for (std::size_t e = 0; e < E.ev.size(); ++e)
      if (E.ef[e][1] < 0) bverts.push_back(E.ev[e][0]), bverts.push_back(E.ev[e][1]);
    const auto dl = dijkstra(g, bverts);
    const int b = argmax_finite(dl);
    const auto db = dijkstra(g, {b});
    cap(db, b, std::min(radius, 0.1 * dl[b]));
  }
  std::vector<char> keep(s.t.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) keep[f] = !remove[f];
  // Pinch vertices (kept faces forming several fans) make the boundary non-manifold: remove the
  // faces around them and keep the largest piece, until the boundary is clean.
  for (int iter = 0; iter < 200; ++iter) {
    keep_largest_component(E, keep);
    std::vector<int> bcount(s.p.size(), 0);
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      const int f0 = E.ef[e][0], f1 = E.ef[e][1];
      const int k = (f0 >= 0 && keep[f0]) + (f1 >= 0 && keep[f1]);
      if (k == 1) ++bcount[E.ev[e][0]], ++bcount[E.ev[e][1]];
    }
    // Also faces with all three corners on the boundary: the harmonic function, constant along
    // each end, would collapse them.
    bool changed = false;
    std::vector<char> bad(s.p.size(), 0);
    for (std::size_t v = 0; v < s.p.size(); ++v) bad[v] = bcount[v] > 2;
    for (std::size_t f = 0; f < s.t.size(); ++f) {
      if (!keep[f]) continue;
      const Tri& t = s.t[f];
      const bool all_on = bcount[t[0]] > 0 && bcount[t[1]] > 0 && bcount[t[2]] > 0;
      if (all_on || bad[t[0]] || bad[t[1]] || bad[t[2]]) keep[f] = 0, changed = true;
    }
    if (!changed) break;
  }
  Opened o;
  o.annulus = sub_surface(s, keep);
  o.removed = s.t.size() - o.annulus.t.size();
  return o;
}

struct Harmonic {
  Eigen::VectorXd u, v;   // v: unit period (periodic part)
  std::vector<signed char> eta;  // per edge, lo->hi direction: crossing count of the cut cocycle
  double period = 0;      // in u units: the rectangle is [0,1] x [0,period]
  double energy_u = 0;
  std::string weights;
};

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

template <class Solver>
void factor(Solver& solver, const Eigen::SparseMatrix<double>& A) {
  solver.compute(A);
  if (solver.info() != Eigen::Success) throw Error("sparse Cholesky factorisation failed (degenerate surface?)");
}

Harmonic solve_harmonic(const Surface& s, const Edges& E, const std::vector<int>& loop_a,
                        const std::vector<int>& loop_b, bool clamp) {
  Harmonic h;
  h.weights = clamp ? "clamped" : "cotan";
  const int nv = int(s.p.size());
  const std::vector<double> w = cot_weights(s, E, clamp);
  // The cut cocycle: a dual path of faces from loop A to loop B; each edge it crosses gets +-1.
  std::vector<char> mark(nv, 0);
  for (int v : loop_a) mark[v] = 1;
  for (int v : loop_b) mark[v] = 2;
  const std::size_t nf = s.t.size();
  auto boundary_edge_on = [&](int f, int which) -> int {
    for (int k = 0; k < 3; ++k) {
      const int e = E.fe[f][k];
      if (E.ef[e][1] < 0 && mark[E.ev[e][0]] == which && mark[E.ev[e][1]] == which) return k;
    }
    return -1;
  };
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
  h.eta.assign(E.ev.size(), 0);
  // Sets eta so that the halfedge of edge (corner k of face f) has value `sign`.
  auto set_eta = [&](int f, int k, int sign) {
    const int a = s.t[f][(k + 1) % 3], b = s.t[f][(k + 2) % 3];
    h.eta[E.fe[f][k]] = static_cast<signed char>(a < b ? sign : -sign);
  };
  set_eta(end_face, boundary_edge_on(end_face, 2), +1);
  for (int f = end_face; parent[f] >= 0; f = parent[f]) {
    const int g = parent[f];  // crossing from g into f
    for (int k = 0; k < 3; ++k) {
      const int e = E.fe[g][k];
      if (E.ef[e][0] == f || E.ef[e][1] == f) {
        set_eta(g, k, +1);
        break;
      }
    }
  }
  {
    int f0 = end_face;
    while (parent[f0] >= 0) f0 = parent[f0];
    set_eta(f0, boundary_edge_on(f0, 1), -1);
  }
  // u: Dirichlet 0 on loop A, 1 on loop B.
  std::vector<int> idx(nv);  // >= 0 unknown index; -1 loop A; -2 loop B
  int n = 0;
  for (int v = 0; v < nv; ++v) idx[v] = mark[v] == 1 ? -1 : mark[v] == 2 ? -2 : n++;
  auto solve_u = [&]() {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(4 * E.ev.size());
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      const int a = E.ev[e][0], b = E.ev[e][1];
      const int ia = idx[a], ib = idx[b];
      if (ia >= 0) trip.emplace_back(ia, ia, w[e]);
      if (ib >= 0) trip.emplace_back(ib, ib, w[e]);
      if (ia >= 0 && ib >= 0) trip.emplace_back(ia, ib, -w[e]), trip.emplace_back(ib, ia, -w[e]);
      if (ia >= 0 && ib == -2) rhs[ia] += w[e];
      if (ib >= 0 && ia == -2) rhs[ib] += w[e];
    }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
    factor(solver, A);
    const Eigen::VectorXd x = solver.solve(rhs);
    h.u.resize(nv);
    for (int v = 0; v < nv; ++v) h.u[v] = idx[v] >= 0 ? x[idx[v]] : idx[v] == -1 ? 0.0 : 1.0;
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      const double d = h.u[E.ev[e][1]] - h.u[E.ev[e][0]];
      h.energy_u += w[e] * d * d;
    }
  };
  // u and v need one factorisation each; they are independent, so run them on two threads.
  auto u_done = std::async(std::launch::async, solve_u);
  // v: minimises sum w (v_b - v_a + eta_ab)^2 with v pinned at vertex 0.
  {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(4 * E.ev.size());
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nv - 1);
    auto id = [](int v) { return v - 1; };
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      const int a = E.ev[e][0], b = E.ev[e][1];
      const double we = w[e];
      if (a > 0) trip.emplace_back(id(a), id(a), we);
      if (b > 0) trip.emplace_back(id(b), id(b), we);
      if (a > 0 && b > 0) trip.emplace_back(id(a), id(b), -we), trip.emplace_back(id(b), id(a), -we);
      if (h.eta[e]) {
        if (a > 0) rhs[id(a)] += we * h.eta[e];
        if (b > 0) rhs[id(b)] -= we * h.eta[e];
      }
    }
    Eigen::SparseMatrix<double> A(nv - 1, nv - 1);
    A.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
    factor(solver, A);
    const Eigen::VectorXd x = solver.solve(rhs);
    h.v.resize(nv);
    h.v[0] = 0;
    for (int v = 1; v < nv; ++v) h.v[v] = x[id(v)];
  }
  u_done.get();
  double ev = 0;
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const double d = h.v[E.ev[e][1]] - h.v[E.ev[e][0]] + h.eta[e];
    ev += w[e] * d * d;
  }
  // Period minimising the conformal energy of (u, P v) (signed area of the unit map is 1).
  h.period = 1.0 / ev;
  return h;
}

double eta_dir(const Harmonic& h, const Edges& E, int e, int from) {
  return E.ev[e][0] == from ? h.eta[e] : -h.eta[e];
}

// 2D coordinates of each face's corners (in u, v units, v scaled to the period), lifted so that
// the face is contiguous and its centroid lies in [0, period).
std::vector<std::array<Eigen::Vector2d, 3>> lift(const Surface& s, const Edges& E, const Harmonic& h, double sign) {
  std::vector<std::array<Eigen::Vector2d, 3>> c(s.t.size());
  const double P = h.period;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const Tri& t = s.t[f];
    double y[3];
    y[0] = h.v[t[0]];
    // corner k (k=1,2) reached from corner 0 along the edge opposite corner 3-k
    y[1] = h.v[t[1]] + eta_dir(h, E, E.fe[f][2], t[0]);
    y[2] = h.v[t[2]] + eta_dir(h, E, E.fe[f][1], t[0]);
    for (double& yy : y) yy *= sign * P;
    const double shift = std::floor((y[0] + y[1] + y[2]) / 3 / P) * P;
    for (int k = 0; k < 3; ++k) c[f][k] = {h.u[t[k]], y[k] - shift};
  }
  return c;
}

// Removes fold-overs (negative cotangent weights, or crowding: long thin protrusions such as strand
// stumps shrink exponentially under a conformal map): the vertices of flipped triangles and 1, 2,
// 4, ... rings around them are re-embedded by Tutte's method (uniform weights, the ring around the
// region fixed, a sparse solve) until every triangle with a positive 3D area has a positive 2D area.
// Returns the number of vertices moved.
std::size_t untangle(const Surface& s, const Edges& E, Harmonic& h, double sign, const std::vector<char>& on_loop,
                     const std::vector<char>& degenerate) {
  const int nv = int(s.p.size());
  // vertex -> (neighbour, edge) lists
  std::vector<int> start(nv + 1, 0);
  for (const auto& e : E.ev) ++start[e[0] + 1], ++start[e[1] + 1];
  for (int i = 0; i < nv; ++i) start[i + 1] += start[i];
  std::vector<std::pair<int, int>> nb(start[nv]);
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (std::size_t e = 0; e < E.ev.size(); ++e) {
      nb[fill[E.ev[e][0]]++] = {E.ev[e][1], int(e)};
      nb[fill[E.ev[e][1]]++] = {E.ev[e][0], int(e)};
    }
  }
  std::vector<std::vector<int>> vf(nv);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    for (int v : s.t[f]) vf[v].push_back(int(f));
  const double P = h.period;
  auto face_area = [&](int f) {
    const Tri& t = s.t[f];
    const double y0 = sign * P * h.v[t[0]];
    const double y1 = sign * P * (h.v[t[1]] + eta_dir(h, E, E.fe[f][2], t[0]));
    const double y2 = sign * P * (h.v[t[2]] + eta_dir(h, E, E.fe[f][1], t[0]));
    return (h.u[t[1]] - h.u[t[0]]) * (y2 - y0) - (y1 - y0) * (h.u[t[2]] - h.u[t[0]]);
  };
  std::vector<char> in(nv, 0);
  std::vector<int> region;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && face_area(int(f)) <= 0)
      for (int v : s.t[f])
        if (!in[v]) in[v] = 1, region.push_back(v);
  if (region.empty()) return 0;
  std::vector<int> idx(nv, -1);
  for (int round = 0; round < 3; ++round) {
    for (int ring = 0; ring < (1 << round) && round > 0; ++ring) {  // grow 1, 2, 4, ... rings
      const std::size_t n0 = region.size();
      for (std::size_t k = 0; k < n0; ++k)
        for (int q = start[region[k]]; q < start[region[k] + 1]; ++q)
          if (!in[nb[q].first]) in[nb[q].first] = 1, region.push_back(nb[q].first);
    }
    // Tutte embedding of the region (uniform weights), its outer ring and the ends fixed.
    int n = 0;
    for (int i : region) idx[i] = on_loop[i] ? -1 : n++;
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 2);
    for (int i : region) {
      if (idx[i] < 0) continue;
      const int r = idx[i];
      trip.emplace_back(r, r, double(start[i + 1] - start[i]));
      for (int q = start[i]; q < start[i + 1]; ++q) {
        const auto [j, e] = nb[q];
        const double eta = E.ev[e][0] == i ? h.eta[e] : -h.eta[e];
        if (in[j] && idx[j] >= 0) {
          trip.emplace_back(r, idx[j], -1.0);
          rhs(r, 1) += eta;
        } else {
          rhs(r, 0) += h.u[j];
          rhs(r, 1) += h.v[j] + eta;
        }
      }
    }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success) break;
    const Eigen::MatrixXd x = solver.solve(rhs);
    for (int i : region)
      if (idx[i] >= 0) h.u[i] = x(idx[i], 0), h.v[i] = x(idx[i], 1);
    bool any = false;
    for (int i : region)
      for (int f : vf[i])
        if (!degenerate[f] && face_area(f) <= 0) any = true;
    if (!any) break;
  }
  return region.size();
}

struct FaceDistortion {
  double qc, area3, area2;
  bool degenerate = false;
};

FaceDistortion face_distortion(const V3& p0, const V3& p1, const V3& p2, const Eigen::Vector2d& q0,
                               const Eigen::Vector2d& q1, const Eigen::Vector2d& q2) {
  const V3 e1 = p1 - p0, e2 = p2 - p0;
  const V3 n = e1.cross(e2);
  const double a3 = 0.5 * n.norm();
  const double l1 = e1.norm();
  FaceDistortion d{kInf, a3, 0, false};
  const Eigen::Vector2d d1 = q1 - q0, d2 = q2 - q0;
  d.area2 = 0.5 * (d1.x() * d2.y() - d1.y() * d2.x());
  if (a3 <= 0 || l1 <= 0) return d;
  const V3 x = e1 / l1, y = n.normalized().cross(x);
  Eigen::Matrix2d S, Q;
  S << l1, e2.dot(x), 0, e2.dot(y);
  Q << d1.x(), d2.x(), d1.y(), d2.y();
  const Eigen::Matrix2d J = Q * S.inverse();
  const double E_ = (J(0, 0) + J(1, 1)) / 2, F = (J(0, 0) - J(1, 1)) / 2, G = (J(1, 0) + J(0, 1)) / 2,
               H = (J(1, 0) - J(0, 1)) / 2;
  const double Qn = std::hypot(E_, H), R = std::hypot(F, G);
  d.qc = std::abs(Qn - R) > 0 ? (Qn + R) / std::abs(Qn - R) : kInf;
  return d;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

DistortionStats stats_of(const std::vector<FaceDistortion>& fd) {
  DistortionStats s;
  s.faces = fd.size();
  if (fd.empty()) return s;
  std::vector<double> qc, ar;
  qc.reserve(fd.size());
  ar.reserve(fd.size());
  double a3 = 0, a2 = 0;
  for (const auto& d : fd) a3 += d.area3, a2 += std::abs(d.area2);
  const double scale = a2 > 0 ? a3 / a2 : 1;
  double qsum = 0, lsum = 0, wsum = 0;
  for (const auto& d : fd) {
    if (d.degenerate) {
      ++s.degenerate;
      continue;
    }
    if (d.area2 <= 0) ++s.flipped;
    const double q = std::isfinite(d.qc) ? d.qc : 1e9;
    qc.push_back(q);
    qsum += q;
    s.qc_max = std::max(s.qc_max, q);
    if (d.area3 > 0) {
      const double r = std::abs(d.area2) * scale / d.area3;
      ar.push_back(r);
      if (r > 0) lsum += d.area3 * std::abs(std::log2(r)), wsum += d.area3;
    }
  }
  s.qc_mean = qc.empty() ? 0 : qsum / double(qc.size());
  s.qc_p95 = percentile(qc, 0.95);
  s.area_p05 = percentile(ar, 0.05);
  s.area_median = percentile(ar, 0.5);
  s.area_p95 = percentile(ar, 0.95);
  s.area_log2_mean_abs = wsum > 0 ? lsum / wsum : 0;
  return s;
}

DistortionStats combine(const std::vector<std::vector<FaceDistortion>>& all) {
  std::vector<FaceDistortion> v;
  for (const auto& a : all) v.insert(v.end(), a.begin(), a.end());
  return stats_of(v);
}

}  // namespace

DistortionStats distortion_stats(const FlatMap& flat, int segment) {
  std::vector<FaceDistortion> fd;
  for (const auto& t : flat.triangles) {
    if (segment >= 0 && flat.segment[t[0]] != segment) continue;
    auto P = [&](int i) { return V3(flat.position[i][0], flat.position[i][1], flat.position[i][2]); };
    auto Q = [&](int i) { return Eigen::Vector2d(flat.uv[i][0], flat.uv[i][1]); };
    fd.push_back(face_distortion(P(t[0]), P(t[1]), P(t[2]), Q(t[0]), Q(t[1]), Q(t[2])));
  }
  double mean = 0;
  for (const auto& d : fd) mean += d.area3;
  mean /= std::max<std::size_t>(1, fd.size());
  for (auto& d : fd) d.degenerate = d.area3 <= 1e-6 * mean;
  return stats_of(fd);
}

FlatMap flatten_colon(const Mesh& mesh, const FlattenOptions& opts) {
  return flatten_colon(to_triangle_list(mesh), opts);
}

FlatMap flatten_colon(const TriangleList& mesh, const FlattenOptions& opts) {
  if (opts.weights != "cotan" && opts.weights != "clamped" && opts.weights != "auto")
    throw UsageError("--weights must be cotan, clamped or auto (got '" + opts.weights + "')");
  const TopologyReport topo = analyze_topology(mesh);
  FlatMap out;
  out.input_vertices = topo.vertices;
  out.input_faces = topo.faces;
  if (topo.faces == 0) throw PreconditionError("the surface has no triangles");
  if (!topo.manifold) throw PreconditionError("the surface is not a 2-manifold; flatten needs a clean colon surface");
  const std::size_t largest = topo.components[0].faces;
  std::vector<std::vector<FaceDistortion>> all_fd;
  double y_cursor = 0;
  for (std::size_t c = 0; c < topo.components.size(); ++c) {
    const ComponentTopology& ct = topo.components[c];
    if (double(ct.faces) < opts.min_segment_fraction * double(largest) || ct.faces < 8) {
      ++out.skipped_components;
      continue;
    }
    if (!ct.genus) throw PreconditionError("segment " + std::to_string(c) + " is not an orientable 2-manifold");
    if (*ct.genus > 0)
      throw PreconditionError("colon segment " + std::to_string(c) + " has genus " + std::to_string(*ct.genus) +
                              " (handles); flatten needs genus 0: run denoise first");
    if (ct.boundary_loops > 2)
      throw PreconditionError("colon segment " + std::to_string(c) + " has " + std::to_string(ct.boundary_loops) +
                              " boundary loops; flatten needs a closed surface or a tube with two open ends");
    // The component as a local surface.
    Surface s;
    {
      std::vector<int> map(mesh.points.size(), -1);
      for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
        if (topo.face_component[f] != int(c)) continue;
        Tri t;
        for (int k = 0; k < 3; ++k) {
          int& m = map[mesh.triangles[f][k]];
          if (m < 0) {
            m = int(s.p.size());
            const auto& q = mesh.points[mesh.triangles[f][k]];
            s.p.emplace_back(q[0], q[1], q[2]);
            s.src.push_back(mesh.triangles[f][k]);
          }
          t[k] = m;
        }
        s.t.push_back(t);
      }
    }
    // Which side is the lumen: signed volume (surface closed by cones to the centroid).
    V3 centroid = V3::Zero();
    for (const auto& p : s.p) centroid += p;
    centroid /= double(s.p.size());
    double vol = 0;
    for (const Tri& t : s.t)
      vol += (s.p[t[0]] - centroid).dot((s.p[t[1]] - centroid).cross(s.p[t[2]] - centroid));
    // Normals out of the lumen (the reconstruct convention): a closed component enclosing a negative
    // volume is the wall of a cavity (a blob floating in the lumen), not colon wall: skipped.
    if (ct.boundary_loops == 0 && vol < 0) {
      ++out.skipped_components;
      continue;
    }
    const double lumen_sign = vol >= 0 ? 1.0 : -1.0;  // face normals * sign point out of the lumen

    FlatSegment seg;
    seg.id = int(out.segments.size());
    seg.component = int(c);
    seg.input_kind = ct.boundary_loops == 0 ? "closed" : ct.boundary_loops == 1 ? "one open end" : "tube";
    Surface ann;
    {
      const Edges E = build_edges(s.t);
      Opened o = open_ends(s, E, ct.boundary_loops, opts.end_cut_radius);
      ann = std::move(o.annulus);
      seg.removed_faces = o.removed;
    }
    const Edges E = build_edges(ann.t);
    auto loops = boundary_loops(ann, E);
    const long long chi = (long long)ann.p.size() - (long long)E.ev.size() + (long long)ann.t.size();
    if (loops.size() != 2 || chi != 0)
      throw Error("could not open the ends of colon segment " + std::to_string(c) + " into a tube (" +
                  std::to_string(loops.size()) + " boundary loops, Euler characteristic " + std::to_string(chi) + ")");
    // End A: the loop whose input vertices have the smaller index sum is arbitrary; prefer the
    // loop with the lower mean z? Keep it deterministic: the loop containing the smallest source id.
    {
      auto min_src = [&](const std::vector<int>& l) {
        int m = INT32_MAX;
        for (int v : l) m = std::min(m, ann.src[v]);
        return m;
      };
      if (min_src(loops[1]) < min_src(loops[0])) std::swap(loops[0], loops[1]);
    }
    auto loop_centre = [&](const std::vector<int>& l) {
      V3 m = V3::Zero();
      for (int v : l) m += ann.p[v];
      m /= double(l.size());
      return std::array<double, 3>{m.x(), m.y(), m.z()};
    };
    seg.end_a = loop_centre(loops[0]);
    seg.end_b = loop_centre(loops[1]);

    // Solve; with "auto", fall back to clamped weights when cotangent weights flip triangles.
    double area3 = 0;
    for (const Tri& t : ann.t) area3 += 0.5 * (ann.p[t[1]] - ann.p[t[0]]).cross(ann.p[t[2]] - ann.p[t[0]]).norm();
    struct Trial {
      Harmonic h;
      double sign = 1, scale = 1;
      std::vector<std::array<Eigen::Vector2d, 3>> corners;
      std::vector<FaceDistortion> fd;
      DistortionStats st;
      std::size_t untangled = 0;
      std::vector<char> crowded;
      std::size_t ncrowded = 0;
    };
    // Degenerate input triangles (zero 3D area) have no meaningful 2D orientation or ratio.
    double mean_area = area3 / double(ann.t.size());
    std::vector<char> degenerate(ann.t.size(), 0);
    for (std::size_t f = 0; f < ann.t.size(); ++f) {
      const Tri& t = ann.t[f];
      degenerate[f] = 0.5 * (ann.p[t[1]] - ann.p[t[0]]).cross(ann.p[t[2]] - ann.p[t[0]]).norm() <= 1e-6 * mean_area;
    }
    std::vector<char> on_loop(ann.p.size(), 0);
    for (const auto& l : loops)
      for (int v : l) on_loop[v] = 1;
    auto attempt = [&](bool clamp) {
      Trial tr;
      tr.h = solve_harmonic(ann, E, loops[0], loops[1], clamp);
      auto c1 = lift(ann, E, tr.h, 1.0);
      double signed_area = 0;
      for (const auto& c3 : c1) {
        const Eigen::Vector2d d1 = c3[1] - c3[0], d2 = c3[2] - c3[0];
        signed_area += d1.x() * d2.y() - d1.y() * d2.x();
      }
      tr.sign = signed_area >= 0 ? 1.0 : -1.0;
      tr.untangled = untangle(ann, E, tr.h, tr.sign, on_loop, degenerate);
      tr.corners = lift(ann, E, tr.h, tr.sign);
      tr.scale = std::sqrt(area3 / tr.h.period);
      for (auto& c3 : tr.corners)
        for (auto& q : c3) q *= tr.scale;
      tr.fd.reserve(ann.t.size());
      for (std::size_t f = 0; f < ann.t.size(); ++f) {
        const Tri& t = ann.t[f];
        tr.fd.push_back(face_distortion(ann.p[t[0]], ann.p[t[1]], ann.p[t[2]], tr.corners[f][0], tr.corners[f][1],
                                        tr.corners[f][2]));
        tr.fd.back().degenerate = degenerate[f];
      }
      // Crowding: long thin protrusions (e.g. the stumps of cut strands) shrink exponentially under
      // a conformal map, below what double precision resolves; their triangles (2D/3D area ratio
      // < 1e-7 at the area-preserving scale, or still folded) are left out of the map.
      tr.crowded.assign(ann.t.size(), 0);
      tr.ncrowded = 0;
      for (std::size_t f = 0; f < ann.t.size(); ++f)
        if (!degenerate[f] && (tr.fd[f].area2 <= 1e-7 * tr.fd[f].area3)) tr.crowded[f] = 1, ++tr.ncrowded;
      {
        std::vector<FaceDistortion> kept;
        kept.reserve(tr.fd.size());
        for (std::size_t f = 0; f < ann.t.size(); ++f)
          if (!tr.crowded[f]) kept.push_back(tr.fd[f]);
        tr.st = stats_of(kept);
      }
      return tr;
    };
    Trial tr = attempt(opts.weights == "clamped");
    if (opts.weights == "auto" && tr.ncrowded > ann.t.size() / 100) {
      Trial t2 = attempt(true);
      if (t2.ncrowded < tr.ncrowded) tr = std::move(t2);
    }
    seg.crowded_faces = tr.ncrowded;
    seg.untangled_vertices = tr.untangled;
    seg.weights = tr.h.weights;
    seg.length = tr.scale;
    seg.period = tr.scale * tr.h.period;
    seg.area_3d = area3;
    seg.faces = ann.t.size();
    seg.vertices = ann.p.size();
    seg.dirichlet_period_ratio = tr.h.energy_u / tr.h.period;
    seg.stats = tr.st;
    seg.x0 = 0;
    seg.y0 = y_cursor;
    y_cursor += seg.period + opts.segment_gap;

    // Vertex normals (area weighted), pointing out of the lumen.
    std::vector<V3> nrm(ann.p.size(), V3::Zero());
    for (const Tri& t : ann.t) {
      const V3 n = (ann.p[t[1]] - ann.p[t[0]]).cross(ann.p[t[2]] - ann.p[t[0]]);
      for (int v : t) nrm[v] += n;
    }
    // Output vertices: one per (vertex, sheet) pair.
    std::unordered_map<long long, int> vid;
    vid.reserve(ann.p.size() * 11 / 10);
    const double Pmm = seg.period;
    for (std::size_t f = 0; f < ann.t.size(); ++f) {
      if (tr.crowded[f]) continue;
      Tri ot;
      for (int k = 0; k < 3; ++k) {
        const int v = ann.t[f][k];
        const double base = tr.sign * tr.h.v[v] * Pmm;
        const long long sheet = std::llround((tr.corners[f][k].y() - base) / Pmm);
        const long long key = (long long)v * 64 + (sheet + 32);
        auto it = vid.find(key);
        if (it == vid.end()) {
          it = vid.emplace(key, int(out.uv.size())).first;
          out.uv.push_back({seg.x0 + tr.corners[f][k].x(), seg.y0 + tr.corners[f][k].y()});
          out.position.push_back({ann.p[v].x(), ann.p[v].y(), ann.p[v].z()});
          const V3 n = (lumen_sign * nrm[v]).normalized();
          out.normal.push_back({n.x(), n.y(), n.z()});
          out.segment.push_back(seg.id);
          out.source_vertex.push_back(ann.src[v]);
        }
        ot[k] = it->second;
      }
      out.triangles.push_back(ot);
    }
    {
      std::vector<FaceDistortion> kept;
      for (std::size_t f = 0; f < ann.t.size(); ++f)
        if (!tr.crowded[f]) kept.push_back(tr.fd[f]);
      all_fd.push_back(std::move(kept));
    }
    out.segments.push_back(seg);
  }
  if (out.segments.empty()) throw PreconditionError("no colon segment large enough to flatten");
  out.stats = combine(all_fd);
  return out;
}

TriangleList flat_to_surface(const FlatMap& flat, std::vector<int>* flat_to_3d) {
  TriangleList t;
  std::unordered_map<int, int> map;
  std::vector<int> f2d(flat.uv.size());
  for (std::size_t i = 0; i < flat.uv.size(); ++i) {
    auto it = map.find(flat.source_vertex[i]);
    if (it == map.end()) {
      it = map.emplace(flat.source_vertex[i], int(t.points.size())).first;
      t.points.push_back(flat.position[i]);
    }
    f2d[i] = it->second;
  }
  t.triangles.reserve(flat.triangles.size());
  for (const auto& tr : flat.triangles) t.triangles.push_back({f2d[tr[0]], f2d[tr[1]], f2d[tr[2]]});
  if (flat_to_3d) *flat_to_3d = std::move(f2d);
  return t;
}

nlohmann::json distortion_to_json(const DistortionStats& s) {
  return {{"faces", s.faces},
          {"flipped_triangles", s.flipped},
          {"degenerate_triangles", s.degenerate},
          {"quasi_conformal_mean", s.qc_mean},
          {"quasi_conformal_p95", s.qc_p95},
          {"quasi_conformal_max", s.qc_max},
          {"area_ratio_p05", s.area_p05},
          {"area_ratio_median", s.area_median},
          {"area_ratio_p95", s.area_p95},
          {"area_log2_mean_abs", s.area_log2_mean_abs}};
}

nlohmann::json segment_to_json(const FlatSegment& s) {
  return {{"id", s.id},
          {"component", s.component},
          {"input", s.input_kind},
          {"rectangle_mm", {{"x0", s.x0}, {"y0", s.y0}, {"length", s.length}, {"period", s.period}}},
          {"area_3d_mm2", s.area_3d},
          {"faces", s.faces},
          {"vertices", s.vertices},
          {"removed_end_faces", s.removed_faces},
          {"end_a_lps_mm", s.end_a},
          {"end_b_lps_mm", s.end_b},
          {"weights", s.weights},
          {"untangled_vertices", s.untangled_vertices},
          {"crowded_faces_left_out", s.crowded_faces},
          {"period_consistency", s.dirichlet_period_ratio},
          {"distortion", distortion_to_json(s.stats)}};
}

nlohmann::json flat_report(const FlatMap& f) {
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : f.segments) segs.push_back(segment_to_json(s));
  return {{"segments", segs},
          {"segment_count", f.segments.size()},
          {"skipped_components", f.skipped_components},
          {"flat_vertices", f.uv.size()},
          {"flat_triangles", f.triangles.size()},
          {"distortion", distortion_to_json(f.stats)}};
}

}  // namespace cf
