// Rectal tube (docs/segment.md step 2): a catheter's air channel enters the volume through its
// inferior face and runs up into the rectum, walled off from the rectal gas by its plastic. It is
// tracked slice by slice from the inferior face: each slice's channel is the gas in the channel's
// disc (the previous slice's centroid, the channel's radius + 1 voxel), as long as the ring around
// it holds a wall (mean HU above -900); a few slices with gas all round mark the open tip.
// The channel is trimmed from the gas, and the channel with its wall (the non-gas voxels within
// the channel's radius + kWallMm) is excluded from the lumen in every later step.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>

#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr double kWallMm = 2.0;         // catheter wall (plastic and partial volume) beyond the air channel
constexpr double kOpenTipMm = 3.0;      // channel not enclosed over this length: its open tip
constexpr double kRingMm = 1.5;         // ring outside the channel in which the wall is looked for
constexpr double kOpenHu = -900;        // HU; a ring darker than this on average is gas all round: the channel is open
}  // namespace

// In-plane pixel (a, b) of slice s (counted from the inferior face) -> full-volume index.
std::size_t ColonSegmenter::slice_index(std::size_t s, long a, long b) const {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  std::size_t c[3];
  c[sup_axis_] = sup_pos_ ? s : full_.n[sup_axis_] - 1 - s;
  c[u] = std::size_t(a);
  c[v] = std::size_t(b);
  return full_.idx(c[0], c[1], c[2]);
}

// In-plane 4-connected gas component of slice s from `seeds`, stopped once it reaches `limit` pixels.
std::vector<std::pair<long, long>> ColonSegmenter::slice_component(std::size_t s, const std::vector<std::pair<long, long>>& seeds,
                                                                   const unsigned char* gas, std::size_t limit) const {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  std::vector<std::pair<long, long>> comp, stack(seeds);
  std::vector<std::size_t> seen;
  for (const auto& p : seeds) seen.push_back(slice_index(s, p.first, p.second));
  std::sort(seen.begin(), seen.end());
  while (!stack.empty() && comp.size() < limit) {
    const auto p = stack.back();
    stack.pop_back();
    comp.push_back(p);
    const long da[4] = {-1, 1, 0, 0}, db[4] = {0, 0, -1, 1};
    for (int t = 0; t < 4; ++t) {
      const long a = p.first + da[t], b = p.second + db[t];
      if (a < 0 || b < 0 || a >= long(full_.n[u]) || b >= long(full_.n[v])) continue;
      const std::size_t q = slice_index(s, a, b);
      auto it = std::lower_bound(seen.begin(), seen.end(), q);
      if (!gas[q] || (it != seen.end() && *it == q)) continue;
      seen.insert(it, q);
      stack.emplace_back(a, b);
    }
  }
  return comp;
}

// Gas bodies reaching the inferior face through channels thinner than tube-area: each channel of
// the face slice is tracked up to its open tip and trimmed; its wall is excluded.
void ColonSegmenter::trim_rectal_tube(const std::vector<unsigned char>& face_dropped, unsigned char* gas) {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const double pixel_mm2 = full_.sp[u] * full_.sp[v];
  const std::size_t limit = std::size_t(std::ceil(opts_.tube_area / pixel_mm2));
  std::vector<unsigned char> visited(full_.n[u] * full_.n[v], 0);
  std::size_t trimmed = 0;
  double sum[3] = {0, 0, 0};
  for (long b = 0; b < long(full_.n[v]); ++b)
    for (long a = 0; a < long(full_.n[u]); ++a) {
      const std::size_t q = slice_index(0, a, b);
      if (!gas[q] || face_dropped[std::size_t(b) * full_.n[u] + std::size_t(a)] || visited[std::size_t(b) * full_.n[u] + std::size_t(a)]) continue;
      const auto channel = slice_component(0, {{a, b}}, gas, limit);
      for (const auto& p : channel) visited[std::size_t(p.second) * full_.n[u] + std::size_t(p.first)] = 1;
      if (channel.size() < limit) trimmed += track_tube(channel, gas, sum);
    }
  if (trimmed == 0) return;
  st_.rectal_tube_trimmed_ml = double(trimmed) * voxel_ml_;
  for (double& x : sum) x /= double(trimmed);
  decide("gas channel", st_.rectal_tube_trimmed_ml, sum, false,
         "rectal tube / anal canal: an enclosed channel thinner than --tube-area from the inferior face to its open tip");
}

// Follows one channel up from the face slice: each next slice's channel is the gas within the
// channel's radius + 1 voxel of the previous centroid; the channel is enclosed while the ring just
// outside it (kRingMm wide) holds a wall: its mean HU stays above kOpenHu (the catheter's plastic,
// even partly resolved, or tissue), where gas all round gives about -1000 HU. Trims
// the channel, records it and its wall in tube_; returns the voxels trimmed (sum: coordinate sums).
std::size_t ColonSegmenter::track_tube(std::vector<std::pair<long, long>> channel, unsigned char* gas, double sum[3]) {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const double pixel_mm2 = full_.sp[u] * full_.sp[v], px = std::sqrt(pixel_mm2);
  const double radius = std::sqrt(double(channel.size()) * pixel_mm2 / 3.14159265358979);  // mm
  const int open_slices = std::max(1, int(std::lround(kOpenTipMm / full_.sp[sup_axis_])));
  std::size_t trimmed = 0;
  int open = 0;
  double ca = 0, cb = 0;  // the channel's centre in the slice
  for (const auto& p : channel) ca += double(p.first), cb += double(p.second);
  ca /= double(channel.size()), cb /= double(channel.size());
  for (std::size_t s = 0; s < full_.n[sup_axis_] && !channel.empty(); ++s) {
    for (const auto& p : channel) {
      const std::size_t q = slice_index(s, p.first, p.second);
      gas[q] = 0;
      tube_.push_back(q);
      std::size_t c[3];
      full_.coords(q, c[0], c[1], c[2]);
      for (int k = 0; k < 3; ++k) sum[k] += double(c[k]);
    }
    trimmed += channel.size();
    exclude_disc(s, ca, cb, (radius + kWallMm) / px);
    if (s + 1 == full_.n[sup_axis_]) break;
    channel = gas_in_disc(s + 1, ca, cb, radius / px + 1.0, gas);
    const auto core = gas_in_disc(s + 1, ca, cb, radius / px, gas);  // re-centred on the inner disc only: no drift into rectal gas
    if (!core.empty()) {
      double na = 0, nb = 0;
      for (const auto& p : core) na += double(p.first), nb += double(p.second);
      ca = na / double(core.size()), cb = nb / double(core.size());
    }
    const double ring_hu = ring_mean_hu(s + 1, ca, cb, radius / px + 0.5, (radius + kRingMm) / px + 0.5);
    if (std::getenv("COLONFLAT_SEGMENT_DEBUG"))
      std::fprintf(stderr, "tube slice %zu: channel %zu ring %.0f HU open %d\n", s + 1, channel.size(), ring_hu, open);
    open = ring_hu >= kOpenHu ? 0 : open + 1;
    if (open > open_slices) break;  // the open tip: rectal gas all round
  }
  return trimmed;
}

// Mean HU of the pixels of slice s between r0_px and r1_px from (ca, cb) (-1000 if none).
double ColonSegmenter::ring_mean_hu(std::size_t s, double ca, double cb, double r0_px, double r1_px) const {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const float* fhu = ct_->GetBufferPointer();
  std::size_t n = 0;
  double sum = 0;
  for (long b = std::max(0L, long(std::floor(cb - r1_px))); b <= std::min(long(full_.n[v]) - 1, long(std::ceil(cb + r1_px))); ++b)
    for (long a = std::max(0L, long(std::floor(ca - r1_px))); a <= std::min(long(full_.n[u]) - 1, long(std::ceil(ca + r1_px))); ++a) {
      const double d2 = (a - ca) * (a - ca) + (b - cb) * (b - cb);
      if (d2 < r0_px * r0_px || d2 > r1_px * r1_px) continue;
      ++n;
      sum += fhu[slice_index(s, a, b)];
    }
  return n ? sum / double(n) : -1000.0;
}

// Gas pixels of slice s within r_px of (ca, cb).
std::vector<std::pair<long, long>> ColonSegmenter::gas_in_disc(std::size_t s, double ca, double cb, double r_px,
                                                               const unsigned char* gas) const {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  std::vector<std::pair<long, long>> out;
  for (long b = std::max(0L, long(std::floor(cb - r_px))); b <= std::min(long(full_.n[v]) - 1, long(std::ceil(cb + r_px))); ++b)
    for (long a = std::max(0L, long(std::floor(ca - r_px))); a <= std::min(long(full_.n[u]) - 1, long(std::ceil(ca + r_px))); ++a)
      if ((a - ca) * (a - ca) + (b - cb) * (b - cb) <= r_px * r_px && gas[slice_index(s, a, b)]) out.emplace_back(a, b);
  return out;
}

// The catheter wall: the non-gas voxels of slice s within r_px of (ca, cb) are excluded from the lumen.
void ColonSegmenter::exclude_disc(std::size_t s, double ca, double cb, double r_px) {
  const int u = (sup_axis_ + 1) % 3, v = (sup_axis_ + 2) % 3;
  const float* fhu = ct_->GetBufferPointer();
  for (long b = std::max(0L, long(std::floor(cb - r_px))); b <= std::min(long(full_.n[v]) - 1, long(std::ceil(cb + r_px))); ++b)
    for (long a = std::max(0L, long(std::floor(ca - r_px))); a <= std::min(long(full_.n[u]) - 1, long(std::ceil(ca + r_px))); ++a) {
      const std::size_t q = slice_index(s, a, b);
      if ((a - ca) * (a - ca) + (b - cb) * (b - cb) <= r_px * r_px && fhu[q] >= opts_.air_threshold) tube_.push_back(q);
    }
}

}  // namespace cf::segment_detail
