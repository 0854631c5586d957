// Distortion statistics of the flat map (src/distortion.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "colonflat/core/threads.h"
#include "../src/flatten_internal.h"

namespace {

using cf::flat_detail::FaceDistortion;

// Faces of every kind the statistics meet: ordinary, degenerate, crushed below what the map holds
// (too_small_in_map), folded, with an infinite quasi-conformal ratio.
std::vector<FaceDistortion> mixed_faces(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<FaceDistortion> fd(n);
  for (FaceDistortion& d : fd) {
    d.area3 = 0.1 + u(rng);
    d.area2 = d.area3 * std::exp(4 * (u(rng) - 0.5));
    d.qc = 1 + 3 * u(rng);
    const double kind = u(rng);
    if (kind < 0.02) d.degenerate = true;
    else if (kind < 0.04) d.area2 = 1e-12 * d.area3;  // crushed: out of the map
    else if (kind < 0.05) d.area2 = -0.3 * d.area3;   // folded: out of the map too
    else if (kind < 0.06) d.qc = std::numeric_limits<double>::infinity();
  }
  return fd;
}

}  // namespace

// bound_stats_in_map (the area correction's trigger, after every whole-band step) gives exactly the
// numbers stats_of gives on the faces in the map, for sizes below, at and above a percentile step.
TEST(FlattenDistortion, BoundStatsEqualStatsOfTheFacesInTheMap) {
  for (std::size_t n : {1u, 2u, 21u, 1000u, 40001u}) {
    const std::vector<FaceDistortion> fd = mixed_faces(n, unsigned(n));
    std::vector<FaceDistortion> in_map;
    for (const FaceDistortion& d : fd)
      if (!d.degenerate && !cf::flat_detail::too_small_in_map(d.area2, d.area3)) in_map.push_back(d);
    const cf::DistortionStats want = cf::flat_detail::stats_of(in_map);
    const cf::flat_detail::BoundStats got = cf::flat_detail::bound_stats_in_map(fd);
    EXPECT_EQ(got.area_p05, want.area_p05) << n;
    EXPECT_EQ(got.area_p95, want.area_p95) << n;
    EXPECT_EQ(got.qc_mean, want.qc_mean) << n;
    if (n >= 1000) EXPECT_LT(got.area_p05, 0.5 * got.area_p95) << n;  // the two are not one value
  }
}

// face_distortion from a face's cached 3D frame (the whole-band stop check's path) gives the same
// bits as face_distortion from its corners, for ordinary, sliver, folded and degenerate triangles.
TEST(FlattenDistortion, FrameOfAFaceGivesTheSameBitsAsItsCorners) {
  using cf::flat_detail::V2;
  using cf::flat_detail::V3;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  std::size_t invalid = 0;
  for (int i = 0; i < 2000; ++i) {
    V3 p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
    if (i % 50 == 0) p1 = p0;                          // degenerate: a zero edge
    if (i % 50 == 1) p2 = p0 + 2.0 * (p1 - p0);        // degenerate: collinear
    if (i % 50 == 2) p2 = p0 + (p1 - p0) + V3(0, 0, 1e-9);  // sliver
    const V2 q0(u(rng), u(rng)), q1(u(rng), u(rng)), q2(u(rng), u(rng));  // either orientation
    const FaceDistortion a = cf::flat_detail::face_distortion(p0, p1, p2, q0, q1, q2);
    const cf::flat_detail::FaceFrame frame = cf::flat_detail::face_frame(p0, p1, p2);
    const FaceDistortion b = cf::flat_detail::face_distortion(frame, q0, q1, q2);
    invalid += !frame.valid;
    EXPECT_EQ(std::memcmp(&a.qc, &b.qc, sizeof(double)), 0) << i << ": " << a.qc << " vs " << b.qc;
    EXPECT_EQ(std::memcmp(&a.area2, &b.area2, sizeof(double)), 0) << i;
    EXPECT_EQ(std::memcmp(&a.area3, &b.area3, sizeof(double)), 0) << i;
  }
  EXPECT_GE(invalid, 40u);  // the degenerate cases were met (qc infinite in both)
}

// The quasi-conformal ratio takes its two lengths |(E, H)|, |(F, G)| as the square root of the
// rounded sum of squares (not std::hypot's scaled form, 2.9 % of the CT flatten's CPU): for 2000
// random faces its bits are (Qn + R) / |Qn - R| with those square roots; and where the squares
// would overflow or underflow (the map scaled by 2^530 or 2^-530, ~1e160 and 1e-160: exact scalings)
// the ratio is still the unscaled map's (qc is scale-free), not infinite: to within 1e-12 qc^2, as
// the lengths' last bits move qc by about qc^2 ulp (qc = (Qn + R) / |Qn - R|).
TEST(FlattenDistortion, QuasiConformalRatioTakesSquareRootsWhereTheSquaresAreNormal) {
  using cf::flat_detail::V2;
  using cf::flat_detail::V3;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int i = 0; i < 2000; ++i) {
    const V3 p0(u(rng), u(rng), u(rng)), p1(u(rng), u(rng), u(rng)), p2(u(rng), u(rng), u(rng));
    const V2 q0(u(rng), u(rng)), q1(u(rng), u(rng)), q2(u(rng), u(rng));
    const cf::flat_detail::FaceFrame fr = cf::flat_detail::face_frame(p0, p1, p2);
    if (!fr.valid) continue;
    Eigen::Matrix2d Q;
    Q << (q1 - q0).x(), (q2 - q0).x(), (q1 - q0).y(), (q2 - q0).y();
    const Eigen::Matrix2d J = Q * fr.s_inv;
    const double E = (J(0, 0) + J(1, 1)) / 2, F = (J(0, 0) - J(1, 1)) / 2, G = (J(1, 0) + J(0, 1)) / 2,
                 H = (J(1, 0) - J(0, 1)) / 2;
    const double Qn = std::sqrt(E * E + H * H), R = std::sqrt(F * F + G * G);
    const double want = (Qn + R) / std::abs(Qn - R);
    const double got = cf::flat_detail::face_distortion(fr, q0, q1, q2).qc;
    EXPECT_EQ(std::memcmp(&got, &want, sizeof(double)), 0) << i << ": " << got << " vs " << want;
    for (double scale : {std::ldexp(1.0, 530), std::ldexp(1.0, -530)}) {
      const double scaled = cf::flat_detail::face_distortion(fr, scale * q0, scale * q1, scale * q2).qc;
      ASSERT_TRUE(std::isfinite(scaled)) << i << " x" << scale;
      EXPECT_NEAR(scaled, got, 1e-12 * got * got) << i << " x" << scale;
    }
  }
}

// order_statistics (the whole-band stop check's p05 / p95) gives the values a plain nth_element
// gives, to the bit, on 300 000 area-ratio-like values with ties (many repeats, zeros, -0, +inf,
// denormals), with 1 and 2 threads and for k at the ends, at p05, p50, p95; nth_element looked at
// under 10 % of the values per k there (the bucket path ran); with a negative value among them it
// falls back to nth_element over all and still gives its values.
TEST(FlattenDistortion, OrderStatisticsAreNthElementsValuesFoundInOneBucket) {
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> base(300000);
  for (double& x : base) {
    const double kind = u(rng);
    x = kind < 0.2 ? std::round(8 * u(rng)) / 4                        // ties: 0, 0.25, ..., 2
        : kind < 0.21 ? (u(rng) < 0.5 ? -0.0 : std::numeric_limits<double>::denorm_min() * 7)
        : kind < 0.22 ? std::numeric_limits<double>::infinity()
                      : std::exp(6 * (u(rng) - 0.5));
  }
  const std::size_t n = base.size();
  const std::vector<std::size_t> ks{0, n / 20, n / 2, n * 19 / 20, n - 1};
  for (bool negative : {false, true}) {
    std::vector<double> data = base;
    if (negative) data[123] = -1.0;
    for (int threads : {1, 2}) {
      cf::set_thread_count(threads);
      std::vector<double> v = data;
      const cf::flat_detail::OrderStatistics got = cf::flat_detail::order_statistics(v, ks);
      cf::set_thread_count(0);
      ASSERT_EQ(got.values.size(), ks.size());
      for (std::size_t i = 0; i < ks.size(); ++i) {
        std::vector<double> w = data;
        std::nth_element(w.begin(), w.begin() + long(ks[i]), w.end());
        std::uint64_t a, b;
        std::memcpy(&a, &got.values[i], 8), std::memcpy(&b, &w[ks[i]], 8);
        EXPECT_TRUE(a == b || (got.values[i] == 0 && w[ks[i]] == 0)) << ks[i] << " " << got.values[i] << " " << w[ks[i]];
      }
      if (negative) EXPECT_EQ(got.searched, n * ks.size()) << threads;
      else EXPECT_LT(got.searched, n * ks.size() / 10) << threads;
    }
  }
}

// distortion_stats (the flat map's final statistics, its faces measured on the worker threads)
// gives the same bits on 1, 2 and 3 threads, for the whole map and per segment, and each
// segment's statistics count exactly that segment's faces.
TEST(FlattenDistortion, FlatMapStatisticsAreTheSameOnAnyThreadCount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  cf::FlatMap flat;
  const int grid = 120;  // a grid of vertices in 3D and a jittered copy in 2D; rows split in 2 segments
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      flat.position.push_back({double(i), double(j), 0.3 * u(rng)});
      flat.uv.push_back({i + 0.4 * u(rng), j * (0.5 + u(rng))});
      flat.segment.push_back(i < grid / 3 ? 0 : 1);
    }
  for (int i = 0; i + 1 < grid; ++i)
    for (int j = 0; j + 1 < grid; ++j) {
      const int a = i * grid + j;
      flat.triangles.push_back({a, a + grid, a + 1});
      flat.triangles.push_back({a + 1, a + grid, a + grid + 1});
    }
  auto all = [&] {
    std::vector<cf::DistortionStats> s{cf::distortion_stats(flat), cf::distortion_stats(flat, 0), cf::distortion_stats(flat, 1)};
    return s;
  };
  cf::set_thread_count(1);
  const std::vector<cf::DistortionStats> one = all();
  EXPECT_EQ(one[1].faces + one[2].faces, flat.triangles.size());
  EXPECT_EQ(one[1].faces, std::size_t(2 * (grid / 3) * (grid - 1)));
  EXPECT_GT(one[0].flipped, 0u);  // the jitter folds some faces: the counts are exercised
  for (int t : {2, 3}) {
    cf::set_thread_count(t);
    const std::vector<cf::DistortionStats> got = all();
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].faces, one[k].faces) << t;
      EXPECT_EQ(got[k].flipped, one[k].flipped) << t;
      EXPECT_EQ(got[k].degenerate, one[k].degenerate) << t;
      EXPECT_EQ(got[k].qc_mean, one[k].qc_mean) << t;
      EXPECT_EQ(got[k].qc_p95, one[k].qc_p95) << t;
      EXPECT_EQ(got[k].area_p05, one[k].area_p05) << t;
      EXPECT_EQ(got[k].area_median, one[k].area_median) << t;
      EXPECT_EQ(got[k].area_p95, one[k].area_p95) << t;
      EXPECT_EQ(got[k].area_log2_mean_abs, one[k].area_log2_mean_abs) << t;
    }
  }
  cf::set_thread_count(0);
}
