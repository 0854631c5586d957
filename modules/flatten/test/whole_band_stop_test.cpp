// The whole-band pass's stop rule (src/whole_band_stop.h, band_axis.cpp whole_band_done): a band
// whose held faces keep its area p05 below the margin stops once the faces the pass moves are within
// the margins and no longer improve; a band whose free faces still improve goes on; the rule before
// (all faces within the margins, angles settled) still stops a band at once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "colonflat/core/threads.h"
#include "squeezed_grid.h"
#include "../src/whole_band_stop.h"

namespace cf {
namespace {

using flat_detail::BoundStats;
using flat_detail::WholeBandStop;

// Steps until `rule` says stop on the measures step k -> (all(k), free(k)), or `budget` + 1.
template <class All, class Free>
int steps_to_stop(All all, Free free, int budget = 60) {
  WholeBandStop rule;
  for (int k = 1; k <= budget; ++k)
    if (rule.all_done(all(k)) || (WholeBandStop::judges_free(k) && rule.free_done(free(k)))) return k;
  return budget + 1;
}

const auto held_low = [](int) { return BoundStats{0.05, 2.0, 3.0}; };  // all faces: p05 held below the margin

// Free faces within the margins whose measures move by less than kStallGain a step stop the pass at
// the second step that judges them (every kStallSteps steps); free faces whose p05, p95 or qc mean
// still improve by more than that, or whose p05 is below the margin, do not stop it within 60 steps.
TEST(WholeBandStop, FreeFacesStopWhenTheyNoLongerImprove) {
  const double slow = 0.5 * WholeBandStop::kStallGain, fast = 2.0 * WholeBandStop::kStallGain;  // per step
  EXPECT_EQ(steps_to_stop(held_low, [&](int k) { return BoundStats{0.3 * (1 + slow * k), 2.0, 2.5 * (1 - slow * k)}; }),
            2 * WholeBandStop::kStallSteps);
  EXPECT_EQ(steps_to_stop(held_low, [&](int k) { return BoundStats{0.3 * (1 + fast * k), 2.0, 2.5}; }), 61);
  EXPECT_EQ(steps_to_stop(held_low, [&](int k) { return BoundStats{0.3, 2.0 * (1 - fast * k), 2.5}; }), 61);
  EXPECT_EQ(steps_to_stop(held_low, [&](int k) { return BoundStats{0.3, 2.0, 2.5 * (1 - fast * k)}; }), 61);
  EXPECT_EQ(steps_to_stop(held_low, [&](int) { return BoundStats{0.24, 2.0, 1.2}; }), 61);
  // angles within their margin: the area measures alone decide
  EXPECT_EQ(steps_to_stop(held_low, [&](int k) { return BoundStats{0.3, 2.0, 1.2 + fast * k}; }),
            2 * WholeBandStop::kStallSteps);
}

// The rule before session 27 is kept: all faces within the area margins stop the pass at once when
// their qc mean is within its margin, or at the first step that does not lower it (the real CT colon
// band's 3rd); no free-face measure is needed for that.
TEST(WholeBandStop, AllFacesWithinTheMarginsStopAsBefore) {
  const auto never = [](int) { return BoundStats{0.1, 2.0, 3.0}; };
  EXPECT_EQ(steps_to_stop([](int) { return BoundStats{0.3, 2.0, 1.3}; }, never), 1);
  EXPECT_EQ(steps_to_stop([](int k) { return BoundStats{k < 3 ? 0.24 : 0.26, 2.0, 1.47 + 0.001 * k}; }, never), 3);
  EXPECT_EQ(steps_to_stop([](int k) { return BoundStats{0.3, 2.0, 3.0 - 0.01 * k}; }, never), 61);
}

// A 48 x 24 band whose map squeezes columns [16, 32) to 0.15 of their width (below the area margin)
// and crushes columns [36, 40) to 0.01 (below coverage_min_ratio: held by the whole-band pass, 8 % of
// the faces, so the band's area p05 over all faces cannot reach the margin). The check stops the
// pass before the pass ends by itself, on "bounds met", with the free faces' p05 within the margin
// and the band's own p05 still below it; the same steps and bits on 1 and 2 threads.
TEST(WholeBandStop, BandWithHeldFacesStopsOnceItsFreeFacesAreDone) {
  FlattenOptions o;
  std::vector<flat_detail::V2> final_pos[2];
  for (int threads : {1, 2}) {
    set_thread_count(threads);
    test_shapes::SqueezedGrid g(0.15, 2);
    double x = 0;
    for (int i = 0; i < g.nx; ++i) {  // column i's left edge at x
      for (int j = 0; j < g.ny; ++j) g.emb.pos[std::size_t(j * g.nx + i)].x() = x;
      x += i >= 16 && i < 32 ? 0.15 : i >= 36 && i < 40 ? 0.01 : 1.0;
    }
    test_shapes::SqueezedGrid free_run = g;
    const auto run_free = flat_detail::correct_area(free_run.s, free_run.vf, free_run.emb, free_run.fixed,
                                                    free_run.degenerate, false, o);
    flat_detail::SegmentWork w;
    w.ann = g.s, w.emb = g.emb;
    const auto run = flat_detail::correct_area(w.ann, g.vf, w.emb, g.fixed, g.degenerate, false, o, false,
                                               flat_detail::whole_band_done(w, g.degenerate, o));
    EXPECT_STREQ(run.stop, "bounds met") << threads;
    EXPECT_GE(run.iterations, 2 * WholeBandStop::kStallSteps) << threads;  // (b) needs its window
    EXPECT_LT(run.iterations, run_free.iterations) << threads;
    const std::vector<flat_detail::FaceDistortion> fd = flat_detail::band_distortion(w, g.degenerate);
    EXPECT_LT(flat_detail::bound_stats_in_map(fd).area_p05, flat_detail::kWholeBandAreaLow) << threads;
    for (std::size_t f = 0; f < w.ann.t.size(); ++f) EXPECT_GT(w.emb.area2(w.ann, int(f)), 0.0) << f;
    final_pos[threads - 1] = w.emb.pos;
  }
  set_thread_count(0);
  ASSERT_EQ(final_pos[0].size(), final_pos[1].size());
  EXPECT_EQ(std::memcmp(final_pos[0].data(), final_pos[1].data(), final_pos[0].size() * sizeof(flat_detail::V2)), 0);
}

// The squeezed grid (24 x 12 x size 8: 36 290 faces, 5 blocks of face_blocks.h) mapped at step k with
// its middle columns squeezed to squeeze[k] of their width, the whole map sheared by shear[k]
// (x += shear y: areas kept, angles not), every vertex moved by a fixed jitter of 1e-3 and its last
// column crushed to 1e-9 of its width.
flat_detail::Embedding squeezed_step(const test_shapes::SqueezedGrid& g, double squeeze, double shear) {
  flat_detail::Embedding emb = g.emb;
  const int a = 8 * g.nx / 24, b = 16 * g.nx / 24;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = i < a ? i : i < b ? a + squeeze * (i - a) : a + (b - a) * squeeze + (i - b);
      const std::size_t v = std::size_t(j * g.nx + i);
      emb.pos[v] = flat_detail::V2(x + shear * j + 1e-3 * std::sin(7.0 * double(v)), j + 1e-3 * std::cos(5.0 * double(v)));
    }
  for (int j = 0; j < g.ny; ++j)  // the last column crushed out of the map
    emb.pos[std::size_t(j * g.nx + g.nx - 1)] = emb.pos[std::size_t(j * g.nx + g.nx - 2)] + flat_detail::V2(1e-9, 0);
  return emb;
}

// AllFacesCheck (rule (a) from counts, its qc means only when the areas are within the margins, the
// step before's from its kept positions) says stop at exactly the steps WholeBandStop::all_done says so
// on the full statistics (bound_stats_in_map of the band's distortion), on 1, 2 and 3 threads, over steps
// that go in and out of the area margins with the qc mean rising and falling; one face is degenerate
// and one column crushed out of the map. The sequence holds a stop right after a step out of the margins
// (the kept positions decide it) and a step within the margins that does not stop (angles unsettled).
TEST(WholeBandStop, CheckFromCountsSaysWhatTheFullStatisticsSay) {
  const std::vector<double> squeeze = {0.1, 0.3, 0.3, 0.32, 0.12, 0.35, 0.35, 0.15, 0.35, 0.45, 0.9, 0.05, 0.6};
  const std::vector<double> shear = {0.0, 0.8, 0.9, 0.7, 0.0, 0.1, 0.2, 0.0, 1.5, 0.4, 0.0, 0.0, 0.3};
  test_shapes::SqueezedGrid g(0.3, 8);
  g.degenerate[100] = 1;
  std::vector<char> expected, within;
  {  // the full statistics
    WholeBandStop rule;
    for (std::size_t k = 0; k < squeeze.size(); ++k) {
      flat_detail::SegmentWork w;
      w.ann = g.s, w.emb = squeezed_step(g, squeeze[k], shear[k]);
      const BoundStats all = flat_detail::bound_stats_in_map(flat_detail::band_distortion(w, g.degenerate));
      within.push_back(WholeBandStop::within_area(all));
      expected.push_back(rule.all_done(all));
    }
  }
  for (int threads : {1, 2, 3}) {
    set_thread_count(threads);
    flat_detail::SegmentWork w;
    w.ann = g.s;
    const std::vector<flat_detail::FaceFrame> frames = flat_detail::band_frames(w);
    flat_detail::AllFacesCheck check(w.ann, frames, g.degenerate);
    for (std::size_t k = 0; k < squeeze.size(); ++k) {
      w.emb = squeezed_step(g, squeeze[k], shear[k]);
      EXPECT_EQ(check.all_done(w.emb), expected[k] != 0) << "step " << k << ", " << threads << " threads";
    }
  }
  set_thread_count(0);
  bool stop_after_out = false, within_going_on = false;
  for (std::size_t k = 1; k < expected.size(); ++k)
    stop_after_out |= expected[k] && !within[k - 1], within_going_on |= within[k] && !expected[k];
  EXPECT_TRUE(stop_after_out);
  EXPECT_TRUE(within_going_on);
  EXPECT_FALSE(std::all_of(within.begin(), within.end(), [](char c) { return c != 0; }));
}

}  // namespace
}  // namespace cf
