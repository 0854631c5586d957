#pragma once
// The local area balancing's energy (area_balance.cpp): the symmetric Dirichlet energy of a set of
// faces, in the interface proxy_descent.h asks of an Energy (with the fused energy_and_gradients).
// Every per-face loop runs in fixed blocks (face_blocks.h).
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "face_blocks.h"
#include "flatten_internal.h"

namespace cf::flat_detail {

// Each 3D triangle in its own plane (2D, mm): corner 0 at the origin, corner 1 on +x.
inline std::vector<std::array<V2, 3>> plane_frames(const Surface& s, const std::vector<int>& faces) {
  std::vector<std::array<V2, 3>> X(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Tri& t = s.t[faces[i]];
    const V3 e1 = s.p[t[1]] - s.p[t[0]], e2 = s.p[t[2]] - s.p[t[0]];
    const double l1 = std::max(e1.norm(), 1e-12);
    const V3 ex = e1 / l1, ey = e1.cross(e2).cross(e1).normalized();
    X[i] = {V2::Zero(), V2(l1, 0), V2(e2.dot(ex), std::isfinite(e2.dot(ey)) ? e2.dot(ey) : 0.0)};
  }
  return X;
}

// Symmetric Dirichlet energy sum_f A3_f (|J|^2 + |J^-1|^2) of the region's faces (Smith &
// Schaefer 2015; infinite for a folded face), with J the 3D -> 2D Jacobian of each face.
struct SymmetricDirichlet {
  const Surface& s;
  const Embedding& emb;
  const std::vector<int>& faces_;
  std::vector<Eigen::Matrix2d> x_inv;  // inverse of the 3D triangle's edge matrix in its plane
  std::vector<double> area3;

  const std::vector<int>& faces() const { return faces_; }
  Eigen::Matrix2d jacobian(const std::vector<V2>& pos, std::size_t i) const {
    const int f = faces_[i];
    Eigen::Matrix2d D;
    const auto c = shifted_corners(s.t[f], pos, emb.dy[f]);  // shifted_corner.h: the same bits
    D.col(0) = c[1] - c[0];
    D.col(1) = c[2] - c[0];
    return D * x_inv[i];
  }
  double energy(const std::vector<V2>& pos) const { return energy_with(pos, nullptr); }
  // Per face, the gradient with respect to each corner.
  void face_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& out) const {
    for_each_block(faces_.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) face_gradient(i, jacobian(pos, i), out[i]);
    });
  }
  // energy(pos) and, when it is below kHuge, face_gradients(pos, out), the same bits as each alone,
  // from one Jacobian a face (proxy_descent.h's fused line search).
  double energy_and_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& out) const {
    return energy_with(pos, &out);
  }
  // The energy, and each face's corner gradients into *out when out is given (one Jacobian a face).
  double energy_with(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>* out) const {
    const double e = block_sum(faces_.size(), [&](std::size_t begin, std::size_t end) {
      double part = 0;
      for (std::size_t i = begin; i < end; ++i) {
        const Eigen::Matrix2d J = jacobian(pos, i);
        const double det = J.determinant();
        if (det <= 0) return kHuge;
        part += area3[i] * J.squaredNorm() * (1 + 1 / (det * det));
        if (out) face_gradient(i, J, (*out)[i]);
      }
      return part;
    });
    return e >= kHuge ? kHuge : e;
  }
  // Face i's corner gradients from its Jacobian J.
  void face_gradient(std::size_t i, const Eigen::Matrix2d& J, std::array<V2, 3>& out) const {
    const double det = J.determinant(), n2 = J.squaredNorm();
    const Eigen::Matrix2d dJ = 2 * J * (1 + 1 / (det * det)) - 2 * n2 / (det * det) * J.inverse().transpose();
    const Eigen::Matrix2d G = area3[i] * dJ * x_inv[i].transpose();
    out = {V2(-(G.col(0) + G.col(1))), V2(G.col(0)), V2(G.col(1))};
  }
  static constexpr double kHuge = 1e300;
};

inline SymmetricDirichlet make_energy(const Surface& s, const Embedding& emb, const std::vector<int>& faces) {
  SymmetricDirichlet sd{s, emb, faces, {}, {}};  // `faces`: the region's faces that are not folded
  const std::vector<std::array<V2, 3>> X = plane_frames(s, faces);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    Eigen::Matrix2d M;
    M.col(0) = X[i][1] - X[i][0];
    M.col(1) = X[i][2] - X[i][0];
    const double det = M.determinant();
    sd.x_inv.push_back(std::abs(det) > 1e-300 ? Eigen::Matrix2d(M.inverse()) : Eigen::Matrix2d::Identity());
    sd.area3.push_back(0.5 * std::abs(det));
  }
  return sd;
}

}  // namespace cf::flat_detail
