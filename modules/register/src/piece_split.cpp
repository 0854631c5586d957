#include "piece_split.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf {
namespace {

// Correlation of x and y over [a, b).
double correlation(const std::vector<double>& x, const std::vector<double>& y, size_t a, size_t b) {
  const double n = double(b - a);
  double mx = 0, my = 0;
  for (size_t i = a; i < b; ++i) mx += x[i] / n, my += y[i] / n;
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = a; i < b; ++i) sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx), syy += (y[i] - my) * (y[i] - my);
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
}

}  // namespace

double reversal_cut_mm(const std::vector<double>& local, const std::vector<double>& sref, double min_run_mm) {
  constexpr double kMonotone = 0.9;  // each side clearly runs one way (a wiggle or a loop alongside does not)
  double best = 0, cut = std::numeric_limits<double>::quiet_NaN();
  const size_t n = local.size();
  for (size_t i = 1; i + 1 < n; ++i) {
    if (local[i] - local.front() < min_run_mm || local.back() - local[i] < min_run_mm) continue;
    const double a = correlation(local, sref, 0, i), b = correlation(local, sref, i, n);
    const double clear = std::min(std::abs(a), std::abs(b));
    if (a * b < 0 && clear >= kMonotone && clear > best) best = clear, cut = 0.5 * (local[i - 1] + local[i]);
  }
  return cut;
}

std::vector<ColonPiece> split_piece(const ColonPiece& p, double cut_mm) {
  const size_t k = std::clamp(size_t(std::lround(cut_mm / p.bin_mm)), size_t(1), p.centre.size() - 1);
  ColonPiece a = p, b = p;
  a.centre.assign(p.centre.begin(), p.centre.begin() + long(k));
  b.centre.assign(p.centre.begin() + long(k), p.centre.end());
  a.length_mm = double(k) * p.bin_mm, b.length_mm = p.length_mm - a.length_mm;
  b.from_mm = p.from_mm + a.length_mm;
  a.x1_end.clear(), b.x0_end.clear();
  a.s_bin.clear(), b.s_bin.clear(), a.on_branch.clear(), b.on_branch.clear();
  return {a, b};
}

const ColonPiece* piece_at(const std::multimap<int, const ColonPiece*>& by_segment, int seg, double c) {
  const ColonPiece* found = nullptr;
  for (auto [it, end] = by_segment.equal_range(seg); it != end; ++it)
    if (const ColonPiece* p = it->second; !found || (p->from_mm <= c && (found->from_mm > c || p->from_mm > found->from_mm)))
      found = p;
  return found;
}

// A colon does not run back along itself: of the bins with an offset, keep the largest set whose common s
// (offset + own mm) runs forward along the piece's direction (longest monotone subsequence), the others
// (a few bins projecting onto a neighbouring loop) lose their offset and are interpolated over.
void keep_forward_run(std::vector<double>& offset, bool flipped, double bin_mm) {
  std::vector<int> at;
  std::vector<double> v;
  for (size_t k = 0; k < offset.size(); ++k)
    if (!std::isnan(offset[k])) at.push_back(int(k)), v.push_back((flipped ? -1 : 1) * (offset[k] + (flipped ? -1 : 1) * (double(k) + 0.5) * bin_mm));
  const size_t m = v.size();
  std::vector<int> len(m, 1), prev(m, -1);
  int best = -1;
  for (size_t i = 0; i < m; ++i) {
    for (size_t j = 0; j < i; ++j)
      if (v[j] <= v[i] && len[j] + 1 > len[i]) len[i] = len[j] + 1, prev[i] = int(j);
    if (best < 0 || len[i] > len[size_t(best)]) best = int(i);
  }
  std::vector<char> keep(m, 0);
  for (int i = best; i >= 0; i = prev[size_t(i)]) keep[size_t(i)] = 1;
  for (size_t i = 0; i < m; ++i)
    if (!keep[i]) offset[size_t(at[i])] = std::numeric_limits<double>::quiet_NaN();
}

bool lay_along_branch(ColonPiece& piece, const std::vector<int>& ref_piece, const std::vector<ColonPiece>& ref,
                      const Eigen::Vector3d& shift, double reach_mm) {
  if (!piece.registered || ref_piece.empty() || piece.centre.empty()) return false;
  const int b = ref_piece.front();
  if (b < 0 || size_t(b) >= ref.size() || !ref[size_t(b)].branch) return false;
  for (int r : ref_piece)
    if (r != b) return false;
  const ColonPiece& br = ref[size_t(b)];
  const Eigen::Vector3d& neck = br.flipped ? br.centre.back() : br.centre.front();  // its s: br.start_mm
  const Eigen::Vector3d& tip = br.flipped ? br.centre.front() : br.centre.back();   // its s: br.start_mm + length
  const Eigen::Vector3d low = (piece.flipped ? piece.centre.back() : piece.centre.front()) + shift;
  const Eigen::Vector3d high = (piece.flipped ? piece.centre.front() : piece.centre.back()) + shift;
  if ((low - neck).norm() > reach_mm || (high - tip).norm() > reach_mm) return false;
  const double scale = br.length_mm / piece.length_mm;
  piece.s_bin.resize(piece.centre.size());
  for (size_t k = 0; k < piece.centre.size(); ++k) {
    const double own = (double(k) + 0.5) * piece.bin_mm;
    piece.s_bin[k] = br.start_mm + (piece.flipped ? piece.length_mm - own : own) * scale;
  }
  piece.start_mm = br.start_mm;  // s of its x0 end (flipped: of its x1 end), as place() sets it
  return true;
}

}  // namespace cf
