// The faces the whole-band area pass holds (see whole_band_stop.h).
#include "whole_band_stop.h"

#include <algorithm>
#include <cmath>

#include "face_blocks.h"

namespace cf::flat_detail {

double band_areas(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate, std::vector<double>& area3,
                  std::vector<double>& area2) {
  area3.resize(s.t.size()), area2.resize(s.t.size());
  for_each_block(s.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) area3[f] = face_area_3d(s, int(f)), area2[f] = emb.area2(s, int(f));
  });
  double a2 = 0, a3 = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f]) a2 += std::max(area2[f], 0.0), a3 += area3[f];
  return a2 > 0 ? a3 / a2 : 1.0;
}

std::vector<char> whole_band_held(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate,
                                  double below) {
  std::vector<double> area3, area2;
  const double scale = band_areas(s, emb, degenerate, area3, area2);
  std::vector<char> held(s.p.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && area2[f] > 0 && crushed_in_band(scale, area2[f], area3[f], below))
      for (int v : s.t[f]) held[v] = 1;
  return held;
}

namespace {

// Whether the k05-th and k95-th smallest of `ratio` (bound_stats_in_map()'s order statistics) are
// within the area margins, from the ratios themselves (the case a ratio is NaN).
bool percentiles_within(std::vector<double>& ratio) {
  if (ratio.empty()) return false;
  const std::size_t last = ratio.size() - 1;
  const std::size_t k05 = std::min(last, std::size_t(0.05 * double(last) + 0.5));
  const std::size_t k95 = std::min(last, std::size_t(0.95 * double(last) + 0.5));
  const OrderStatistics q = order_statistics(ratio, {k05, k95});
  return WholeBandStop::within_area(BoundStats{q.values[0], q.values[1], 0.0});
}

// Per block of faces: the area ratios counted, those below kWholeBandAreaLow, above kWholeBandAreaHigh, NaN.
struct RatioCounts {
  std::size_t ratios = 0, below = 0, above = 0, nan = 0;
};

}  // namespace

bool AllFacesCheck::within_area(const Embedding& emb) {
  const std::size_t nf = s_.t.size();
  area2_.resize(nf);
  for_each_block(nf, [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) area2_[f] = emb.area2(s_, int(f));
  });
  double a3 = 0, a2 = 0;  // in face order, as bound_stats_in_map() adds them
  for (std::size_t f = 0; f < nf; ++f)
    if (in_map(f, area2_[f])) a3 += area3_[f], a2 += std::abs(area2_[f]);
  const double scale = a2 > 0 ? a3 / a2 : 1;
  const auto ratio = [&](std::size_t f) { return std::abs(area2_[f]) * scale / area3_[f]; };
  std::vector<RatioCounts> part(face_blocks(nf));
  for_each_block(nf, [&](std::size_t begin, std::size_t end) {
    RatioCounts& c = part[begin / kFaceBlock];
    for (std::size_t f = begin; f < end; ++f) {
      if (!in_map(f, area2_[f]) || !(area3_[f] > 0)) continue;
      const double r = ratio(f);
      ++c.ratios, c.below += r < kWholeBandAreaLow, c.above += r > kWholeBandAreaHigh, c.nan += r != r;
    }
  });
  RatioCounts all;
  for (const RatioCounts& c : part) all.ratios += c.ratios, all.below += c.below, all.above += c.above, all.nan += c.nan;
  if (all.nan > 0) {
    std::vector<double> ratios;
    for (std::size_t f = 0; f < nf; ++f)
      if (in_map(f, area2_[f]) && area3_[f] > 0) ratios.push_back(ratio(f));
    return percentiles_within(ratios);
  }
  if (all.ratios == 0) return false;  // both percentiles 0
  const std::size_t last = all.ratios - 1;
  const std::size_t k05 = std::min(last, std::size_t(0.05 * double(last) + 0.5));
  const std::size_t k95 = std::min(last, std::size_t(0.95 * double(last) + 0.5));
  return all.below <= k05 && all.ratios - all.above >= k95 + 1;
}

double AllFacesCheck::qc_mean(const std::vector<V2>& pos, const Embedding& emb) {
  const std::size_t nf = s_.t.size();
  area2_.resize(nf), qc_.resize(nf);
  for_each_block(nf, [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const auto c = shifted_corners(s_.t[f], pos, emb.dy[f]);
      const FaceDistortion d = face_distortion(frames_[f], c[0], c[1], c[2]);
      area2_[f] = d.area2, qc_[f] = d.qc;
    }
  });
  double qsum = 0;  // in face order, as bound_stats_in_map() adds them
  std::size_t n = 0;
  for (std::size_t f = 0; f < nf; ++f)
    if (in_map(f, area2_[f])) ++n, qsum += std::isfinite(qc_[f]) ? qc_[f] : 1e9;
  return n ? qsum / double(n) : 0;
}

bool AllFacesCheck::all_done(const Embedding& emb) {
  if (!within_area(emb)) {
    before_ = emb.pos, known_ = false;
    return false;
  }
  if (!known_) qc_before_ = qc_mean(before_, emb);
  const double qc = qc_mean(emb.pos, emb);
  const bool settled = WholeBandStop::angles_settled(qc, qc_before_);
  qc_before_ = qc, known_ = true;
  return settled;
}

}  // namespace cf::flat_detail
