#pragma once
// Descent with a quadratic proxy on a region of the band (the "accelerated quadratic proxy" idea):
// direction d = -A^-1 grad E / 2 with A the region's system matrix (a cotangent Laplacian,
// factorised once), step 0.9 x the largest keeping every judged face positive (no fold can
// appear), halved until the Armijo condition holds (after 30 halvings the last trial is kept if it
// still lowers E). Shared by the symmetric-Dirichlet balancing (area_balance.cpp) and the area
// correction (area_correct.cpp).
// Energy: const std::vector<int>& faces() const (the faces it sums over);
//         double energy(const std::vector<V2>& pos) const (>= Energy::kHuge: not injective);
//         void face_gradients(const std::vector<V2>& pos, std::vector<std::array<V2, 3>>& g) const
//           (per face of faces(), the gradient with respect to each corner).
// Every per-face loop runs on all worker threads in fixed blocks (face_blocks.h): the steps are
// the same for any thread count.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <type_traits>
#include <utility>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "face_blocks.h"
#include "flatten_internal.h"
#include "held_steps.h"

namespace cf::flat_detail {

struct DescentResult {
  int steps = 0;                                // steps taken (the last one, below min_gain, not counted)
  double energy_before = 0, energy_after = 0;
  // Why it stopped: "steps" (max_steps taken), "converged" (gain below min_gain), "no descent"
  // (no step lowers E, or the direction does not descend), "not injective" (E infinite at the start),
  // "bounds met" (the caller's `enough` said so after a step), "held" (the steps stalled on the
  // same faces' fold-free cut once the piece was done: held_steps.h).
  const char* stop = "steps";
};

// The gradient over the unknowns of a region system from per-face corner gradients: each unknown
// sums the corners it is, in face order (the order a sequential scatter over the faces adds them).
class CornerGather {
 public:
  CornerGather(const Surface& s, const std::vector<int>& faces, const RegionSystem& sys);
  // n x 2 (n = unknowns of sys).
  Eigen::MatrixXd sum(const std::vector<std::array<V2, 3>>& face_gradients) const;

 private:
  std::vector<int> start_, corner_;  // unknown u's corners (3 i + k): corner_[start_[u] .. start_[u + 1])
};

// COLONFLAT_FLATTEN_DEBUG_DESCENT=N: one stderr line per step taken by every descent over exactly N
// faces (a local piece's face count, as its "local piece" debug line gives it): the step length as a
// fraction of the proxy's full step, the energy, its relative gain, and the judged faces' smallest map /
// 3D area ratio (the map unscaled) with how many are below 1e-3. It tells a piece's ramp (crushed faces
// growing at a bounded factor a step) from its tail (a step length held by the fold-free cut while the
// energy creeps down): docs/flatten.md, session 28 "localpass". Reads the map only.
class DescentTrace {
 public:
  explicit DescentTrace(std::size_t faces) {
    const char* want = std::getenv("COLONFLAT_FLATTEN_DEBUG_DESCENT");
    on_ = want && std::strtoull(want, nullptr, 10) == faces;
    faces_ = faces;
  }
  void step(const Surface& s, const Embedding& emb, const std::vector<int>& judged, const std::vector<double>& area3,
            int step, double t, double energy, double gain) const {
    if (!on_) return;
    double least = 1e300;
    std::size_t below = 0;
    for (int f : judged) {
      const double r = emb.area2(s, f) / std::max(area3[f], 1e-300);
      least = std::min(least, r), below += r < 1e-3;
    }
    std::fprintf(stderr, "flatten debug descent %zu faces, step %d: t %.3g, energy %.8g, gain %.3g, least ratio %.3g, "
                 "%zu below 1e-3\n", faces_, step, t, energy, gain, least, below);
  }

 private:
  bool on_ = false;
  std::size_t faces_ = 0;
};

// At most `max_steps` steps moving the unknowns of `sys` in emb.pos; stops when E gains less than
// `min_gain` (relative) or no step lowers it. `judged`: the faces kept positive (the energy's).
// `enough` (optional): asked after each step taken; true stops the descent there (its goal is met).
// `scratch` (optional): a vector of emb.pos's size for the trial positions, shared by regions that run
// side by side (each writes only its own vertices; one allocation of the mesh's size per region
// instead: 59 local pieces of the real CT colon band zeroed 1 GB).
// `times` (optional): where the steps' wall time went (COLONFLAT_FLATTEN_DEBUG prints it; a check
// beside the next step counts its own wall time, which overlaps that step's gradient and solve).
// `check_beside` (with `enough`): past the first kChecksAlone steps, each step's `enough` runs on
// one thread while the next step's gradient and solve run beside it (parallel_tasks; both only
// read emb.pos, which changes only when a step is taken), and that next step is dropped when
// `enough` says stop. The same steps and bits as asking it after the step (the next step's work is
// that of its own turn); the check's wall time is hidden behind the one-core solve when the solve
// is longer, and a check that stops costs the dropped step's gradient and solve (CPU; wall where
// they outlast the check). On one thread the check runs alone, as without it. For descents whose
// checks mostly say "go on": the whole-band pass (60 steps on the U's colon bands, each check
// ~0.03 s beside a ~0.08 s gradient and solve); `enough` must not write what the step reads.
// The first kChecksAlone checks run after their step: a band that meets its bounds does so within
// a few steps (the real CT colon band at its 3rd, the U's branches at their 1st-3rd), where a step
// beside the stopping check is wasted (CT, load 7: +0.8 CPU s, +1.6 s wall for its pass). Session
// 27 (whole_band_stop.h): the whole-band rule's first part stops bands at steps 1-5 on every row
// measured, its second part only at multiples of 8 from 16 on (U180's colon band at 24, the U's
// 140-150 k-face branch bands at 16), where the one dropped step is the price of 11+ checks hidden
// behind the solve before it: kept at 5.
// `held` (optional, local pieces): computes each step's cut (the same bits) and stops the descent
// ("held") when its steps have stalled on the same faces' cut and its `done` says so.
constexpr int kChecksAlone = 5;

// Whether an Energy also offers double energy_and_gradients(pos, g) const: energy(pos) and, when it
// is below kHuge, face_gradients(pos, g), the same bits as each alone. The line search then asks it at
// each trial, and the step it takes needs no gradient pass of its own (one read of the faces' corners
// a step instead of two).
template <class Energy, class = void>
struct FusedGradients : std::false_type {};
template <class Energy>
struct FusedGradients<Energy, std::void_t<decltype(std::declval<const Energy&>().energy_and_gradients(
                                  std::declval<const std::vector<V2>&>(), std::declval<std::vector<std::array<V2, 3>>&>()))>>
    : std::true_type {};

template <class Energy>
DescentResult proxy_descent(const Surface& s, Embedding& emb, const Energy& energy, const RegionSystem& sys,
                            const std::vector<int>& judged, const std::vector<double>& area3, int max_steps,
                            double min_gain, const std::function<bool()>& enough = {},
                            std::vector<V2>* scratch = nullptr, StepTimes* times = nullptr, bool check_beside = false,
                            HeldSteps* held = nullptr) {
  DescentResult res;
  StepTimes spent;
  double e0 = res.energy_before = res.energy_after = energy.energy(emb.pos);
  if (e0 >= Energy::kHuge) {  // the region is not injective: leave it
    res.stop = "not injective";
    return res;
  }
  const std::vector<int>& unknowns = sys.unknowns();
  const CornerGather gather(s, energy.faces(), sys);
  std::vector<std::array<V2, 3>> face_gradients(energy.faces().size());
  constexpr bool fused = FusedGradients<Energy>::value;
  std::vector<std::array<V2, 3>> trial_gradients(fused ? face_gradients.size() : 0);  // at the line search's trial
  bool have_gradients = false;  // face_gradients are emb.pos's (from the step's accepted trial)
  // emb.pos with the unknowns moved, filled only where the region reads it (its faces' corners):
  // regions far apart may run side by side on one embedding, each reading and writing its own.
  std::vector<V2> own;
  if (!scratch) own.resize(emb.pos.size());
  std::vector<V2>& trial = scratch ? *scratch : own;
  for (const std::vector<int>* list : {&energy.faces(), &judged})
    for (int f : *list)
      for (int v : s.t[f]) trial[v] = emb.pos[v];
  for (int v : unknowns) trial[v] = emb.pos[v];
  auto move_to = [&](const Eigen::MatrixXd& d, double t) {
    for_each_block(unknowns.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) trial[unknowns[i]] = emb.pos[unknowns[i]] + t * V2(d(i, 0), d(i, 1));
    });
  };
  Eigen::MatrixXd g, d;  // the step's gradient (n x 2) and direction
  auto direction = [&] {  // of the step from emb.pos
    Stopwatch clock;
    if (!have_gradients) energy.face_gradients(emb.pos, face_gradients);
    have_gradients = false;
    g = gather.sum(face_gradients);
    spent.gradient += clock.lap();
    d = -sys.solve_raw(g) / 2;
    spent.solve += clock.lap();
  };
  bool ready = false;  // g and d are the next step's (computed beside the last check)
  const DescentTrace trace(energy.faces().size());
  for (; res.steps < max_steps; ++res.steps) {
    if (!ready) direction();
    ready = false;
    Stopwatch clock;
    const double slope = (g.array() * d.array()).sum();
    if (!(slope < 0)) {
      res.stop = "no descent";
      break;
    }
    move_to(d, 1.0);
    const double limit = held ? held->cut(judged, trial) : max_area_step(s, emb, trial, judged, area3, 0.0);
    double t = std::min(1.0, 0.9 * limit);
    spent.step_limit += clock.lap();
    double e1 = Energy::kHuge;
    for (int half = 0; half < 30; ++half, t *= 0.5) {
      move_to(d, t);
      if constexpr (fused) e1 = energy.energy_and_gradients(trial, trial_gradients);
      else e1 = energy.energy(trial);
      ++spent.energy_evals;
      if (e1 <= e0 + 1e-4 * t * slope) break;
    }
    spent.line_search += clock.lap();
    if (!(e1 < e0)) {
      res.stop = "no descent";
      break;
    }
    for (int v : unknowns) emb.pos[v] = trial[v];
    if constexpr (fused) face_gradients.swap(trial_gradients), have_gradients = true;
    const double gain = (e0 - e1) / e0, e_before = e0;
    trace.step(s, emb, judged, area3, res.steps, t, e1, gain);
    e0 = res.energy_after = e1;
    if (!(gain > min_gain)) {
      res.stop = "converged";
      break;
    }
    if (const char* why = held ? held->stop(limit, e_before, e1, max_steps - res.steps - 1) : nullptr) {
      ++res.steps;
      res.stop = why;
      break;
    }
    bool met = false;
    if (enough && check_beside && res.steps >= kChecksAlone && res.steps + 1 < max_steps && thread_count() > 1) {
      double check_s = 0;
      parallel_tasks({[&] {
                        const Stopwatch own;
                        met = enough();
                        check_s = own.seconds();
                      },
                      direction});
      spent.check += check_s, ready = !met;
    } else {
      met = enough && enough();
      spent.check += clock.lap();
    }
    if (met) {
      ++res.steps;
      res.stop = "bounds met";
      break;
    }
  }
  if (times) *times = spent;
  return res;
}

}  // namespace cf::flat_detail
