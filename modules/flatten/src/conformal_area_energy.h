#pragma once
// The area correction's energy (area_correct.cpp) over a set of faces of the band:
//   E = sum_f sum_k w_fk |c_a - c_b|^2  +  lambda sum_f A3_f pen(log r_f)
// (the cotangent Dirichlet energy of the map's corners plus the squared log area ratio outside
// [lo, hi]; +infinity once a face folds), with its per-face corner gradients, in the interface
// proxy_descent.h asks of an Energy. Every per-face loop runs in fixed blocks (face_blocks.h).
#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "face_blocks.h"
#include "flatten_internal.h"
#include "quotient_bounds.h"

namespace cf::flat_detail {
namespace area_energy_detail {
inline double cross2(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace area_energy_detail

class ConformalAreaEnergy {
 public:
  // `scale`: 3D / 2D area of the whole band (ratios at the area-preserving scale).
  ConformalAreaEnergy(const Surface& s, const Embedding& emb, std::vector<int> faces, const std::vector<double>& area3,
                      double lo, double hi, double lambda, double scale)
      : s_(s), emb_(emb), faces_(std::move(faces)), area3_(area3), excess_(lo, hi),
        inside_(lo, hi, LogRatioExcess::kInsideMargin), lambda_(lambda), scale_(scale) {
    w_ = corner_weights(s, faces_);
  }
  const std::vector<std::array<double, 3>>& weights() const { return w_; }
  const std::vector<int>& faces() const { return faces_; }

  double energy(const std::vector<V2>& pos) const { return energy_with(pos, nullptr); }

  // Per face, the gradient with respect to each corner.
  void face_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& out) const {
    for_each_block(faces_.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const auto c = corners(pos, faces_[i]);
        const double a2 = 0.5 * area_energy_detail::cross2(c[1] - c[0], c[2] - c[0]);
        face_gradient(i, c, a2, excess(i, a2), out[i]);
      }
    });
  }

  // energy(pos) and, when it is below kHuge, face_gradients(pos, out) (the same bits as each alone),
  // from one read of each face's corners: the descent's line search asks it at each trial, so the
  // step it takes comes with the next step's gradients (proxy_descent.h).
  double energy_and_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& out) const {
    return energy_with(pos, &out);
  }
  // The energy, and each face's corner gradients into *out when out is given (one corner read a face).
  double energy_with(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>* out) const {
    const double e = block_sum(faces_.size(), [&](std::size_t begin, std::size_t end) {
      double part = 0;
      for (std::size_t i = begin; i < end; ++i) {
        const auto c = corners(pos, faces_[i]);
        const double a2 = 0.5 * area_energy_detail::cross2(c[1] - c[0], c[2] - c[0]);
        if (a2 <= 0) return kHuge;
        const double x = excess(i, a2);
        add_face_energy(i, c, x, part);
        if (out) face_gradient(i, c, a2, x, (*out)[i]);
      }
      return part;
    });
    return e >= kHuge ? kHuge : e;
  }
  static constexpr double kHuge = 1e300;

 private:
  // Face i's log area ratio outside [lo, hi] (a2: its signed map area): excess_(scale a2 / A3), +0
  // without the division when the ratio is surely inside excess_'s margins (quotient_bounds.h).
  double excess(std::size_t i, double a2) const {
    const double n = scale_ * a2, d = area3_[std::size_t(faces_[i])];
    return inside_(n, d) ? 0.0 : excess_(n / d);
  }
  // Face i's terms added to `part` one by one (the order energy() has always summed them in); x: excess().
  void add_face_energy(std::size_t i, const std::array<V2, 3>& c, double x, double& part) const {
    for (int k = 0; k < 3; ++k) part += w_[i][k] * (c[(k + 1) % 3] - c[(k + 2) % 3]).squaredNorm();
    part += lambda_ * area3_[std::size_t(faces_[i])] * x * x;
  }
  // Face i's corner gradients at corners c (a2: its signed map area, x: excess()).
  void face_gradient(std::size_t i, const std::array<V2, 3>& c, double a2, double x, std::array<V2, 3>& grad) const {
    const int f = faces_[i];
    // d(penalty)/d(a2): (lambda A3 2 x) / a2, not divided when x = 0 (quotient_bounds.h: the same bits)
    const double dpen = a2 > 0 ? quotient_of_zero(lambda_ * area3_[f] * 2 * x, a2) : 0.0;
    grad = {V2::Zero(), V2::Zero(), V2::Zero()};
    for (int k = 0; k < 3; ++k) {
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      const V2 e = 2 * w_[i][k] * (c[a] - c[b]);
      grad[a] += e, grad[b] -= e;
      grad[k] += dpen * 0.5 * V2(c[a].y() - c[b].y(), c[b].x() - c[a].x());  // d(a2)/d(c_k)
    }
  }
  std::array<V2, 3> corners(const std::vector<V2>& pos, int f) const {
    return shifted_corners(s_.t[f], pos, emb_.dy[f]);  // shifted_corner.h: the same bits, in registers
  }
  const Surface& s_;
  const Embedding& emb_;
  std::vector<int> faces_;
  const std::vector<double>& area3_;
  LogRatioExcess excess_;
  SurelyInside inside_;  // excess_'s inside test by products (quotient_bounds.h)
  double lambda_, scale_ = 1;
  std::vector<std::array<double, 3>> w_;
};

}  // namespace cf::flat_detail
