// Sparse quadratic solves on a region of the periodic-cylinder embedding (Tutte untangling and
// the ARAP global step), the rest of the map fixed.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>

#include "flatten_internal.h"
#include "proxy_descent.h"
#include "spd_solver.h"

namespace cf::flat_detail {

struct RegionSystem::Impl {
  SpdSolver solver;
};

bool RegionSystem::build(const Surface& s, const std::vector<char>& free_vertex, const std::vector<int>& faces,
                         const std::vector<std::array<double, 3>>& w, const std::vector<int>* vertex_order) {
  faces_ = faces;
  w_ = w;
  index_.assign(s.p.size(), -1);
  vars_.clear();
  for (int f : faces_)
    for (int v : s.t[f])
      if (free_vertex[v] && index_[v] < 0) index_[v] = int(vars_.size()), vars_.push_back(v);
  const int n = int(vars_.size());
  // Only the lower triangle is assembled (every solver here reads only it), the diagonal summed per
  // unknown in face order (the order setFromTriplets added its duplicates): the same matrix entries
  // from a quarter of the triplets (21.8 M on the real CT colon band's 1.8 M faces otherwise).
  std::vector<double> diagonal(std::size_t(n), 0.0);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(3 * faces_.size() + std::size_t(n));
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    const Tri& t = s.t[faces_[i]];
    for (int k = 0; k < 3; ++k) {
      const int a = index_[t[(k + 1) % 3]], b = index_[t[(k + 2) % 3]];
      const double wk = w_[i][k];
      if (a >= 0) diagonal[std::size_t(a)] += wk;
      if (b >= 0) diagonal[std::size_t(b)] += wk;
      if (a >= 0 && b >= 0) trip.emplace_back(std::max(a, b), std::min(a, b), -wk);
    }
  }
  for (int u = 0; u < n; ++u) trip.emplace_back(u, u, diagonal[std::size_t(u)]);
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  trip = {};
  impl_ = std::make_shared<Impl>();
  if (n == 0) return true;
  if (!vertex_order) return impl_->solver.compute(A);
  std::vector<int> order;  // the given order restricted to the unknowns
  order.reserve(vars_.size());
  for (int v : *vertex_order)
    if (index_[std::size_t(v)] >= 0) order.push_back(index_[std::size_t(v)]);
  return impl_->solver.compute(A, order.size() == vars_.size() ? &order : nullptr);
}

std::vector<V2> RegionSystem::solve(const Surface& s, const Embedding& emb,
                                    const std::vector<std::array<V2, 3>>& target) const {
  std::vector<V2> out = emb.pos;
  const int n = int(vars_.size());
  if (n == 0) return out;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 2);
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    const int f = faces_[i];
    const Tri& t = s.t[f];
    for (int k = 0; k < 3; ++k) {
      const int ka = (k + 1) % 3, kb = (k + 2) % 3;
      // term w |p_a - p_b - g|^2 with g = target - (offset_a - offset_b)
      const V2 g = target[i][k] - V2(0, emb.dy[f][ka] - emb.dy[f][kb]);
      const int a = index_[t[ka]], b = index_[t[kb]];
      const double wk = w_[i][k];
      if (a >= 0) {
        rhs.row(a) += wk * g.transpose();
        if (b < 0) rhs.row(a) += wk * emb.pos[t[kb]].transpose();
      }
      if (b >= 0) {
        rhs.row(b) -= wk * g.transpose();
        if (a < 0) rhs.row(b) += wk * emb.pos[t[ka]].transpose();
      }
    }
  }
  const Eigen::MatrixXd x = impl_->solver.solve(rhs);
  for (int i = 0; i < n; ++i) out[vars_[i]] = V2(x(i, 0), x(i, 1));
  return out;
}

Eigen::MatrixXd RegionSystem::solve_raw(const Eigen::MatrixXd& b) const {
  if (vars_.empty()) return b;
  return impl_->solver.solve(b);
}

CornerGather::CornerGather(const Surface& s, const std::vector<int>& faces, const RegionSystem& sys) {
  const std::size_t n = sys.unknowns().size();
  start_.assign(n + 1, 0);
  for (int f : faces)
    for (int v : s.t[f])
      if (sys.index(v) >= 0) ++start_[std::size_t(sys.index(v)) + 1];
  for (std::size_t u = 0; u < n; ++u) start_[u + 1] += start_[u];
  corner_.resize(std::size_t(start_[n]));
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < faces.size(); ++i)  // face order: each unknown's corners come in face order
    for (int k = 0; k < 3; ++k)
      if (const int u = sys.index(s.t[faces[i]][k]); u >= 0) corner_[std::size_t(fill[u]++)] = int(3 * i) + k;
}

Eigen::MatrixXd CornerGather::sum(const std::vector<std::array<V2, 3>>& face_gradients) const {
  const std::size_t n = start_.size() - 1;
  Eigen::MatrixXd g(Eigen::Index(n), 2);
  for_each_block(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t u = begin; u < end; ++u) {
      double gx = 0, gy = 0;
      for (int c = start_[u]; c < start_[u + 1]; ++c) {
        const V2& q = face_gradients[std::size_t(corner_[c] / 3)][std::size_t(corner_[c] % 3)];
        gx += q.x(), gy += q.y();
      }
      g(Eigen::Index(u), 0) = gx, g(Eigen::Index(u), 1) = gy;
    }
  });
  return g;
}

}  // namespace cf::flat_detail
