// Open interfaces (docs/segment.md step 6, issue 25 session 12): where gas and tagged fluid meet
// along an image axis, is there tissue between them? Fluid and gas in one lumen meet directly (the
// profile crosses the soft-tissue range only within the partial-volume blur); two lumens pressed
// together keep their walls between them (at least two bowel walls, >= 2 mm of tissue), and bowels
// lying apart have fat between them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "segment_internal.h"
#include "segment_linkgrid.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kGas = 1, kCandidate = 4;
// A direct gas/fluid interface crosses the tissue range (kTissueLowHu..kTissueHighHu) in about 0.6
// blur sigma (the blurred step from -1000 to 500-900 HU).
constexpr int kSubSamples = 8;  // samples per voxel of the linear profile between voxel centres
// Columns whose gas and fluid lie within kWindowMm are looked at: wide enough that a wall of two
// bowel walls (2-6 mm) between them is seen (interface-width, 3 mm, is the layer taken as lumen).
constexpr double kWindowMm = 6;
// One lumen: the open columns cover >= 1 cm^2 (as a level, docs/segment.md step 4: a colon's
// cross-section is 7-50 cm^2) and are most of the pair's columns (a wall seen open where it is
// thinner than a voxel stays a minority).
constexpr double kMinOpenAreaMm2 = 100, kMinOpenShare = 0.5;
}  // namespace

// Longest run (mm) of the profile along a line (linear between voxel centres) inside the tissue
// range, from position a to position b (voxel indices along the line).
double ColonSegmenter::tissue_run_mm(std::size_t base, std::size_t stride, int a, int b, double h) const {
  double run = 0, best = 0;
  for (int p = a; p < b; ++p) {
    const double v0 = hu_[base + std::size_t(p) * stride], v1 = hu_[base + std::size_t(p + 1) * stride];
    for (int s = 0; s < kSubSamples; ++s) {
      const double v = v0 + (v1 - v0) * (s + 0.5) / kSubSamples;
      run = v >= kTissueLowHu && v <= kTissueHighHu ? run + h / kSubSamples : 0;
      best = std::max(best, run);
    }
  }
  return best;
}

// Every column along each image axis where the gas of a colon segment or of a candidate meets the
// fluid (>= fluid-threshold) of another candidate within kWindowMm: per (candidate, gas owner) the
// columns and the open ones (no tissue between). Owner: the segment's link-grid id, or kKeptCandidateId + candidate.
std::map<std::pair<std::uint32_t, std::uint32_t>, InterfaceTally> ColonSegmenter::gas_fluid_interfaces(const RunLookup& cand) const {
  std::map<std::pair<std::uint32_t, std::uint32_t>, InterfaceTally> out;
  std::mutex lock;
  for (int axis = 0; axis < 3; ++axis) {
    const int wvox = int(std::ceil(kWindowMm / d_.sp[axis]));
    const std::size_t stride = d_.stride[axis], len = d_.n[axis];
    parallel_for(d_.total / len, [&](std::size_t l0, std::size_t l1) {
      std::map<std::pair<std::uint32_t, std::uint32_t>, InterfaceTally> local;
      for (std::size_t l = l0; l < l1; ++l) {
        const std::size_t base = line_base(d_, axis, l);
        int last_kind = 0, last_pos = -1000000;
        for (int p = 0; p < int(len); ++p) {
          const std::size_t q = base + std::size_t(p) * stride;
          const bool gas = hu_[q] < opts_.air_threshold && (lab_[q] == kGas || lab_[q] == kCandidate);
          const int k = gas ? 1 : (lab_[q] == kCandidate && hu_[q] >= opts_.fluid_threshold ? 2 : 0);
          if (!k) continue;
          if (last_kind && last_kind != k && p - last_pos - 1 <= wvox) {
            const std::size_t g = k == 1 ? q : base + std::size_t(last_pos) * stride, f = k == 1 ? base + std::size_t(last_pos) * stride : q;
            const std::uint32_t fl = cand.at(f);
            const std::uint32_t owner = lab_[g] == kGas ? grid_->segment_at(g, d_) : kKeptCandidateId + cand.at(g);
            if (owner && owner != kKeptCandidateId + fl && owner != kKeptCandidateId) {
              const double run = tissue_run_mm(base, stride, last_pos, p, d_.sp[axis]);
              InterfaceTally& t = local[{fl, owner}];
              ++t.bins[std::min(5, int(run / 0.5))];
              t.columns[axis] += 1;
              t.open[axis] += run < kOpenWallMm;
            }
          }
          last_kind = k;
          last_pos = p;
        }
      }
      std::lock_guard<std::mutex> g(lock);
      for (const auto& [key, t] : local) out[key].add(t);
    });
  }
  return out;
}

// One lumen: the pair's open columns cover >= kMinOpenAreaMm2 (summed over the three axes) and are
// >= kMinOpenShare of its columns.
bool ColonSegmenter::one_lumen(const InterfaceTally& t) const {
  double open_mm2 = 0;
  std::size_t columns = 0, open = 0;
  for (int a = 0; a < 3; ++a) {
    open_mm2 += double(t.open[a]) * d_.sp[0] * d_.sp[1] * d_.sp[2] / d_.sp[a];
    columns += t.columns[a], open += t.open[a];
  }
  return open_mm2 >= kMinOpenAreaMm2 && double(open) >= kMinOpenShare * double(columns);
}

// The link-grid id of the colon body that gas owner `owner` (a segment id, or kKeptCandidateId +
// candidate) belongs to now; 0 when it is the gas of a candidate not kept.
std::uint32_t ColonSegmenter::colon_body_of(std::uint32_t owner) const {
  return owner >= kKeptCandidateId ? kept_id_[owner - kKeptCandidateId] : owner;
}

// Candidate l's fluid meets the gas of a colon body (a segment, or a candidate kept already) in one
// lumen (one_lumen). Returns that body's link-grid id (the first such body), 0 if none.
std::uint32_t ColonSegmenter::meets_colon_gas(std::uint32_t l) const {
  for (auto it = interfaces_.lower_bound({l, 0}); it != interfaces_.end() && it->first.first == l; ++it) {
    const std::uint32_t body = colon_body_of(it->first.second);
    if (body && one_lumen(it->second)) return body;
  }
  return 0;
}

// The other way round (an open interface is one lumen whichever side is colon already): candidate
// l's gas meets the fluid of a kept candidate in one lumen. Returns that body's id, 0 if none.
std::uint32_t ColonSegmenter::gas_meets_colon_fluid(std::uint32_t l) const {
  for (const auto& [key, t] : interfaces_) {
    const std::uint32_t body = key.second == kKeptCandidateId + l ? kept_id_[key.first] : 0;
    if (body && one_lumen(t)) return body;
  }
  return 0;
}

// Eligible candidates in one lumen with a colon body (their fluid meets its gas, or their gas meets
// its fluid, with no wall between) join that body: its ends are theirs, they use none of their own
// (a piece of the lumen's fluid or gas has no end of its own). Repeated until nothing joins (a body
// joined may be the gas or fluid another one meets). Returns the number kept.
std::size_t ColonSegmenter::join_open_bodies(std::vector<unsigned char>& eligible, std::vector<std::string>& why,
                                             std::vector<double>& kept_gap) {
  std::size_t kept = 0;
  for (bool again = true; again;) {
    again = false;
    for (std::uint32_t l = 1; l < eligible.size(); ++l) {
      if (!eligible[l]) continue;
      std::uint32_t body = meets_colon_gas(l);
      why[l] = body ? kOpenFluidReason : why[l];
      if (!body && (body = gas_meets_colon_fluid(l))) why[l] = kOpenGasReason;
      if (!body) continue;
      kept_gap[l] = 0, eligible[l] = 0, kept_id_[l] = body;
      grid_->absorb(l, body);
      ++kept, again = true;
    }
  }
  return kept;
}

// Every (candidate, gas body) interface of >= 8 columns: columns, open ones, tissue runs (0.5 mm bins).
void ColonSegmenter::debug_interfaces(const std::vector<BodyStats>& bodies) const {
  for (const auto& [key, t] : interfaces_) {
    const std::size_t cols = t.columns[0] + t.columns[1] + t.columns[2], open = t.open[0] + t.open[1] + t.open[2];
    if (cols < 8) continue;
    std::fprintf(stderr, "iface cand %u (%.1f mL) gas of %x: columns %zu open %zu runs", key.first, double(bodies[key.first].voxels) * voxel_ml_,
                 key.second, cols, open);
    for (std::size_t b : t.bins) std::fprintf(stderr, " %zu", b);
    std::fprintf(stderr, "\n");
  }
}

}  // namespace cf::segment_detail
