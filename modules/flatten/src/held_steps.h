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
//   In the last local pass such a piece stops ("stuck") and goes to that rule as soon as its steps
//   have stayed below kStuckStep for kStallSteps steps, shown no wall over them, and fallen too
//   slowly to matter (kStuckFall): the CT mask's window took 62 such steps first (issue 26, session
//   30 "ctmask"). Not in the first pass: there the same crawl (462 steps, 0.6 of 1 262 mm2 shown)
//   is the window's ramp, and without it the last pass's spots do not open it (99.73 % shown
//   against 99.92 %).
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
  // A step cut below this fraction of the proxy's step is stuck: pieces open at 1e-5 .. 3e-2 once
  // their ramp is over; the CT mask's window steps at 1e-9 .. 4e-8.
  static constexpr double kStuckStep = 1e-6;
  // A stuck streak of kStallSteps steps or more that showed no wall stops the piece when its energy's
  // fall per step over its last kStallSteps steps, times the steps left in its budget, is below this
  // fraction of the energy (at that rate it could not even halve it): the window's crawl falls ~1.5e-4 a step (first pass:
  // 7 % of its 495-step budget); a strand stump's ramp, stuck too at first, falls 0.3-2 % a step.
  static constexpr double kStuckFall = 0.5;

  // `hidden` (optional): the piece's wall shown below coverage_min_ratio now (mm2); `leave_stuck`:
  // the "stuck" stop applies (it needs `hidden`).
  HeldSteps(const Surface& s, const Embedding& emb, std::function<double()> hidden, double tolerance,
            bool leave_stuck = false);
  // The largest step in [0, 1] keeping every face of `judged` positive along trial - emb.pos
  // (bitwise max_area_step(s, emb, trial, judged, area3, 0)); remembers the face that sets it.
  double cut(const std::vector<int>& judged, const std::vector<V2>& trial);
  // After a step taken at cut `limit` (cut()'s value) that took the energy from `before` to `after`,
  // with `steps_left` steps of the budget left: why the piece stops ("held": stalled and done;
  // "stuck": stalled below kStuckStep, showing nothing), or nullptr to go on.
  const char* stop(double limit, double before, double after, int steps_left);
  // The face of `judged` that set the last cut() (the first with the smallest limit), -1 when none held it below 1.
  int limiting_face() const { return limiting_; }
  // The largest cut() of the descent (0 before any).
  double largest_cut() const { return largest_; }

 private:
  const Surface& s_;
  const Embedding& emb_;
  std::function<double()> hidden_;
  double tolerance_ = 0, last_hidden_ = -1;  // -1: not measured in this streak
  std::vector<int> recent_;    // the faces that set the last kRecent cuts
  int limiting_ = -1, streak_ = 0;
  double largest_ = 0;
  // The stuck streak: whether it may stop the piece, the energies before and after its last
  // kStallSteps steps (empty: no streak), its steps counted, the hidden wall after its first step.
  bool leave_stuck_ = false;
  std::vector<double> stuck_energies_;
  long stuck_ = 0;
  double stuck_hidden_ = 0;
  bool stuck_at(double limit, double before, double after, int steps_left);
};

}  // namespace cf::flat_detail
