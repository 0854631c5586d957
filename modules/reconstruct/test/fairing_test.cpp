// Constrained fairing (src/fairing.h) on tiny height fields built here: terraces of a tilted plane
// become the plane, every vertex stays within the radius of its anchor, a surface that is already
// fair is left alone, and bad input is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "../src/fairing.h"
#include "colonflat/core/error.h"

namespace cf::reconstruct_detail {
namespace {

// An n x n grid of unit-spaced vertices (two triangles per cell) with height z(x, y).
TriangleList height_field(int n, const std::function<double(int, int)>& z) {
  TriangleList t;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) t.points.push_back({double(x), double(y), z(x, y)});
  auto id = [n](int x, int y) { return y * n + x; };
  for (int y = 0; y + 1 < n; ++y)
    for (int x = 0; x + 1 < n; ++x) {
      t.triangles.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
      t.triangles.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
    }
  return t;
}

// The largest |M (p - anchor)| over the points (voxel units).
double largest_offset_voxels(const TriangleList& t, const std::vector<std::array<double, 3>>& anchors,
                             const Eigen::Matrix3d& to_index) {
  double worst = 0;
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    const Eigen::Vector3d d(t.points[i][0] - anchors[i][0], t.points[i][1] - anchors[i][1], t.points[i][2] - anchors[i][2]);
    worst = std::max(worst, (to_index * d).norm());
  }
  return worst;
}

constexpr int kSide = 40;
constexpr double kSlope = 0.15;  // one voxel step every 6.7 voxels: wide terraces
bool interior(int x, int y) { return x >= 8 && y >= 8 && x < kSide - 8 && y < kSide - 8; }
double terrace(int x) { return std::round(kSlope * x); }
// What a smoothing filter makes of the terraces (the start the stage gives the fairing): their
// mean over 7 columns, wavy where the steps were.
double blurred_terrace(int x) {
  double sum = 0;
  for (int k = -3; k <= 3; ++k) sum += terrace(x + k);
  return sum / 7.0;
}

// Anchored to the terraces of z = 0.15 x (heights rounded to whole voxels, each within half a
// voxel of the plane) and started from their blur, the surface comes out as the plane: interior
// heights within 0.1 voxel of it, against 0.5 for the terraces, every vertex within half a voxel
// of its anchor, and a lower energy.
TEST(ConstrainedFairing, TerracesOfATiltedPlaneBecomeThePlane) {
  const auto anchors = height_field(kSide, [](int x, int) { return terrace(x); }).points;
  TriangleList t = height_field(kSide, [](int x, int) { return blurred_terrace(x); });
  const Eigen::Matrix3d to_index = Eigen::Matrix3d::Identity();
  double before = 0;
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x)
      if (interior(x, y)) before = std::max(before, std::abs(anchors[std::size_t(y * kSide + x)][2] - kSlope * x));
  FairingOptions options;
  options.iterations = 400;
  const FairingResult r = fair_within_tolerance(t, anchors, to_index, options);
  double after = 0;
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x)
      if (interior(x, y)) after = std::max(after, std::abs(t.points[std::size_t(y * kSide + x)][2] - kSlope * x));
  EXPECT_GT(before, 0.45);
  EXPECT_LT(after, 0.05) << "terraces " << before;
  EXPECT_LE(largest_offset_voxels(t, anchors, to_index), options.radius_voxels * (1 + 1e-9));
  EXPECT_LT(r.energy_after, 0.2 * r.energy_before);
  EXPECT_EQ(r.iterations, 400);
}

// Anisotropic voxels (0.8 x 0.8 x 2.5 mm): the constraint is measured in voxels, so a vertex may
// move at most 1.25 mm along z and 0.4 mm along x or y.
TEST(ConstrainedFairing, AnisotropicConstraintIsInVoxels) {
  TriangleList t = height_field(24, [](int x, int y) { return ((x + y) % 2) ? 3.0 : -3.0; });  // a rough field
  const auto anchors = t.points;
  const Eigen::Matrix3d to_index = Eigen::Vector3d(1 / 0.8, 1 / 0.8, 1 / 2.5).asDiagonal();
  FairingOptions options;
  const FairingResult r = fair_within_tolerance(t, anchors, to_index, options);
  double largest_z = 0;
  for (std::size_t i = 0; i < anchors.size(); ++i) largest_z = std::max(largest_z, std::abs(t.points[i][2] - anchors[i][2]));
  EXPECT_LE(largest_offset_voxels(t, anchors, to_index), options.radius_voxels * (1 + 1e-9));
  EXPECT_GT(largest_z, 1.0);  // the rough field needs most of the 1.25 mm
  EXPECT_LE(largest_z, 1.25);
  EXPECT_GT(r.vertices_at_limit, 0u);
  EXPECT_LT(r.energy_after, r.energy_before);
}

// A plane is already the fairest surface: it stays that plane (vertices may only slide along it,
// here at the open grid's rim, which a closed surface does not have).
TEST(ConstrainedFairing, PlaneStaysThePlane) {
  auto plane = [](double x, double y) { return 0.3 * x - 0.2 * y + 5.0; };
  TriangleList t = height_field(16, [&](int x, int y) { return plane(x, y); });
  const auto anchors = t.points;
  const FairingResult r = fair_within_tolerance(t, anchors, Eigen::Matrix3d::Identity(), FairingOptions{});
  double off_plane = 0;
  for (const auto& p : t.points) off_plane = std::max(off_plane, std::abs(p[2] - plane(p[0], p[1])));
  EXPECT_LT(off_plane, 1e-9);
  EXPECT_LE(r.energy_after, r.energy_before);
}

// Zero iterations leave the surface untouched; anchors that do not match the points are refused.
TEST(ConstrainedFairing, OffOrMismatchedInput) {
  TriangleList t = height_field(6, [](int x, int) { return std::round(0.4 * x); });
  const TriangleList copy = t;
  FairingOptions off;
  off.iterations = 0;
  fair_within_tolerance(t, t.points, Eigen::Matrix3d::Identity(), off);
  EXPECT_EQ(t.points, copy.points);
  std::vector<std::array<double, 3>> too_few(t.points.begin(), t.points.end() - 1);
  EXPECT_THROW(fair_within_tolerance(t, too_few, Eigen::Matrix3d::Identity(), FairingOptions{}), Error);
  EXPECT_EQ(t.points, copy.points);
}

}  // namespace
}  // namespace cf::reconstruct_detail
