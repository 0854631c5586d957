// Tagged fluid in a mask phantom: fully tagged stretches (every lumen voxel within a range of path
// distance from the rectal end along the lumen) and dependent pools (one per pocket of the gas-filled
// lumen, found by a watershed along gravity; level at 10-30 % of the pocket's height, never above the
// pocket's spill point, so every pool has one level surface).
#include <algorithm>
#include <cmath>
#include <limits>

#include "colonflat/core/voxel_path.h"
#include "mask_phantom_model.h"

namespace cf::phantom_detail {

namespace {
// Pool depth as a fraction of the pocket's height (docs/phantom.md: 10-30 % of each haustral pocket).
constexpr double kPoolMinFraction = 0.10, kPoolMaxFraction = 0.30;
// Deep pools (--deep-pools): 30-50 % of the pocket's height, above the folds between haustral
// pockets (fold height 10-30 % of the lumen), so one level runs along a whole dependent segment.
constexpr double kDeepMinFraction = 0.30, kDeepMaxFraction = 0.50;
// ... of at most a colon's width (mm): through a vertical stretch the lumen's height along gravity is
// its length, and a level at 30-50 % of it would fill the whole colon below.
constexpr double kDeepHeightCapMm = 50;
// Deep pools are the deepest pockets' (the dependent segment's: the transverse colon prone, the
// sigmoid or descending colon supine); the others stay 10-30 %: a scan holds a few hundred mL of
// tagged fluid, not a colon filled to a third everywhere.
constexpr int kDeepPools = 2;
// Fully tagged stretch length along the colon (mm) and where it may lie (fraction of the path from
// the rectal end): the example is 90 mm of descending colon.
constexpr double kStretchMinMm = 60, kStretchMaxMm = 120, kStretchGapMm = 40;
}  // namespace

// Path distance (mm, 26-neighbour Dijkstra through the lumen; core voxel_path_distance) from `start`
// over the lumen box; infinity where the lumen does not connect. Indexed like the box (i - lo, j - lo, k - lo).
std::vector<float> MaskPainter::path_distance(std::size_t start) const {
  const VoxelBox box{mask_buf_, g_.n, g_.sp, {lo_[0], lo_[1], lo_[2]}, {hi_[0], hi_[1], hi_[2]}};
  int si, sj, sk;
  ijk(start, si, sj, sk);
  return voxel_path_distance(box, {si, sj, sk});
}

// K stretches of 60-120 mm of path, 15-85 % of the way from the rectal end, 40 mm apart (and first,
// with --long-stretch, one of that length lying beside other parts of the colon): every lumen voxel
// there becomes tagged fluid (500-900 HU).
void MaskPainter::place_stretches() {
  if (o_.fully_tagged == 0 && o_.long_stretch_mm <= 0) return;
  const std::vector<float> dist = path_distance(rectum_);
  double D = 0;
  for (float d : dist)
    if (std::isfinite(d)) D = std::max(D, double(d));
  std::vector<std::pair<double, double>> ranges;
  if (o_.long_stretch_mm > 0 && o_.long_stretch_mm < 0.7 * D) {
    const auto r = beside_range(dist, D, o_.long_stretch_mm);
    if (r.first >= 0) ranges.push_back(r);
  }
  for (int t = 0; t < o_.fully_tagged; ++t)
    for (int attempt = 0; attempt < 100; ++attempt) {
      const double len = rng_.uniform(kStretchMinMm, kStretchMaxMm);
      if (0.7 * D < len) break;
      const double s0 = rng_.uniform(0.15 * D, 0.85 * D - len), s1 = s0 + len;
      bool clear = true;
      for (const auto& [a, b] : ranges) clear = clear && (s1 + kStretchGapMm < a || s0 > b + kStretchGapMm);
      if (!clear) continue;
      ranges.push_back({s0, s1});
      break;
    }
  const int bn[3] = {hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]};
  for (std::size_t t = 0; t < ranges.size(); ++t) {
    md_.stretches.push_back({ranges[t].first, ranges[t].second, std::round(rng_.uniform(500, 900))});
    MaskFluidBody b;
    b.kind = "stretch";
    b.hu = md_.stretches.back().hu;
    b.from_mm = ranges[t].first;
    b.to_mm = ranges[t].second;
    out_.bodies.push_back(b);
    const auto id = static_cast<std::uint16_t>(out_.bodies.size());
    const auto m = static_cast<unsigned char>(kFluid0 + kPoolSlots + t);
    for (int k = lo_[2]; k < hi_[2]; ++k)
      for (int j = lo_[1]; j < hi_[1]; ++j)
        for (int i = lo_[0]; i < hi_[0]; ++i) {
          const float d = dist[(std::size_t(k - lo_[2]) * bn[1] + (j - lo_[1])) * bn[0] + (i - lo_[0])];
          if (d < ranges[t].first || d > ranges[t].second) continue;
          const std::size_t q = g_.index(i, j, k);
          mat_[q] = m;
          out_.fluid_id[q] = id;
          ++out_.bodies.back().voxels;
        }
  }
}

// Height (mm) of the lumen along the grid axis nearest to gravity, through voxel (i, j, k).
double MaskPainter::pocket_height(int i, int j, int k) const {
  int a = 0;
  for (int d = 1; d < 3; ++d)
    if (std::abs(down_[d]) > std::abs(down_[a])) a = d;
  int n = 0;
  for (int s : {-1, 1}) {
    int ix[3] = {i, j, k};
    if (s == 1) ix[a] += 1;
    while (ix[a] >= 0 && ix[a] < g_.n[a] && lumen(g_.index(ix[0], ix[1], ix[2]))) ++n, ix[a] += s;
  }
  return n * g_.sp[a];
}

namespace {
struct Basin {
  std::size_t bottom;
  double d0, spill;  // depth of the lowest voxel; depth where it joined a deeper basin (NaN: never)
};
std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t v) {
  std::int32_t r = v;
  while (parent[r] != r) r = parent[r];
  while (parent[v] != r) {
    const std::int32_t n = parent[v];
    parent[v] = r;
    v = n;
  }
  return r;
}
}  // namespace

// Watershed of the gas lumen along gravity (deepest voxels first, union-find of 6-neighbours): each
// basin is a pocket with its lowest voxel and the depth where it spills into a deeper one. Each
// pocket, deepest first, gets a pool at 10-30 % of its height (not above its spill point, at least
// one voxel deep).
void MaskPainter::place_pools() {
  const int bn[3] = {hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]};
  auto box = [&](int i, int j, int k) { return std::int32_t((std::size_t(k - lo_[2]) * bn[1] + (j - lo_[1])) * bn[0] + (i - lo_[0])); };
  std::vector<std::pair<double, std::int32_t>> order;
  for (int k = lo_[2]; k < hi_[2]; ++k)
    for (int j = lo_[1]; j < hi_[1]; ++j)
      for (int i = lo_[0]; i < hi_[0]; ++i)
        if (mat_[g_.index(i, j, k)] == kColonGas) order.push_back({-depth(i, j, k), box(i, j, k)});
  std::sort(order.begin(), order.end());
  std::vector<std::int32_t> parent(std::size_t(bn[0]) * bn[1] * bn[2], -1), bid(parent.size(), -1);
  std::vector<Basin> basins;
  for (const auto& [nd, v] : order) {
    const int i = lo_[0] + v % bn[0], j = lo_[1] + (v / bn[0]) % bn[1], k = lo_[2] + v / (bn[0] * bn[1]);
    std::int32_t roots[6];
    int nr = 0;
    const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& n : nb) {
      if (n[0] < lo_[0] || n[1] < lo_[1] || n[2] < lo_[2] || n[0] >= hi_[0] || n[1] >= hi_[1] || n[2] >= hi_[2]) continue;
      const std::int32_t u = box(n[0], n[1], n[2]);
      if (parent[u] >= 0) roots[nr++] = find_root(parent, u);
    }
    if (nr == 0) {
      parent[v] = v;
      bid[v] = std::int32_t(basins.size());
      basins.push_back({g_.index(i, j, k), -nd, std::numeric_limits<double>::quiet_NaN()});
      continue;
    }
    std::int32_t w = roots[0];
    for (int t = 1; t < nr; ++t)
      if (basins[bid[roots[t]]].d0 > basins[bid[w]].d0) w = roots[t];
    for (int t = 0; t < nr; ++t)
      if (roots[t] != w && parent[roots[t]] == roots[t]) basins[bid[roots[t]]].spill = -nd, parent[roots[t]] = w;
    parent[v] = w;
  }
  std::vector<std::int32_t>().swap(parent);
  std::vector<std::int32_t>().swap(bid);
  std::stable_sort(basins.begin(), basins.end(), [](const Basin& a, const Basin& b) { return a.d0 > b.d0; });
  int a = 0;
  for (int d = 1; d < 3; ++d)
    if (std::abs(down_[d]) > std::abs(down_[a])) a = d;
  const double step = g_.sp[a] * std::abs(down_[a]);
  int deep_left = o_.deep_pools ? kDeepPools : 0;
  for (const Basin& b : basins) {
    const bool deep = deep_left > 0;
    const double f = deep ? rng_.uniform(kDeepMinFraction, kDeepMaxFraction) : rng_.uniform(kPoolMinFraction, kPoolMaxFraction);
    if (mat_[b.bottom] != kColonGas) continue;  // under an earlier pool
    deep_left -= deep;
    int i, j, k;
    ijk(b.bottom, i, j, k);
    const double H = deep ? std::min(kDeepHeightCapMm, pocket_height(i, j, k)) : pocket_height(i, j, k);
    const bool spills = !deep && !std::isnan(b.spill) && f * H >= b.d0 - b.spill;
    const double level = spills ? b.spill : b.d0 - f * H;
    const double frac = (b.d0 - level) / H;
    if (frac < kPoolMinFraction || b.d0 - level < step) continue;
    MaskFluidBody body;
    body.kind = "pool";
    body.level_depth_mm = level;
    body.bottom_depth_mm = b.d0;
    body.pocket_height_mm = H;
    body.fraction = frac;
    out_.bodies.push_back(body);
    fill_pocket(b.bottom, level, int(out_.bodies.size()));
  }
}

// Flood fill of the gas lumen deeper than `level` from the pocket's lowest voxel: fluid body `body`.
void MaskPainter::fill_pocket(std::size_t bottom, double level, int body) {
  const int pool_index = int(std::count_if(out_.bodies.begin(), out_.bodies.end(), [](const MaskFluidBody& b) { return b.kind == "pool"; })) - 1;
  const auto m = static_cast<unsigned char>(kFluid0 + pool_index % kPoolSlots);
  MaskFluidBody& rec = out_.bodies[std::size_t(body - 1)];
  rec.hu = md_.pools[std::size_t(pool_index % kPoolSlots)].hu;
  std::vector<std::size_t> stack{bottom};
  mat_[bottom] = m;
  while (!stack.empty()) {
    const std::size_t q = stack.back();
    stack.pop_back();
    out_.fluid_id[q] = static_cast<std::uint16_t>(body);
    ++rec.voxels;
    int i, j, k;
    ijk(q, i, j, k);
    const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& n : nb) {
      if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= g_.n[0] || n[1] >= g_.n[1] || n[2] >= g_.n[2]) continue;
      const std::size_t r = g_.index(n[0], n[1], n[2]);
      if (mat_[r] != kColonGas || depth(n[0], n[1], n[2]) <= level) continue;
      mat_[r] = m;
      stack.push_back(r);
    }
  }
}

}  // namespace cf::phantom_detail
