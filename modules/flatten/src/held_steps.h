#pragma once
// What holds a local piece's steps (issue 26, docs/flatten.md session 29 "tail"). The area
// correction's proxy (proxy_descent.h) is the cotangent Laplacian alone: at a face whose area
// penalty is steep (its gradient grows as 1 / its map area) the direction sends a corner far past
// the penalty's minimum, and the fold-free cut (no face may pass through zero area) shrinks the
// whole piece's step to that face. Two cases cost the CT mask row's local passes most of their time:
// - the tail: a piece that has shown its hidden wall goes on for hundreds of steps at a constant
//   ~4e-4 of the proxy's step, the cut set by the same one or two faces every step (the strand
//   stump: 1 540 of its 2 439 steps, energy -20 %, nothing more shown); such a piece stops ("held");
// - the frozen window: every step of a piece at 1e-9 .. 1e-6 of the proxy's step, held by the
//   hundreds of faces at ratio 1e-6 .. 1e-3 around denoise's contact window; the crushed-spot rule
//   (area_correct.cpp) opens those faces, not only the ones below 1e-4, when largest_cut() says so.
// Per descent; serial bookkeeping over the cut's per-face limits: the same for any thread count.
#include <functional>
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

class HeldSteps {
 public:
  // A step whose fold-free cut is below this fraction of the proxy's full step is held. Pieces that
  // open normally step at 2e-3 .. 3e-2 of it; the stump's tail at 3.6e-4 .. 4e-4.
  static constexpr double kHeldStep = 1e-3;
  // The face that sets a held step's cut "recurs" when it set one of the kRecent cuts before (the
  // stump's tail alternates between two faces).
  static constexpr int kRecent = 4;
  // After this many held steps in a row, each cut by a recurring face, the piece's hidden wall is
  // measured, and again every kStallSteps / 4 steps while the streak lasts; the piece stops when its
  // hidden wall is within `tolerance` and no smaller than at the measure before (the held steps show
  // no more wall). A piece in its ramp (crushed faces growing by a bounded factor a step, the cut
  // often set again by a face it set a few steps before) hides more than that, and one still
  // opening its last faces shows more at each measure: both go on.
  static constexpr int kStallSteps = 32;

  // `hidden` (optional): the piece's wall shown below coverage_min_ratio now (mm2).
  HeldSteps(const Surface& s, const Embedding& emb, std::function<double()> hidden, double tolerance);
  // The largest step in [0, 1] keeping every face of `judged` positive along trial - emb.pos
  // (bitwise max_area_step(s, emb, trial, judged, area3, 0)); remembers the face that sets it.
  double cut(const std::vector<int>& judged, const std::vector<V2>& trial);
  // After a step taken at cut `limit` (cut()'s value): true when the piece has stalled and is done.
  bool stop(double limit);
  // The largest cut() of the descent (0 before any).
  double largest_cut() const { return largest_; }

 private:
  const Surface& s_;
  const Embedding& emb_;
  std::function<double()> hidden_;
  double tolerance_ = 0, last_hidden_ = -1;  // -1: not measured in this streak
  std::vector<double> limit_;  // per judged face: its fold limit at the last cut()
  std::vector<int> recent_;    // the faces that set the last kRecent cuts
  int limiting_ = -1, streak_ = 0;
  double largest_ = 0;
};

}  // namespace cf::flat_detail
