// Fluid bodies split at narrow necks (docs/segment.md step 4): bowel loops pressed together merge
// in the bright mask across their walls (the 3 x 3 x 3 mean bridges a wall of a voxel or two), so
// one bright component can hold colon fluid, small bowel with oral contrast and bone. A ball of
// kCoreRadiusMm fits inside every lumen that holds tagged fluid but not through such a bridge: the
// bright voxels where the ball fits (the cores) are labelled, and every bright voxel joins the core
// nearest along paths inside the bright mask (a geodesic Voronoi partition), so each piece is one
// lumen. A core voxel is fluid in its own value too, and the cores grow through fluid voxels before
// the rest of the mask: a wall of one voxel between two lumens is bright in the mean (the ball fits
// across it at coarse pixels) but not in its own value, so it separates the cores and their growth.
// Bright components without a core (thin layers) keep their own label.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <array>
#include <vector>

#include "colonflat/core/union_find.h"
#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr double kCoreRadiusMm = 3.0;
constexpr double kMinCoreVoxels = 1.5;  // the ball must span this many voxels along every axis
constexpr double kMinFluidPairShare = 0.5;  // two pieces are one lumen when this share of their boundary is fluid
// A plateau of another level holds at least this much (50 mm^3: a lumen 4 mm across over 4 mm beyond its rim);
// smaller components above a region's median are noise blobs of the 3 x 3 x 3 mean (a few voxels).
constexpr double kMinOtherLevelMl = 0.05;
// Workers of the pieces' growth: one per thread, at most one owner byte's values.
std::size_t grow_workers() { return std::size_t(std::clamp(cf::thread_count(), 1, 255)); }
// The growth's owners are found on cells of 2^3 voxels (ComponentOwners): 1/8 of the voxels to
// label; bright bodies closer than a cell share a worker. Speed only: the pieces are the same for any cell.
constexpr std::size_t kOwnerCell = 2;
}

// Erosion of `m` (0/1) by the ball of radius r_mm (an ellipsoid in voxels): voxels outside the
// volume count as set. The box inside the ball (half-width r / sqrt 3) gives the voxels that may
// pass, the box around it those that pass for sure; only the shell between is checked voxel by voxel.
Bytes erode_ball(const Bytes& m, const Dims& d, double r_mm) {
  int rin[3], rout[3];
  for (int a = 0; a < 3; ++a) {
    rout[a] = int(std::floor(r_mm / d.sp[a] + 1e-9));
    rin[a] = int(std::floor(r_mm / std::sqrt(3.0) / d.sp[a] + 1e-9));
  }
  Bytes sure = m, maybe = m;
  erode_box(sure, d, rout);
  erode_box(maybe, d, rin);
  std::vector<std::array<int, 3>> ball;
  for (int k = -rout[2]; k <= rout[2]; ++k)
    for (int j = -rout[1]; j <= rout[1]; ++j)
      for (int i = -rout[0]; i <= rout[0]; ++i) {
        const double x = i * d.sp[0], y = j * d.sp[1], z = k * d.sp[2];
        if (x * x + y * y + z * z <= r_mm * r_mm + 1e-9) ball.push_back({i, j, k});
      }
  parallel_for(d.n[2], [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k)
      for (std::size_t j = 0; j < d.n[1]; ++j)
        for (std::size_t i = 0; i < d.n[0]; ++i) {
          const std::size_t q = d.idx(i, j, k);
          if (!maybe[q] || sure[q]) continue;
          bool all = true;
          for (std::size_t t = 0; t < ball.size() && all; ++t) {
            const long x = long(i) + ball[t][0], y = long(j) + ball[t][1], z = long(k) + ball[t][2];
            if (x < 0 || y < 0 || z < 0 || x >= long(d.n[0]) || y >= long(d.n[1]) || z >= long(d.n[2])) continue;
            all = m[d.idx(std::size_t(x), std::size_t(y), std::size_t(z))] != 0;
          }
          sure[q] = all;
        }
  });
  return sure;
}

namespace {
// One worker's growth (grow_labels): the serial breadth-first passes over its queue. The second pass
// starts from the voxels of the first that have a bright non-fluid neighbour still unlabelled (the
// first pass never labels one), in the first pass's order: the others would add nothing.
void grow_queue(const GrowInput& in, std::vector<std::size_t>& queue) {
  const Dims& d = *in.d;
  std::uint32_t* label = in.label;
  std::vector<std::size_t> border;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t q = queue[head];
    bool wall_next = false;
    for_face_neighbours(d, q, [&](std::size_t r) {
      if (!in.bright[r] || label[r]) return;
      if ((*in.hu)[r] < in.fluid_threshold) return void(wall_next = true);
      label[r] = label[q];
      queue.push_back(r);
    });
    if (wall_next) border.push_back(q);
  }
  queue.swap(border);
  std::vector<std::size_t>().swap(border);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t q = queue[head];
    for_face_neighbours(d, q, [&](std::size_t r) {
      if (!in.bright[r] || label[r]) return;
      label[r] = label[q];
      queue.push_back(r);
    });
  }
  std::vector<std::size_t>().swap(queue);
}
}  // namespace

ComponentOwners::ComponentOwners(const Bytes& mask, const Dims& d, std::size_t workers, std::size_t cell)
    : d_(&d), cell_(cell), workers_(workers) {
  std::size_t n[3];
  for (int a = 0; a < 3; ++a) n[a] = (d.n[a] + cell - 1) / cell;
  cells_ = make_dims(n, d.sp);
  std::vector<std::uint32_t> count(cells_.total, 0);  // mask voxels per cell
  parallel_for(cells_.n[2], [&](std::size_t c0, std::size_t c1) {  // each cell layer written by one worker
    for (std::size_t k = c0 * cell; k < std::min(d.n[2], c1 * cell); ++k)
      for (std::size_t j = 0; j < d.n[1]; ++j) {
        const unsigned char* row = mask.data() + d.idx(0, j, k);
        std::uint32_t* out = count.data() + cells_.idx(0, j / cell, k / cell);
        for (std::size_t i0 = 0; i0 < d.n[0]; i0 += cell)
          out[i0 / cell] += std::uint32_t(std::count_if(row + i0, row + std::min(d.n[0], i0 + cell), [](unsigned char v) { return v != 0; }));
      }
  });
  Bytes set(cells_.total);
  for (std::size_t c = 0; c < cells_.total; ++c) set[c] = count[c] > 0;
  const RunLabels cl = component_runs(set.data(), cells_);
  std::vector<std::size_t> voxels(cl.count() + 1, 0);
  std::vector<std::uint32_t> order;
  for (std::uint32_t l = 1; l <= cl.count(); ++l) {
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r)
      for (std::size_t c = r->start; c < r->start + r->length; ++c) voxels[l] += count[c];
    order.push_back(l);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return voxels[a] > voxels[b]; });
  std::vector<std::size_t> load(workers, 0);
  owner_.assign(cells_.total, 0);
  for (std::uint32_t l : order) {
    const auto w = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
    load[w] += voxels[l];
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r) std::fill_n(owner_.data() + r->start, r->length, static_cast<unsigned char>(w));
  }
}

unsigned char ComponentOwners::at(std::size_t q) const {
  std::size_t c[3];
  d_->coords(q, c[0], c[1], c[2]);
  return owner_[cells_.idx(c[0] / cell_, c[1] / cell_, c[2] / cell_)];
}

std::size_t grow_labels(const GrowInput& in, const ComponentOwners& owners, std::vector<std::size_t>& queue) {
  const std::size_t workers = owners.workers();
  std::vector<unsigned char> by(queue.size());
  std::vector<std::size_t> count(workers, 0);
  for (std::size_t t = 0; t < queue.size(); ++t) ++count[by[t] = owners.at(queue[t])];
  std::vector<std::vector<std::size_t>> parts(workers);
  for (std::size_t w = 0; w < workers; ++w) parts[w].reserve(count[w]);
  for (std::size_t t = 0; t < queue.size(); ++t) parts[by[t]].push_back(queue[t]);
  std::vector<std::size_t>().swap(queue);
  std::size_t used = 0;
  for (const auto& p : parts) used += !p.empty();
  cf::parallel_for(workers, [&](std::size_t w0, std::size_t w1) {
    for (std::size_t w = w0; w < w1; ++w) grow_queue(in, parts[w]);
  });
  return used;
}

// Breadth-first from the cores (`queue`, in label order): the nearest core along the mask, first
// through fluid voxels only (a core does not reach across a wall into the next lumen's fluid), then
// into the mask's other voxels (grow_labels: the bright components over the workers).
void ColonSegmenter::grow_pieces(const Bytes& bright, const ComponentOwners& owners, std::vector<std::size_t>& queue) {
  const GrowInput in{&d_, bright.data(), &hu_, opts_.fluid_threshold, fluid_label_.data()};
  grow_labels(in, owners, queue);
}

// fluid_label_: the pieces of the bright mask (cores grown along paths inside the mask, then the
// coreless components); fluid_count_ their number. Where a piece holds fluid of another level behind
// a darker bridge (other_level_cores), that fluid is a core of its own and the pieces are grown again.
void ColonSegmenter::split_fluid_bodies(const Bytes& bright) {
  fluid_count_ = 0;
  // Voxels coarser than the ball can resolve (radius < 1.5 voxels: the 3 x 3 x 3 mean alone spreads
  // a voxel): no cores, every bright component is one piece.
  const bool resolved = kCoreRadiusMm >= kMinCoreVoxels * std::max({d_.sp[0], d_.sp[1], d_.sp[2]});
  if (resolved) {
    Bytes core = erode_ball(bright, d_, kCoreRadiusMm);
    step_time("erode_ball");
    for_each_voxel(d_.total, [&](std::size_t q) { core[q] = core[q] && hu_[q] >= opts_.fluid_threshold; });  // a wall voxel is no core
    const RunLabels cl = component_runs(core.data(), d_);
    step_time("core labels");
    fill_parallel(fluid_label_, d_.total, std::uint32_t(0));  // after the ball's work buffers are freed: the labels reuse their pages
    const ComponentOwners owners(bright, d_, grow_workers(), kOwnerCell);
    step_time("bright components");
    std::vector<std::size_t> queue = seed_cores(cl);
    step_time("seed_cores");
    grow_pieces(bright, owners, queue);
    step_time("grow_pieces");
    const std::vector<std::vector<std::size_t>> other = other_level_cores(bright, core, cl);
    step_time("other_level_cores");
    Bytes().swap(core);
    if (!other.empty()) {  // each a core of its own (its voxels leave the old cores); all grown again
      fill_parallel(fluid_label_, d_.total, std::uint32_t(0));
      queue = seed_cores(cl);
      for (std::size_t t = 0; t < other.size(); ++t)
        for (std::size_t q : other[t]) fluid_label_[q] = cl.count() + std::uint32_t(t) + 1, queue.push_back(q);
      fluid_count_ += std::uint32_t(other.size());
      grow_pieces(bright, owners, queue);
      step_time("grow_pieces again");
    }
  }
  if (!resolved) fill_parallel(fluid_label_, d_.total, std::uint32_t(0));
  Bytes rest(d_.total);
  for_each_voxel(d_.total, [&](std::size_t q) { rest[q] = bright[q] && !fluid_label_[q]; });
  const RunLabels thin = component_runs(rest.data(), d_);
  for (std::uint32_t l = 1; l <= thin.count(); ++l)
    for (const Run* r = thin.begin(l); r != thin.end(l); ++r) std::fill_n(fluid_label_.data() + r->start, r->length, fluid_count_ + l);
  fluid_count_ += thin.count();
}

// Labels the cores 1.. into fluid_label_ and returns their voxels in label order (the breadth-first
// queue of grow_pieces); fluid_count_ = the cores' number.
std::vector<std::size_t> ColonSegmenter::seed_cores(const RunLabels& cl) {
  release_kept_blocks();  // the queue grows on the heap (to every bright voxel): freed buffers must not add to its peak
  std::vector<std::size_t> queue;
  std::size_t voxels = 0;
  for (const Run& r : cl.runs) voxels += r.length;
  queue.reserve(voxels);
  for (std::uint32_t l = 1; l <= cl.count(); ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r) {
      std::fill_n(fluid_label_.data() + r->start, r->length, l);
      for (std::size_t q = r->start; q < r->start + r->length; ++q) queue.push_back(q);
    }
  fluid_count_ = cl.count();
  return queue;
}

// Per core label of `cl`: the level of its fluid, the median own HU of its core voxels (>= fluid-threshold).
std::vector<float> ColonSegmenter::core_levels(const RunLabels& cl) const {
  std::vector<float> level(cl.count() + 1, 0), v;
  for (std::uint32_t l = 1; l <= cl.count(); ++l) {
    v.clear();
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r)
      for (std::size_t q = r->start; q < r->start + r->length; ++q) v.push_back(hu_[q]);
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    level[l] = v[v.size() / 2];
  }
  return level;
}

// 3 x 3 x 3 mean of the CT at voxel q (edges clamped, as box_mean3_slices).
float ColonSegmenter::mean3_at(std::size_t q) const {
  std::size_t c[3];
  d_.coords(q, c[0], c[1], c[2]);
  double sum = 0;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const long x = std::clamp(long(c[0]) + di, 0L, long(d_.n[0]) - 1), y = std::clamp(long(c[1]) + dj, 0L, long(d_.n[1]) - 1);
        const long z = std::clamp(long(c[2]) + dk, 0L, long(d_.n[2]) - 1);
        sum += hu_[d_.idx(std::size_t(x), std::size_t(y), std::size_t(z))];
      }
  return float(sum / 27.0);
}

// Fluid of another level behind a darker bridge (docs/segment.md step 4, session 19). One lumen holds
// one mixture of tagged fluid: its HU departs from the level only by noise and, toward the wall, by
// partial volume, and where two mixtures meet in one lumen the fluid between them is fluid. So the
// voxels of a piece whose 3 x 3 x 3 mean is below the midpoint between its cores' level and
// fluid-threshold, without the partial-volume rim (eroded by one voxel) and fluid in their own
// value, in regions of >= kMinOtherLevelMl, are another lumen's fluid when they reach the piece's own
// level only through voxels darker than themselves (plateau_beyond_bridge): oral contrast in a
// small-bowel loop joined to a colon pool through the walls' partial volume. Returns each such
// plateau (its voxels), a core of its own.
std::vector<std::vector<std::size_t>> ColonSegmenter::other_level_cores(const Bytes& bright, const Bytes& core, const RunLabels& cl) const {
  const std::vector<float> level = core_levels(cl);
  Bytes low(d_.total, 0);
  parallel_for(d_.total, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) {
      const std::uint32_t l = fluid_label_[q];
      if (bright[q] && l >= 1 && l <= cl.count()) low[q] = mean3_at(q) < 0.5 * (level[l] + opts_.fluid_threshold);
    }
  });
  const int one[3] = {1, 1, 1};
  erode_box(low, d_, one);
  for_each_voxel(d_.total, [&](std::size_t q) { low[q] = low[q] && hu_[q] >= opts_.fluid_threshold; });
  const RunLabels found = component_runs(low.data(), d_);
  Bytes().swap(low);
  std::vector<std::vector<std::size_t>> out;
  Bytes seen(d_.total, 0);
  for (std::uint32_t f = 1; f <= found.count(); ++f) {
    std::vector<std::size_t> region;
    for (const Run* r = found.begin(f); r != found.end(f); ++r)
      for (std::size_t q = r->start; q < r->start + r->length; ++q) region.push_back(q);
    if (double(region.size()) * voxel_ml_ < kMinOtherLevelMl) continue;
    const std::uint32_t p = fluid_label_[region.front()];
    auto found_here = plateaus_beyond_bridge(region, p, 0.5 * (level[p] + opts_.fluid_threshold), core, seen);
    std::size_t n = 0;
    for (auto& v : found_here) n += v.size(), out.push_back(std::move(v));
    if (std::getenv("COLONFLAT_SEGMENT_DEBUG")) debug_other_level(region, n, level[p]);
  }
  return out;
}

// The plateaus of `region` (of piece p) behind a darker bridge: from each of its voxels whose 3 x 3 x 3
// mean is at least the region's median (its own fluid, not the bridge or rim it may hold), breadth-
// first through the piece's voxels at least as bright; a component that never reaches the piece's
// own level (mean >= `own`: one lumen, whose mixtures meet through fluid) and holds >= kMinOtherLevelMl
// is a plateau, with the piece's core voxels below `own` connected to it (the core may pass the
// bridge). seen: 1 for a component joined to the piece's level (a later flood meeting it is joined).
std::vector<std::vector<std::size_t>> ColonSegmenter::plateaus_beyond_bridge(const std::vector<std::size_t>& region, std::uint32_t p,
                                                                            double own, const Bytes& core, Bytes& seen) const {
  std::vector<float> m;
  for (std::size_t q : region) m.push_back(mean3_at(q));
  std::nth_element(m.begin(), m.begin() + std::ptrdiff_t(m.size() / 2), m.end());
  const float floor = m[m.size() / 2];
  std::vector<std::vector<std::size_t>> out;
  std::vector<std::size_t> marked;
  for (std::size_t q : region) {
    if (seen[q] || mean3_at(q) < floor) continue;
    std::vector<std::size_t> comp{q};
    seen[q] = 2;
    bool joined = false;
    auto flood = [&](auto&& admit) {
      for (std::size_t head = 0; head < comp.size() && !joined; ++head)
        for_face_neighbours(d_, comp[head], [&](std::size_t r) {
          if (seen[r] == 1) joined = true;
          if (seen[r] || fluid_label_[r] != p || joined || !admit(r, mean3_at(r))) return;
          seen[r] = 2;
          comp.push_back(r);
        });
    };
    flood([&](std::size_t, float v) { return v >= own ? (joined = true, false) : v >= floor; });
    if (!joined && double(comp.size()) * voxel_ml_ >= kMinOtherLevelMl) flood([&](std::size_t r, float v) { return core[r] && v < own; });
    for (std::size_t c : comp) seen[c] = 1, marked.push_back(c);  // joined or small: no later flood passes it
    if (!joined && double(comp.size()) * voxel_ml_ >= kMinOtherLevelMl) out.push_back(std::move(comp));
  }
  for (std::size_t c : marked) seen[c] = 0;
  return out;
}

// A region of another level (COLONFLAT_SEGMENT_DEBUG): volume, centroid (LPS), median own HU, the
// level of its piece, and the plateau's volume when it lies behind a darker bridge (0: joined).
void ColonSegmenter::debug_other_level(const std::vector<std::size_t>& region, std::size_t plateau, float level) const {
  std::vector<float> v;
  double sum[3] = {0, 0, 0};
  for (std::size_t q : region) {
    std::size_t c[3];
    d_.coords(q, c[0], c[1], c[2]);
    for (int a = 0; a < 3; ++a) sum[a] += double(c[a]);
    v.push_back(hu_[q]);
  }
  const double n = double(v.size()), c[3] = {sum[0] / n, sum[1] / n, sum[2] / n};
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  const auto p = lps_of(c);
  std::fprintf(stderr, "other level %.2f mL at LPS (%.0f %.0f %.0f) crop (%.0f %.0f %.0f) HU %.0f, piece level %.0f: %s %.2f mL\n", n * voxel_ml_,
               p[0], p[1], p[2], c[0], c[1], c[2], v[v.size() / 2], level, plateau ? "behind a bridge, core" : "joined", double(plateau) * voxel_ml_);
}

// Candidate bodies (docs/segment.md step 6): face-connected candidate voxels, where two fluid pieces
// (split_fluid_bodies) are one body only when the fluid itself continues between them: at least
// kMinFluidPairShare of the face pairs across their boundary hold fluid (>= fluid-threshold) in both
// voxels' own values, not only in the 3 x 3 x 3 mean. Inside one lumen two pieces meet where the fluid
// narrows below the core ball, and the voxels there are fluid; a bridge across the walls of two
// pressed bowels is bright only in the mean (its voxels are wall). Voxels of no piece (gas and layer
// of a refused segment) join every body they touch. Labels follow the components' order, each
// component's bodies in raster order of their first voxel (no cut: the components' labels).
RunLabels ColonSegmenter::candidate_bodies(const Bytes& candidate) const {
  const RunLabels cl = component_runs(candidate.data(), d_);
  std::vector<std::uint64_t> units;  // (component << 32 | piece), sorted: a unit's index is its union-find id
  std::vector<PiecePair> pairs = piece_pairs(cl, candidate, units);
  std::sort(units.begin(), units.end());
  units.erase(std::unique(units.begin(), units.end()), units.end());
  auto unit_of = [&](std::uint32_t l, std::uint32_t piece) {
    return std::uint32_t(std::lower_bound(units.begin(), units.end(), (std::uint64_t(l) << 32) | piece) - units.begin());
  };
  std::sort(pairs.begin(), pairs.end(), [](const PiecePair& a, const PiecePair& b) { return a.key < b.key; });
  UnionFind uf(units.size());
  const bool debug = std::getenv("COLONFLAT_SEGMENT_DEBUG") != nullptr;
  for (std::size_t g0 = 0, g1; g0 < pairs.size(); g0 = g1) {  // one group per (component, piece, piece)
    std::size_t all = 0, fluid = 0;
    for (g1 = g0; g1 < pairs.size() && pairs[g1].key == pairs[g0].key; ++g1) all += pairs[g1].pairs, fluid += pairs[g1].fluid;
    const auto& [l, p0, p1] = pairs[g0].key;
    if (debug && p0)
      std::fprintf(stderr, "pieces %u and %u: %zu boundary pairs, %zu fluid in both voxels\n", p0, p1, all, fluid);
    if (p0 == 0 || double(fluid) >= kMinFluidPairShare * double(all)) uf.unite(unit_of(l, p0), unit_of(l, p1));
  }
  std::vector<std::uint32_t> label(units.size(), 0);
  std::vector<std::vector<Run>> runs;
  for (std::uint32_t l = 1; l <= cl.count(); ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r)
      for (std::size_t q = r->start, end = r->start + r->length; q < end;) {
        std::size_t e = q + 1;
        while (e < end && fluid_label_[e] == fluid_label_[q]) ++e;
        std::uint32_t& lab = label[uf.find(unit_of(l, fluid_label_[q]))];
        if (!lab) lab = std::uint32_t(runs.size() + 1), runs.emplace_back();
        runs[lab - 1].push_back({q, e - q});
        q = e;
      }
  RunLabels out;
  for (const auto& v : runs) {
    out.runs.insert(out.runs.end(), v.begin(), v.end());
    out.first.push_back(out.runs.size());
  }
  return out;
}

// The face pairs of candidate voxels of component l whose fluid pieces differ, counted per key (l,
// smaller piece, larger piece): pairs, and those fluid in both voxels' own values; consecutive pairs
// of one key share an entry, so a key may have several (unsorted). `units` gets the (component,
// piece) of every candidate voxel (unsorted; repeats only where not consecutive).
std::vector<PiecePair> ColonSegmenter::piece_pairs(const RunLabels& cl, const Bytes& candidate, std::vector<std::uint64_t>& units) const {
  std::vector<PiecePair> pairs;
  for (std::uint32_t l = 1; l <= cl.count(); ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r)
      for (std::size_t q = r->start; q < r->start + r->length; ++q) {
        const std::uint64_t unit = (std::uint64_t(l) << 32) | fluid_label_[q];
        if (units.empty() || units.back() != unit) units.push_back(unit);
        std::size_t c[3];
        d_.coords(q, c[0], c[1], c[2]);
        for (int a = 0; a < 3; ++a) {
          if (c[a] + 1 >= d_.n[a] || !candidate[q + d_.stride[a]]) continue;
          const std::uint32_t p0 = fluid_label_[q], p1 = fluid_label_[q + d_.stride[a]];
          if (p0 == p1) continue;
          const bool fluid = std::min(hu_[q], hu_[q + d_.stride[a]]) >= opts_.fluid_threshold;
          const std::array<std::uint32_t, 3> key{l, std::min(p0, p1), std::max(p0, p1)};
          if (pairs.empty() || pairs.back().key != key) pairs.push_back({key, 0, 0});  // a run's pairs mostly share a key
          ++pairs.back().pairs, pairs.back().fluid += fluid;
        }
      }
  return pairs;
}

}  // namespace cf::segment_detail
