// The stops of a local piece's descent that watch what holds its steps (held_steps.h), fed with
// step sequences written out here: their cuts, energies and hidden wall.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "../src/face_blocks.h"
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

// cut() over judged faces in several blocks (3 x kFaceBlock + 5 separate triangles, listed last to
// first) is the smallest face_step_limit() to the bit, and the face it names is the first in the
// list among those tied at it (two identical faces in different blocks), as a serial scan finds it.
TEST(HeldSteps, CutIsTheFirstSmallestFaceLimitAcrossBlocks) {
  flat_detail::Surface s;
  flat_detail::Embedding emb;
  std::vector<flat_detail::V2> next;
  const int n = int(3 * flat_detail::kFaceBlock + 5);
  for (int f = 0; f < n; ++f) {
    const double shrink = f == 9000 || f == 20000 ? 4.0 : f == 3 ? 2.0 : 1.2 + 1e-5 * (f % 97);  // at the edge at t = 1 / shrink
    const double x = 2.0 * f;
    for (const flat_detail::V2& c : {flat_detail::V2(x, 0), flat_detail::V2(x + 1, 0), flat_detail::V2(x + 0.3, 1)}) {
      s.p.emplace_back(c.x(), c.y(), 0.0), emb.pos.push_back(c), next.push_back(c);
    }
    next.back().y() -= shrink;
    s.t.push_back({3 * f, 3 * f + 1, 3 * f + 2});
    emb.dy.push_back({0.0, 0.0, 0.0});
  }
  std::vector<int> judged(std::size_t(n), 0);
  for (int i = 0; i < n; ++i) judged[std::size_t(i)] = n - 1 - i;
  HeldSteps held(s, emb, [] { return 0.0; }, 1.0);
  const double want = flat_detail::face_step_limit(s, emb, next, 9000, 0.0);
  ASSERT_EQ(want, flat_detail::face_step_limit(s, emb, next, 20000, 0.0));
  EXPECT_EQ(want, 0.25);
  EXPECT_EQ(held.cut(judged, next), want);
  EXPECT_EQ(held.limiting_face(), 20000);
  std::vector<flat_detail::V2> still = emb.pos;  // no move: nothing holds the step
  EXPECT_EQ(held.cut(judged, still), 1.0);
  EXPECT_EQ(held.limiting_face(), -1);
}

}  // namespace
}  // namespace cf
