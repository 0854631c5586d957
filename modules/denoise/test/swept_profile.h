#pragma once
// Closed bands for the surgery tests: a closed 2D profile swept around the z axis; boxes; mean edge length.
#include <array>
#include <cmath>
#include <vector>

#include "colonflat/core/synthetic.h"

namespace cf::testing {

// The profile (radial offset r from R, height z; counter-clockwise, so the normals point out)
// swept around the z axis at radius R in nu sections, turning `twist` half turns on the way round
// (even: the profile must come back upright to close up). Genus 1; section i holds vertices
// [i * n, (i + 1) * n) for a profile of n points.
inline TriangleList swept_profile(const std::vector<std::array<double, 2>>& profile, int nu, int twist, double R) {
  constexpr double kPi = 3.14159265358979323846;
  const int n = static_cast<int>(profile.size());
  TriangleList t;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu, a = twist * kPi * i / nu;
    for (const auto& p : profile) {
      const double r = p[0] * std::cos(a) - p[1] * std::sin(a), z = p[0] * std::sin(a) + p[1] * std::cos(a);
      t.points.push_back({(R + r) * std::cos(u), (R + r) * std::sin(u), z});
    }
  }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * n + j, b = ((i + 1) % nu) * n + j, c = ((i + 1) % nu) * n + (j + 1) % n, d = i * n + (j + 1) % n;
      t.triangles.push_back({a, b, c});
      t.triangles.push_back({a, c, d});
    }
  return t;
}

// A closed axis-aligned box from corner lo to corner hi (outward faces, 12 triangles).
inline TriangleList axis_box(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  TriangleList t;
  for (int c = 0; c < 8; ++c) t.points.push_back({c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t.triangles.push_back({q[0], q[1], q[2]});
    t.triangles.push_back({q[0], q[2], q[3]});
  }
  return t;
}

// The loop of profile point `point` round a profile of n points swept in nu sections (the
// sweep's direction): vertex i * n + point of each section i.
inline std::vector<Mesh::VertexHandle> swept_point_loop(int nu, int n, int point) {
  std::vector<Mesh::VertexHandle> loop;
  for (int i = 0; i < nu; ++i) loop.push_back(Mesh::VertexHandle(i * n + point));
  return loop;
}

inline double mean_edge(const Mesh& m) {
  double s = 0;
  for (auto e : m.edges()) s += m.calc_edge_length(e);
  return s / m.n_edges();
}

}  // namespace cf::testing
