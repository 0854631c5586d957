#include "colonflat/register/align.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>

namespace cf {
namespace {

constexpr double kInfCost = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 6.283185307179586;

// Z-score over the bins that hold wall (`count` > 0); empty bins get 0.
std::vector<double> zscore(std::vector<double> v, const std::vector<int>& count) {
  double mean = 0, sq = 0, n = 0;
  for (size_t k = 0; k < v.size(); ++k)
    if (count[k] > 0) mean += v[k], n += 1;
  mean /= std::max(1.0, n);
  for (size_t k = 0; k < v.size(); ++k)
    if (count[k] > 0) sq += (v[k] - mean) * (v[k] - mean);
  const double sd = std::sqrt(sq / std::max(1.0, n));
  for (size_t k = 0; k < v.size(); ++k) v[k] = sd > 1e-12 && count[k] > 0 ? (v[k] - mean) / sd : 0.0;
  return v;
}

// Weighted, z-scored features per bin: [fold, smoothed calibre, curvature].
std::vector<std::array<double, 3>> features(const LengthProfile& p, const AlignOptions& o) {
  const auto fold = zscore(p.fold, p.count);
  const auto calibre = zscore(gaussian_smooth(p.radius, 10.0 / p.bin_mm), p.count);
  const auto curv = zscore(gaussian_smooth(p.curvature, 5.0 / p.bin_mm), p.count);
  std::vector<std::array<double, 3>> f(fold.size());
  for (size_t k = 0; k < f.size(); ++k)
    f[k] = {std::sqrt(o.fold_weight) * fold[k], std::sqrt(o.calibre_weight) * calibre[k],
            std::sqrt(o.curvature_weight) * curv[k]};
  return f;
}

double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front() + (at - x.front());
  if (at >= x.back()) return y.back() + (at - x.back());
  const size_t k = size_t(std::upper_bound(x.begin(), x.end(), at) - x.begin());
  const double w = (at - x[k - 1]) / (x[k] - x[k - 1]);
  return (1 - w) * y[k - 1] + w * y[k];
}

// Smooths the path's B positions per A bin and makes them strictly increasing.
LengthAlignment knots_from_path(const std::vector<double>& mean_j, double bin_a, double bin_b, double smooth_mm) {
  LengthAlignment out;
  const auto smooth = gaussian_smooth(mean_j, smooth_mm / bin_a);
  for (size_t i = 0; i < smooth.size(); ++i) {
    out.a_mm.push_back((double(i) + 0.5) * bin_a);
    double b = (smooth[i] + 0.5) * bin_b;
    if (!out.b_mm.empty()) b = std::max(b, out.b_mm.back() + 1e-3 * bin_b);
    out.b_mm.push_back(b);
  }
  return out;
}

}  // namespace

double LengthAlignment::a_to_b(double s) const { return interpolate(a_mm, b_mm, s); }
double LengthAlignment::b_to_a(double s) const { return interpolate(b_mm, a_mm, s); }

LengthProfile reversed_profile(const LengthProfile& p) {
  LengthProfile r = p;
  std::reverse(r.centre.begin(), r.centre.end());
  std::reverse(r.tangent.begin(), r.tangent.end());
  for (auto& t : r.tangent) t = -t;
  std::reverse(r.reference.begin(), r.reference.end());
  for (auto* v : {&r.radius, &r.curvature, &r.fold}) std::reverse(v->begin(), v->end());
  std::reverse(r.count.begin(), r.count.end());
  return r;
}

namespace {

// Cost of pairing bin i of A with bin j of B: feature distance, the distance of the two centre
// lines (capped: beyond it every mismatch is as bad), a bin without wall in either scan a fixed
// cost (nothing to compare: the path crosses it at the cost of an unsupported stretch), the
// proportional prior, and anchors (a row of an anchor is open only within its tolerance).
class LocalCost {
 public:
  LocalCost(const LengthProfile& a, const LengthProfile& b, const AlignOptions& o, const AlignContext& ctx)
      : a_(a), b_(b), o_(o), ctx_(ctx), fa_(features(a, o)), fb_(features(b, o)) {
    na_ = int(fa_.size()), nb_ = int(fb_.size());
    ratio_ = double(nb_ - 1) / double(std::max(1, na_ - 1));
    band_ = std::max(o.band_mm / b.bin_mm, 2.0 + std::abs(nb_ - na_ * ratio_));
    anchor_.assign(size_t(na_), {-1, 0});
    double last_b = -1;
    for (const auto& an : ctx.anchors) {  // sorted by a; an anchor out of order with the previous is dropped
      if (an.b_mm <= last_b) continue;
      last_b = an.b_mm;
      anchor_[size_t(a.bin_of(an.a_mm))] = {b.bin_of(an.b_mm), std::max(1, int(std::ceil(an.tolerance_mm / b.bin_mm)))};
    }
  }
  int na() const { return na_; }
  int nb() const { return nb_; }
  int lo(int i) const { return std::max(0, int(std::floor(i * ratio_ - band_))); }
  int hi(int i) const { return std::min(nb_ - 1, int(std::ceil(i * ratio_ + band_))); }
  double operator()(int i, int j) const {
    const double off = (j - i * ratio_) / band_;
    double d = o_.prior_weight * off * off;
    if (const auto& [aj, tol] = anchor_[size_t(i)]; aj >= 0 && std::abs(j - aj) > tol) d += 1e6;
    if (ctx_.use_position && (a_.count[size_t(i)] == 0 || b_.count[size_t(j)] == 0)) return d + o_.empty_cost;
    for (int c = 0; c < 3; ++c) d += (fa_[size_t(i)][c] - fb_[size_t(j)][c]) * (fa_[size_t(i)][c] - fb_[size_t(j)][c]);
    if (ctx_.use_position) {
      const double e = (a_.centre[size_t(i)] - b_.centre[size_t(j)] - ctx_.b_to_a).norm() / o_.position_sigma_mm;
      d += o_.position_weight * std::min(e * e, o_.position_cap);
    }
    return d;
  }

 private:
  const LengthProfile &a_, &b_;
  const AlignOptions& o_;
  const AlignContext& ctx_;
  std::vector<std::array<double, 3>> fa_, fb_;
  std::vector<std::pair<int, int>> anchor_;  // per A bin: (B bin, tolerance in bins), -1 = none
  int na_ = 0, nb_ = 0;
  double ratio_ = 1, band_ = 1;
};

}  // namespace

LengthAlignment align_length(const LengthProfile& a, const LengthProfile& b, const AlignOptions& o,
                             const AlignContext& ctx) {
  const LocalCost local(a, b, o, ctx);
  const int na = local.na(), nb = local.nb();
  std::vector<double> cost(size_t(na) * size_t(nb), kInfCost);
  std::vector<std::uint8_t> step(cost.size(), 0);
  auto at = [&](int i, int j) -> double& { return cost[size_t(i) * size_t(nb) + size_t(j)]; };
  for (int i = 0; i < na; ++i) {
    for (int j = local.lo(i); j <= local.hi(i); ++j) {
      const double d = local(i, j);
      if (i == 0 && j == 0) { at(i, j) = d; continue; }
      double best = kInfCost;
      std::uint8_t s = 0;
      if (i > 0 && j > 0 && at(i - 1, j - 1) + 2 * d < best) best = at(i - 1, j - 1) + 2 * d, s = 1;
      if (i > 0 && at(i - 1, j) + d < best) best = at(i - 1, j) + d, s = 2;
      if (j > 0 && at(i, j - 1) + d < best) best = at(i, j - 1) + d, s = 3;
      at(i, j) = best;
      step[size_t(i) * size_t(nb) + size_t(j)] = s;
    }
  }
  std::vector<double> sum_j(size_t(na), 0.0), n_j(size_t(na), 0.0);
  for (int i = na - 1, j = nb - 1;;) {
    sum_j[size_t(i)] += j, n_j[size_t(i)] += 1;
    const std::uint8_t s = step[size_t(i) * size_t(nb) + size_t(j)];
    if (s == 0) break;
    if (s != 3) --i;
    if (s != 2) --j;
  }
  for (int i = 0; i < na; ++i) sum_j[size_t(i)] /= std::max(1.0, n_j[size_t(i)]);
  LengthAlignment out = knots_from_path(sum_j, a.bin_mm, b.bin_mm, o.warp_smooth_mm);
  out.cost = at(na - 1, nb - 1) / double(na + nb);
  return out;
}

namespace {

constexpr double kRowMm = 4.0;  // along-colon row height of the relief patches

// Relief patch of the samples with s in [lo, hi): rows of kRowMm (row of a sample = `row_of(s)`),
// `bins` angle columns; each row minus its mean; NaN where a cell has no sample.
std::vector<double> relief(const ScanCoordinates& c, const std::vector<int>& order, double lo, double hi, int rows,
                           int bins, const std::function<double(double)>& row_of) {
  std::vector<double> sum(size_t(rows * bins), 0.0), n(sum.size(), 0.0);
  auto first = std::lower_bound(order.begin(), order.end(), lo, [&](int v, double x) { return c.s[size_t(v)] < x; });
  for (auto it = first; it != order.end() && c.s[size_t(*it)] < hi; ++it) {
    const int r = std::clamp(int(row_of(c.s[size_t(*it)])), 0, rows - 1);
    const int k = std::min(bins - 1, int(c.theta[size_t(*it)] / kTwoPi * bins));
    sum[size_t(r * bins + k)] += c.radial[size_t(*it)], n[size_t(r * bins + k)] += 1;
  }
  for (int r = 0; r < rows; ++r) {
    double mean = 0, used = 0;
    for (int k = 0; k < bins; ++k) {
      const size_t i = size_t(r * bins + k);
      sum[i] = n[i] > 0 ? sum[i] / n[i] : std::numeric_limits<double>::quiet_NaN();
      if (n[i] > 0) mean += sum[i], used += 1;
    }
    for (int k = 0; k < bins; ++k) sum[size_t(r * bins + k)] -= used > 0 ? mean / used : 0.0;
  }
  return sum;
}

std::vector<int> sorted_by_s(const ScanCoordinates& c) {
  std::vector<int> order;
  for (size_t v = 0; v < c.s.size(); ++v)
    if (!std::isnan(c.s[v])) order.push_back(int(v));
  std::sort(order.begin(), order.end(), [&](int x, int y) { return c.s[size_t(x)] < c.s[size_t(y)]; });
  return order;
}

// Best circular column shift (rad) of patch hb against ha within +-max bins, and its Pearson
// correlation over the cells present in both.
std::pair<double, double> best_shift(const std::vector<double>& ha, const std::vector<double>& hb, int rows, int bins,
                                     int max_shift) {
  double best = -2, best_m = 0;
  for (int m = -max_shift; m <= max_shift; ++m) {
    double dot = 0, na = 0, nb = 0;
    for (int r = 0; r < rows; ++r)
      for (int k = 0; k < bins; ++k) {
        const double a = ha[size_t(r * bins + k)], b = hb[size_t(r * bins + ((k + m) % bins + bins) % bins)];
        if (std::isnan(a) || std::isnan(b)) continue;
        dot += a * b, na += a * a, nb += b * b;
      }
    const double corr = na > 1e-9 && nb > 1e-9 ? dot / std::sqrt(na * nb) : 0.0;
    if (corr > best) best = corr, best_m = m;
  }
  return {best_m * kTwoPi / bins, best};
}

}  // namespace

std::vector<double> estimate_twist(const ScanCoordinates& a, const ScanCoordinates& b, const LengthAlignment& length,
                                   const TwistOptions& o, int* windows_used) {
  const LengthProfile& pa = a.profile;
  std::vector<double> twist(size_t(pa.bins()), 0.0);
  if (windows_used) *windows_used = 0;
  if (o.max_twist_deg <= 0) return twist;
  const auto order_a = sorted_by_s(a), order_b = sorted_by_s(b);
  const int max_shift = int(std::round(o.max_twist_deg / 360.0 * o.angle_bins));
  std::vector<double> at_s, value;
  for (double lo = 0; lo + 0.5 * o.window_mm < pa.length_mm(); lo += 0.5 * o.window_mm) {
    const double hi = lo + o.window_mm;
    const int rows = std::max(1, int(std::ceil(o.window_mm / kRowMm)));
    const auto ha = relief(a, order_a, lo, hi, rows, o.angle_bins, [&](double s) { return (s - lo) / kRowMm; });
    const auto hb = relief(b, order_b, length.a_to_b(lo), length.a_to_b(hi), rows, o.angle_bins,
                           [&](double s) { return (length.b_to_a(s) - lo) / kRowMm; });
    const auto [shift, r] = best_shift(ha, hb, rows, o.angle_bins, max_shift);
    if (r < o.min_correlation) continue;
    at_s.push_back(0.5 * (lo + hi));
    value.push_back(shift);
  }
  if (windows_used) *windows_used = int(at_s.size());
  if (at_s.empty()) return twist;
  for (int k = 0; k < pa.bins(); ++k) {
    const double s = (k + 0.5) * pa.bin_mm;
    if (at_s.size() == 1 || s <= at_s.front()) twist[size_t(k)] = value.front();
    else if (s >= at_s.back()) twist[size_t(k)] = value.back();
    else {
      const size_t i = size_t(std::upper_bound(at_s.begin(), at_s.end(), s) - at_s.begin());
      const double w = (s - at_s[i - 1]) / (at_s[i] - at_s[i - 1]);
      twist[size_t(k)] = (1 - w) * value[i - 1] + w * value[i];
    }
  }
  return gaussian_smooth(twist, 0.25 * o.window_mm / pa.bin_mm);
}

}  // namespace cf
