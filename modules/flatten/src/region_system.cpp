// Sparse quadratic solves on a region of the periodic-cylinder embedding (Tutte untangling and
// the ARAP global step), the rest of the map fixed.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>

#include "colonflat/core/bucket_slots.h"
#include "colonflat/core/threads.h"
#include "flatten_internal.h"
#include "proxy_descent.h"
#include "spd_solver.h"

namespace cf::flat_detail {

struct RegionSystem::Impl {
  SpdSolver solver;
};

namespace {

// Column j's entries (rows `row`, values `value`, m of them, in face order) sorted by row, stably
// (insertion sort: a column holds a few entries), and the entries of one row summed in face order
// (((v1 + v2) + v3): as Eigen's setFromTriplets summed duplicates); returns how many rows remain.
int sort_and_merge(int* row, double* value, int m) {
  for (int x = 1; x < m; ++x) {
    const int r = row[x];
    const double v = value[x];
    int y = x;
    for (; y > 0 && row[y - 1] > r; --y) row[y] = row[y - 1], value[y] = value[y - 1];
    row[y] = r, value[y] = v;
  }
  int u = 0;
  for (int x = 0; x < m; ++x) {
    if (u > 0 && row[u - 1] == row[x]) value[u - 1] += value[x];
    else row[u] = row[x], value[u] = value[x], ++u;
  }
  return u;
}

}  // namespace

// Each face's three terms in face order, bucketed by column (counting pass, then filling pass);
// the columns then sorted, merged and copied on the worker threads (each column its own: the same
// bits for any thread count).
Eigen::SparseMatrix<double> region_lower(const Surface& s, const std::vector<int>& faces,
                                         const std::vector<std::array<double, 3>>& w, const std::vector<int>& index, int n) {
  std::vector<double> diagonal(std::size_t(n), 0.0);
  BucketSlots<int> slots{std::size_t(n)};  // entries below the diagonal per column, repeats included
  const auto each_term = [&](auto&& term) {
    for (std::size_t i = 0; i < faces.size(); ++i) {
      const Tri& t = s.t[std::size_t(faces[i])];
      for (int k = 0; k < 3; ++k) term(index[std::size_t(t[(k + 1) % 3])], index[std::size_t(t[(k + 2) % 3])], w[i][k]);
    }
  };
  each_term([&](int a, int b, double wk) {
    if (a >= 0) diagonal[std::size_t(a)] += wk;
    if (b >= 0) diagonal[std::size_t(b)] += wk;
    if (a >= 0 && b >= 0) slots.count(std::size_t(std::min(a, b)));
  });
  slots.close();
  const std::vector<int>& start = slots.starts();
  std::vector<int> row(std::size_t(slots.total()));
  std::vector<double> value(row.size());
  each_term([&](int a, int b, double wk) {
    if (a < 0 || b < 0) return;
    const int p = slots.place(std::size_t(std::min(a, b)));
    row[std::size_t(p)] = std::max(a, b), value[std::size_t(p)] = -wk;
  });
  std::vector<int> kept(static_cast<std::size_t>(n), 0);
  parallel_for(std::size_t(n), [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j)
      kept[j] = sort_and_merge(row.data() + start[j], value.data() + start[j], start[j + 1] - start[j]);
  });
  Eigen::SparseMatrix<double> A(n, n);
  int* outer = A.outerIndexPtr();
  outer[0] = 0;
  for (int j = 0; j < n; ++j) outer[j + 1] = outer[j] + 1 + kept[std::size_t(j)];
  A.resizeNonZeros(outer[n]);
  parallel_for(std::size_t(n), [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const int o = A.outerIndexPtr()[j];
      A.innerIndexPtr()[o] = int(j), A.valuePtr()[o] = diagonal[j];
      std::copy_n(row.data() + start[j], kept[j], A.innerIndexPtr() + o + 1);
      std::copy_n(value.data() + start[j], kept[j], A.valuePtr() + o + 1);
    }
  });
  return A;
}

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
  const Eigen::SparseMatrix<double> A = region_lower(s, faces_, w_, index_, n);
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
      const V2 g = unshifted_corner(target[i][k], emb.dy[f][ka] - emb.dy[f][kb]);  // shifted_corner.h: same bits
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
  BucketSlots<int> slots(n);
  for (int f : faces)
    for (int v : s.t[f])
      if (sys.index(v) >= 0) slots.count(std::size_t(sys.index(v)));
  slots.close();
  corner_.resize(std::size_t(slots.total()));
  for (std::size_t i = 0; i < faces.size(); ++i)  // face order: each unknown's corners come in face order
    for (int k = 0; k < 3; ++k)
      if (const int u = sys.index(s.t[faces[i]][k]); u >= 0) corner_[std::size_t(slots.place(std::size_t(u)))] = int(3 * i) + k;
  start_ = std::move(slots).take_starts();
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
