// Where a long fully tagged stretch goes in a mask phantom (issue 25): the window of the colon's
// course (path distance from the rectal end) whose lumen lies most beside other parts of the colon.
// A fluid-filled transverse colon hanging beside the gas-filled ascending and descending colon, or a
// filled sigmoid folded against the rectum, is the case that real scans fail on; the window is
// chosen from the mask's own geometry (no voxel index), so any mask gives its own hard case.
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "mask_phantom_model.h"

namespace cf::phantom_detail {

namespace {
// Lumen samples every kSampleMm: coarse enough to keep the search small (a colon of 3-4 L gives
// ~50 k samples), fine enough that a lumen 20-80 mm wide has several across.
constexpr double kSampleMm = 4.0;
// Two samples this close (mm, lumen to lumen, plus a sample's spacing) lie side by side: two colon
// walls of 2-3 mm pressed together leave 4-6 mm between the lumens.
constexpr double kBesideMm = 12.0;
// ... and belong to different parts of the colon when their path distances differ by more than
// this: a point across the same tube is at most its width (colon 30-80 mm) plus a fold's detour
// away along paths inside the lumen; 150 mm excludes that.
constexpr double kOtherPartMm = 150.0;
// The stretch's ends stay this far (path mm) from the parts it lies beside (so the ends meet gas).
constexpr double kEndClearMm = 20.0;
// A window holding more lumen than len x kMaxSectionMm2 is not one stretch of tube: where the mask's
// segments touch, path distances from the rectum shortcut through the contact, and a window of path
// then holds several segments. 5000 mm^2 is the cross-section of an 80 mm wide colon, the widest
// (a distended caecum); on the shared real mask a 200 mm window held 2 L without this.
constexpr double kMaxSectionMm2 = 5000.0;
// Windows are tried every kWindowStepMm of path; any window scoring >= 70 % of the best may be
// drawn, so seeds give different stretches of the same kind.
constexpr double kWindowStepMm = 5.0, kGoodShare = 0.7;

struct Sample {
  V3 p;
  float d;
  float lo = 1e30f, hi = -1e30f;  // least / greatest path distance of other parts beside it
};
}  // namespace

// The path range [s0, s0 + len] (15-85 % of the way from the rectal end) with the most lumen beside
// other parts of the colon outside the range. Returns {-1, -1} when no window has any.
std::pair<double, double> MaskPainter::beside_range(const std::vector<float>& dist, double D, double len) {
  const int bn[3] = {hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]};
  int st[3];
  for (int a = 0; a < 3; ++a) st[a] = std::max(1, int(std::lround(kSampleMm / g_.sp[a])));
  std::vector<Sample> s;
  for (int k = lo_[2]; k < hi_[2]; k += st[2])
    for (int j = lo_[1]; j < hi_[1]; j += st[1])
      for (int i = lo_[0]; i < hi_[0]; i += st[0]) {
        const float d = dist[(std::size_t(k - lo_[2]) * bn[1] + (j - lo_[1])) * bn[0] + (i - lo_[0])];
        if (std::isfinite(d)) s.push_back({g_.point(i, j, k), d});
      }
  auto key = [](const V3& p) {
    const auto c = [](double v) { return std::int64_t(std::floor(v / kBesideMm)) & 0x1fffff; };
    return (c(p[0]) << 42) | (c(p[1]) << 21) | c(p[2]);
  };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells;
  for (std::size_t t = 0; t < s.size(); ++t) cells[key(s[t].p)].push_back(t);
  const double reach = kBesideMm + kSampleMm;
  for (Sample& a : s)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find(key(a.p + kBesideMm * V3(dx, dy, dz)));
          if (it == cells.end()) continue;
          for (std::size_t u : it->second)
            if (std::abs(s[u].d - a.d) > kOtherPartMm && (s[u].p - a.p).norm() <= reach)
              a.lo = std::min(a.lo, s[u].d), a.hi = std::max(a.hi, s[u].d);
        }
  std::vector<std::pair<double, int>> score;  // (s0, samples beside other parts)
  const double sample_mm3 = double(st[0]) * g_.sp[0] * double(st[1]) * g_.sp[1] * double(st[2]) * g_.sp[2];
  for (double s0 = 0.15 * D; s0 + len <= 0.85 * D; s0 += kWindowStepMm) {
    int n = 0, all = 0;
    for (const Sample& a : s) {
      const bool in = a.d >= s0 && a.d <= s0 + len;
      all += in;
      n += in && (a.lo < s0 - kEndClearMm || a.hi > s0 + len + kEndClearMm);
    }
    if (all * sample_mm3 <= kMaxSectionMm2 * len) score.push_back({s0, n});  // else: not one stretch of tube
  }
  int best = 0;
  for (const auto& w : score) best = std::max(best, w.second);
  if (best == 0) return {-1, -1};
  std::vector<double> good;
  for (const auto& w : score)
    if (w.second >= kGoodShare * best) good.push_back(w.first);
  const double s0 = good[std::min(good.size() - 1, std::size_t(rng_.uniform() * double(good.size())))];
  return {s0, s0 + len};
}

}  // namespace cf::phantom_detail
