#pragma once
// When the whole-band area pass stops (band_axis.cpp whole_band_done): the faces it can move and
// the rule on their measures, asked after each of its steps.
#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// The whole band's margins (under the targets 0.2, 5, 1.5): area ratio 5th / 95th percentiles and
// quasi-conformal mean. A band out of them gets the whole-band pass (band_axis.cpp needs_correction).
constexpr double kWholeBandAreaLow = 0.25, kWholeBandAreaHigh = 4.0, kWholeBandQcMean = 1.45;

// Whether the whole-band pass holds a face's corners (area_correct.cpp hold_crushed): its map area
// `area2` at the band's area scale `scale` is below `below` (coverage_min_ratio) x its 3D area.
inline bool crushed_in_band(double scale, double area2, double area3, double below) {
  return scale * area2 < below * area3;
}

// Per face of s its 3D area and signed map area (area3, area2: resized to s.t.size()), each face on
// its own (any thread); returns the band's area scale, 3D / map area summed in face order over the
// faces not degenerate (map areas below 0 as 0): correct_area()'s scale.
double band_areas(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate, std::vector<double>& area3,
                  std::vector<double>& area2);

// The vertices the whole-band pass holds on `emb` as it is (per vertex 1: a corner of a face in the
// map, not degenerate, crushed_in_band() at the band's scale): what correct_area() holds when it
// starts on this embedding. Size s.p.size().
std::vector<char> whole_band_held(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate,
                                  double below);

// The stop rule, fed the measures after each step (area p05 / p95, qc mean of the faces in the map):
// `all` over every face of the band, `free` over the faces the pass moves (no corner held by it).
// Stop when either
//  (a) all faces are within the area margins and their angles are settled: qc mean within its margin
//      or not lower than after the previous step (the first step, a full Newton step on the quadratic
//      part, may raise it): the rule before session 27; the real CT colon band stops at its 3rd step;
//  (b) the free faces are within the area margins and the pass has stopped improving them: judged every
//      kStallSteps steps against their measures kStallSteps steps before, their area p05 rose, their p95
//      fell and (unless within its margin) their qc mean fell each by less than kStallGain a step.
// (a) alone never holds on a band whose held faces (crushed pockets, 5-13 % of the U's colon bands)
// are over 5 % of it: they cannot move in this pass (the local passes open them), so its p05 stays
// where they put it and the pass used to run its whole budget.
// kStallGain: 0.1 % a step, below what the final qc mean moves by when the factor changes at rounding
// level (U120 2.602 -> 2.581, U60 2.353 -> 2.393: docs/flatten.md, session 26 "factor"). kStallSteps:
// longer than the lulls in the U bands' measures (U120's colon band: free p05 0.3023 -> 0.3027 over
// steps 45-49, then 2 % more by step 60; a 5-step window stopped it at 49 and its final p05 fell
// 0.159 -> 0.154), and past the first steps, where (a) stops the bands that meet their bounds (1-5
// on every row measured). Judged every kStallSteps steps, not every step: measuring the free faces is
// a second pass of the statistics (17.6 ms CPU on U120's 852 k faces, 43 ms on the CT's 2.06 M), ~1 s
// CPU over a 60-step pass; the CT's pass (3 steps) never measures them. docs/flatten.md, session 27
// "stoprule".
class WholeBandStop {
 public:
  static constexpr int kStallSteps = 8;
  static constexpr double kStallGain = 0.001;
  static bool within_area(const BoundStats& b) {
    return b.area_p05 >= kWholeBandAreaLow && b.area_p95 <= kWholeBandAreaHigh;
  }
  // (a), after each step; the caller measures the free faces only when this says go on.
  bool all_done(const BoundStats& all) {
    const bool angles = angles_settled(all.qc_mean, last_qc_);
    last_qc_ = all.qc_mean;
    return within_area(all) && angles;
  }
  // (a)'s angle part: qc mean `qc` after a step, `before` after the step before (infinity before the first).
  static bool angles_settled(double qc, double before) { return qc <= kWholeBandQcMean || qc >= before; }
  // Whether (b) is judged after step `step` (1, 2, ...; the caller measures the free faces then).
  static bool judges_free(int step) { return step % kStallSteps == 0; }
  // (b), after each step judges_free() names, when all_done() said go on.
  bool free_done(const BoundStats& free) {
    const auto stalled = [](double from, double gain) { return gain < kStallGain * kStallSteps * from; };
    const BoundStats& b = before_;
    const bool done = judged_ && within_area(free) && stalled(b.area_p05, free.area_p05 - b.area_p05) &&
                      stalled(b.area_p95, b.area_p95 - free.area_p95) &&
                      (free.qc_mean <= kWholeBandQcMean || stalled(b.qc_mean, b.qc_mean - free.qc_mean));
    before_ = free, judged_ = true;
    return done;
  }

 private:
  double last_qc_ = std::numeric_limits<double>::infinity();
  BoundStats before_;    // the free faces' measures kStallSteps steps before
  bool judged_ = false;  // before_ is set
};

// Rule (a) of WholeBandStop measured after each step as cheaply as its verdict allows (issue 26, session
// 34 "idle"): the same verdicts, step by step, as WholeBandStop::all_done() on bound_stats_in_map() of
// the band's distortion (the same area ratio and qc bits, summed in the same face order). Whether the
// area ratios are within the margins needs no percentile: the 5th is >= kWholeBandAreaLow exactly when
// at most k05 ratios are below it (the 95th likewise), so a step costs each face's map area and two
// counts. The qc mean is needed only when the areas are within the margins (then for this step and
// the one before, whose positions are kept): on U120's colon band (held faces keep its p05 at 0.04)
// never, on the CT rows' bands at their last 2 steps. A ratio that is NaN falls back to the percentiles.
class AllFacesCheck {
 public:
  // `frames`: band_frames() of the band's faces (kept by reference, as s and degenerate are).
  AllFacesCheck(const Surface& s, const std::vector<FaceFrame>& frames, const std::vector<char>& degenerate)
      : s_(s), frames_(frames), degenerate_(degenerate) {
    area3_.reserve(frames.size());
    for (const FaceFrame& fr : frames) area3_.push_back(fr.area3);
  }
  // Rule (a) on the map `emb` after the next step.
  bool all_done(const Embedding& emb);
  // The qc mean over the faces in the map at positions `pos` (corner offsets emb.dy): bound_stats_in_map()'s.
  double qc_mean(const std::vector<V2>& pos, const Embedding& emb);
  // Whether every face's area ratio is within the area margins (WholeBandStop::within_area of the faces in the map).
  bool within_area(const Embedding& emb);

 private:
  bool in_map(std::size_t f, double area2) const { return !degenerate_[f] && !too_small_in_map(area2, area3_[f]); }
  const Surface& s_;
  const std::vector<FaceFrame>& frames_;
  const std::vector<char>& degenerate_;
  std::vector<double> area3_;       // per face, frames_[f].area3 (the sums read them in face order)
  std::vector<double> area2_, qc_;  // per face, the last measure's
  std::vector<V2> before_;          // the positions after the step before, when its qc mean is not known
  double qc_before_ = std::numeric_limits<double>::infinity();
  bool known_ = true;               // qc_before_ is the qc mean after the step before
};

// The whole-band pass's stop check for band `w` as it is now (asked after each step; band_axis.cpp):
// WholeBandStop on the band's statistics over all faces in the map and over the faces none of whose
// corners whole_band_held() holds now. Keeps references to w, degenerate and o.
std::function<bool()> whole_band_done(const SegmentWork& w, const std::vector<char>& degenerate, const FlattenOptions& o);

}  // namespace cf::flat_detail
