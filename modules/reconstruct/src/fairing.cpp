// Constrained fairing: the smoothest surface within half a voxel of the staircase (fairing.h).
#include "fairing.h"

#include <Eigen/Geometry>
#include <vtkSMPTools.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "colonflat/core/error.h"
#include "colonflat/core/vertex_graph.h"

namespace cf::reconstruct_detail {
namespace {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

Points to_points(const std::vector<std::array<double, 3>>& p) {
  Points x(Eigen::Index(p.size()), 3);
  for (std::size_t i = 0; i < p.size(); ++i) x.row(Eigen::Index(i)) = Eigen::RowVector3d(p[i][0], p[i][1], p[i][2]);
  return x;
}

// The state of one fairing: the vertex graph, the anchors (staircase positions) and the constraint.
class ConstrainedFairing {
 public:
  // start: the surface's points (#P x 3), whose cotangent weights the energy keeps.
  ConstrainedFairing(const TriangleList& surface, const Points& start, Points anchors,
                     const Eigen::Matrix3d& lps_to_index, double radius)
      : to_index_(lps_to_index), radius_(radius), anchors_(std::move(anchors)) {
    build_graph(surface);
    cotangent_weights(surface.triangles, start);
  }

  // x (#P x 3): the start (within the radius of the anchors) and the result.
  FairingResult run(int iterations, Points& x) {
    FairingResult result;
    const Points start = x;
    result.energy_before = energy(x);
    accelerated_descent(x, iterations, 1.0 / (1.05 * largest_eigenvalue()));
    result.energy_after = energy(x);
    if (!(result.energy_after <= result.energy_before)) {  // never worse than the start
      x = start;
      result.energy_after = result.energy_before;
    }
    result.iterations = iterations;
    result.vertices_at_limit = count_at_limit(x);
    return result;
  }

 private:
  void build_graph(const TriangleList& surface) {
    VertexGraph g = vertex_graph(surface);
    start_ = std::move(g.start);
    neighbours_ = std::move(g.neighbours);
    rim_ = std::move(g.on_boundary);
  }

  // weight_[k] for the k-th CSR entry: the cotangent weight of the edge on the start surface,
  // clamped to [0, 10], normalised per row so that U(x)_i is a weighted mean minus x_i. Cotangent
  // weights have linear precision (a plane's Laplacian is 0 however it is triangulated); the clamp
  // keeps that wherever no weight is negative.
  void cotangent_weights(const std::vector<std::array<int, 3>>& triangles, const Points& x) {
    weight_.assign(neighbours_.size(), 0.0);
    auto entry = [&](int i, int j) -> double& {
      const auto first = neighbours_.begin() + std::ptrdiff_t(start_[std::size_t(i)]);
      const auto last = neighbours_.begin() + std::ptrdiff_t(start_[std::size_t(i) + 1]);
      return weight_[std::size_t(std::lower_bound(first, last, j) - neighbours_.begin())];
    };
    for (const auto& t : triangles)
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d u = (x.row(t[(k + 1) % 3]) - x.row(t[k])).transpose();
        const Eigen::Vector3d v = (x.row(t[(k + 2) % 3]) - x.row(t[k])).transpose();
        const double sine = u.cross(v).norm(), cot = sine > 0 ? u.dot(v) / sine : 0.0;
        entry(t[(k + 1) % 3], t[(k + 2) % 3]) += 0.5 * cot;
        entry(t[(k + 2) % 3], t[(k + 1) % 3]) += 0.5 * cot;
      }
    for (std::size_t i = 0; i + 1 < start_.size(); ++i) {
      double row_weight = 0;
      for (auto k = std::size_t(start_[i]); k < std::size_t(start_[i + 1]); ++k) weight_[k] = std::clamp(weight_[k], 0.0, 10.0);
      for (auto k = std::size_t(start_[i]); k < std::size_t(start_[i + 1]); ++k) row_weight += weight_[k];
      for (auto k = std::size_t(start_[i]); k < std::size_t(start_[i + 1]); ++k)
        weight_[k] = row_weight > 0 ? weight_[k] / row_weight : 1.0 / double(start_[i + 1] - start_[i]);
    }
    // transpose weights: for entry k = (i, j), the weight of (j, i) in row j
    weight_t_.resize(weight_.size());
    for (std::size_t i = 0; i + 1 < start_.size(); ++i)
      for (auto k = std::size_t(start_[i]); k < std::size_t(start_[i + 1]); ++k) weight_t_[k] = entry(neighbours_[k], int(i));
  }

  // out_i = weighted mean of the neighbours of i - x_i; 0 on the rim of an open surface (no
  // bending is measured there, so a rim vertex is pulled by its neighbours' terms only).
  void umbrella(const Points& x, Points& out) const {
    out.resize(x.rows(), 3);
    vtkSMPTools::For(0, vtkIdType(start_.size() - 1), kGrain, [&](vtkIdType first, vtkIdType last) {
      for (auto i = std::size_t(first); i < std::size_t(last); ++i) {
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        for (auto k = std::size_t(start_[i]); k < std::size_t(start_[i + 1]); ++k) sum += weight_[k] * x.row(neighbours_[k]);
        out.row(Eigen::Index(i)) = rim_[i] ? Eigen::RowVector3d::Zero() : Eigen::RowVector3d(sum - x.row(Eigen::Index(i)));
      }
    });
  }

  // out = U^T r: (U^T r)_j = -r_j + sum over neighbours i of j of w_ij r_i (w_ij: row i's weight of j).
  void umbrella_transpose(const Points& r, Points& out) const {
    out.resize(r.rows(), 3);
    vtkSMPTools::For(0, vtkIdType(start_.size() - 1), kGrain, [&](vtkIdType first, vtkIdType last) {
      for (auto j = std::size_t(first); j < std::size_t(last); ++j) {
        Eigen::RowVector3d sum = -r.row(Eigen::Index(j));
        for (auto k = std::size_t(start_[j]); k < std::size_t(start_[j + 1]); ++k) sum += weight_t_[k] * r.row(neighbours_[k]);
        out.row(Eigen::Index(j)) = sum;
      }
    });
  }

  double energy(const Points& x) {
    umbrella(x, residual_);
    return 0.5 * residual_.squaredNorm();
  }

  // The gradient of E at x: U^T U x.
  void gradient(const Points& x, Points& out) {
    umbrella(x, residual_);
    umbrella_transpose(residual_, out);
  }

  // Power iterations for the largest eigenvalue of U^T U (the gradient's Lipschitz constant).
  double largest_eigenvalue() {
    Points v(anchors_.rows(), 3), w;
    for (Eigen::Index i = 0; i < v.rows(); ++i)  // a deterministic, rough start vector
      v.row(i) = Eigen::RowVector3d(double((i * 7919) % 997) / 997.0 - 0.5, double((i * 104729) % 991) / 991.0 - 0.5,
                                    double((i * 1299709) % 983) / 983.0 - 0.5);
    double lambda = 4.0;
    for (int it = 0; it < 20 && v.squaredNorm() > 0; ++it) {
      v /= v.norm();
      gradient(v, w);
      lambda = w.norm();
      std::swap(v, w);
    }
    return std::max(lambda, 1e-12);
  }

  // FISTA with gradient-based adaptive restart (O'Donoghue & Candes 2015).
  void accelerated_descent(Points& x, int iterations, double step) {
    Points y = x, g, next;
    double t = 1.0;
    for (int it = 0; it < iterations; ++it) {
      gradient(y, g);
      next = y - step * g;
      project(next);
      const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
      if (((y - next).cwiseProduct(next - x)).sum() > 0) {  // momentum points uphill: restart
        y = next;
        t = 1.0;
      } else {
        y = next + ((t - 1.0) / t_next) * (next - x);
        t = t_next;
      }
      std::swap(x, next);
    }
  }

  // Each vertex's offset from its anchor scaled back to |M d| <= radius.
  void project(Points& x) const {
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const Eigen::Vector3d offset = (x.row(i) - anchors_.row(i)).transpose();
      const double voxels = (to_index_ * offset).norm();
      if (voxels > radius_) x.row(i) = anchors_.row(i) + (offset * (radius_ / voxels)).transpose();
    }
  }

  std::size_t count_at_limit(const Points& x) const {
    std::size_t count = 0;
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      count += (to_index_ * (x.row(i) - anchors_.row(i)).transpose()).norm() >= radius_ * (1 - 1e-3);
    return count;
  }

  static constexpr vtkIdType kGrain = 16384;  // vertices per parallel chunk (vtkSMPTools)
  Eigen::Matrix3d to_index_;
  double radius_;
  std::vector<int> start_;
  std::vector<int> neighbours_;
  std::vector<char> rim_;
  std::vector<double> weight_, weight_t_;
  Points anchors_, residual_;
};

}  // namespace

FairingResult fair_within_tolerance(TriangleList& surface, const std::vector<std::array<double, 3>>& anchors,
                                    const Eigen::Matrix3d& lps_to_index, const FairingOptions& options) {
  if (anchors.size() != surface.points.size())
    throw Error("fairing: " + std::to_string(anchors.size()) + " anchors for " + std::to_string(surface.points.size()) +
                " points");
  if (options.iterations <= 0 || surface.points.empty()) return {};
  Points x = to_points(surface.points);
  ConstrainedFairing fairing(surface, x, to_points(anchors), lps_to_index, options.radius_voxels);
  const FairingResult result = fairing.run(options.iterations, x);
  for (std::size_t i = 0; i < surface.points.size(); ++i)
    for (int a = 0; a < 3; ++a) surface.points[i][std::size_t(a)] = x(Eigen::Index(i), a);
  return result;
}

}  // namespace cf::reconstruct_detail
