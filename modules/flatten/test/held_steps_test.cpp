// The stops of a local piece's descent that watch what holds its steps (held_steps.h), fed with
// step sequences written out here: their cuts, energies and hidden wall.
#include <gtest/gtest.h>

#include <cstring>

#include "../src/held_steps.h"

namespace cf {
namespace {

using flat_detail::HeldSteps;

// A descent's steps as HeldSteps sees them: each at cut `limit(k)`, the energy falling by `fall(k)`
// (relative) a step from 1e5, the piece's hidden wall `hidden(k)` mm2 after step k, a budget of
// `budget` steps. Returns the step (1-based) at which stop() said `why`, or 0 if it never did.
template <class Limit, class Fall, class Hidden>
int first_stop(bool leave_stuck, int budget, const char* why, Limit&& limit, Fall&& fall, Hidden&& hidden) {
  const flat_detail::Surface s;
  const flat_detail::Embedding emb;
  int k = 0;
  HeldSteps held(s, emb, [&] { return hidden(k); }, 1.0, leave_stuck);
  double e = 1e5;
  for (k = 0; k < budget; ++k) {
    const double after = e * (1 - fall(k));
    const char* said = held.stop(limit(k), e, after, budget - k - 1);
    e = after;
    if (said) return std::strcmp(said, why) == 0 ? k + 1 : -(k + 1);
  }
  return 0;
}

// The CT mask window's crawl in the last local pass: every cut ~1e-8 of the proxy's step, the
// energy -1.5e-4 a step, nothing shown: "stuck" at the first judgement, after kStallSteps steps
// (at that rate its 164-step budget lowers the energy by ~2.5 %, far from half).
TEST(HeldSteps, StuckCrawlShowingNothingStopsAfterItsStreak) {
  const int at = first_stop(true, 164, "stuck", [](int) { return 1e-8; }, [](int) { return 1.5e-4; },
                            [](int) { return 1262.0; });
  EXPECT_EQ(at, HeldSteps::kStallSteps);
}

// What goes on: a ramp (cuts as small, the energy -2 % a step: at that rate it could halve it many
// times over, until the last ~34 steps of its 2 000-step budget),
// a crawl that shows wall (its hidden wall shrinking), a pass that does not leave stuck pieces, and
// steps above kStuckStep; a step above kStuckStep restarts the streak.
TEST(HeldSteps, RampWallShownOrLargerStepsGoOn) {
  const auto tiny = [](int) { return 1e-8; };
  const auto slow = [](int) { return 1.5e-4; };
  const auto fixed_wall = [](int) { return 1262.0; };
  const int ramp = first_stop(true, 2000, "stuck", tiny, [](int) { return 0.02; }, fixed_wall);
  EXPECT_TRUE(ramp == 0 || ramp > 2000 - 2 * HeldSteps::kStallSteps) << ramp;  // (the budget's last steps)
  EXPECT_EQ(first_stop(true, 500, "stuck", tiny, slow, [](int k) { return 1262.0 - k; }), 0);
  EXPECT_EQ(first_stop(false, 500, "stuck", tiny, slow, fixed_wall), 0);
  EXPECT_EQ(first_stop(true, 500, "stuck", [](int) { return 10 * HeldSteps::kStuckStep; }, slow, fixed_wall), 0);
  const int restarted = first_stop(true, 500, "stuck", [](int k) { return k == 20 ? 1e-3 : 1e-8; }, slow, fixed_wall);
  EXPECT_EQ(restarted, 21 + HeldSteps::kStallSteps);
}

// The rate is weighed against the steps left: the same crawl with a budget of 5 000 steps would
// lower the energy by more than half, so it goes on until few enough steps are left.
TEST(HeldSteps, StuckStreakIsWeighedAgainstTheStepsLeft) {
  const int at = first_stop(true, 5000, "stuck", [](int) { return 1e-8; }, [](int) { return 1.5e-4; },
                            [](int) { return 1262.0; });
  // the fall per step over the last kStallSteps steps (~1.5e-4) x steps left < 0.5 once fewer than
  // ~3 334 steps are left, judged every kStallSteps / 4 steps: at step 1 664.
  EXPECT_EQ(at, 1664);
}

}  // namespace
}  // namespace cf
