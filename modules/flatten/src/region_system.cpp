// Sparse quadratic solves on a region of the periodic-cylinder embedding (Tutte untangling and
// the ARAP global step), the rest of the map fixed.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>

#include "flatten_internal.h"
#include "spd_solver.h"

namespace cf::flat_detail {

struct RegionSystem::Impl {
  SpdSolver solver;
};

bool RegionSystem::build(const Surface& s, const std::vector<char>& free_vertex, const std::vector<int>& faces,
                         const std::vector<std::array<double, 3>>& w) {
  faces_ = faces;
  w_ = w;
  index_.assign(s.p.size(), -1);
  vars_.clear();
  for (int f : faces_)
    for (int v : s.t[f])
      if (free_vertex[v] && index_[v] < 0) index_[v] = int(vars_.size()), vars_.push_back(v);
  const int n = int(vars_.size());
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(12 * faces_.size());
  for (std::size_t i = 0; i < faces_.size(); ++i) {
    const Tri& t = s.t[faces_[i]];
    for (int k = 0; k < 3; ++k) {
      const int a = index_[t[(k + 1) % 3]], b = index_[t[(k + 2) % 3]];
      const double wk = w_[i][k];
      if (a >= 0) trip.emplace_back(a, a, wk);
      if (b >= 0) trip.emplace_back(b, b, wk);
      if (a >= 0 && b >= 0) trip.emplace_back(a, b, -wk), trip.emplace_back(b, a, -wk);
    }
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  impl_ = std::make_shared<Impl>();
  if (n == 0) return true;
  return impl_->solver.compute(A);
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

std::size_t untangle(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                     const std::vector<char>& fixed, const std::vector<char>& degenerate) {
  const int nv = int(s.p.size());
  std::vector<char> in(nv, 0);
  std::vector<int> region;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && too_small_in_map(emb.area2(s, int(f)), face_area_3d(s, int(f))))
      for (int v : s.t[f])
        if (!in[v]) in[v] = 1, region.push_back(v);
  if (region.empty()) return 0;
  for (int round = 0; round < 4; ++round) {
    for (int ring = 0; ring < (1 << round) && round > 0; ++ring) {  // grow 1, 2, 4, ... rings
      const std::size_t n0 = region.size();
      for (std::size_t k = 0; k < n0; ++k)
        for (int f : vf[region[k]])
          for (int v : s.t[f])
            if (!in[v]) in[v] = 1, region.push_back(v);
    }
    std::vector<char> free_vertex(nv, 0);
    for (int v : region) free_vertex[v] = !fixed[v];
    std::vector<int> faces;
    std::vector<char> seen(s.t.size(), 0);
    for (int v : region)
      if (free_vertex[v])
        for (int f : vf[v])
          if (!seen[f]) seen[f] = 1, faces.push_back(f);
    RegionSystem sys;  // Tutte: uniform weights, zero targets
    if (!sys.build(s, free_vertex, faces, std::vector<std::array<double, 3>>(faces.size(), {1.0, 1.0, 1.0}))) break;
    emb.pos = sys.solve(s, emb, std::vector<std::array<V2, 3>>(faces.size(), {V2::Zero(), V2::Zero(), V2::Zero()}));
    bool any = false;
    for (int f : faces)
      if (!degenerate[f] && too_small_in_map(emb.area2(s, f), face_area_3d(s, f))) any = true;
    if (!any) break;
  }
  return region.size();
}

}  // namespace cf::flat_detail
