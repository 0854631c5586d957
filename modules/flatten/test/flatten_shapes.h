#pragma once
// Synthetic colon-like surfaces for the flatten tests, meshed by VTK flying edges from a signed
// distance on a grid (LPS mm, normals out of the lumen).
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "colonflat/core/soup.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/vtk_convert.h"
#include "colonflat/flatten/flatten.h"

namespace cf::test_shapes {

// flatten_colon(mesh) with `threads` worker threads (then back to the default count).
inline FlatMap flatten_with_threads(const TriangleList& mesh, int threads) {
  set_thread_count(threads);
  FlatMap f = flatten_colon(mesh);
  set_thread_count(0);
  return f;
}

// How many map vertices of `a` and `b` differ in u or v (bitwise; 0: the same map). Pre: same size.
inline std::size_t uv_differences(const FlatMap& a, const FlatMap& b) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.uv.size(); ++i) differ += a.uv[i][0] != b.uv[i][0] || a.uv[i][1] != b.uv[i][1];
  return differ;
}

inline double capsule(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm() - r;
}

// The zero level set of `sdf` on the box [lo, hi] sampled every h mm, outward normals.
inline TriangleList surface_of(const std::function<double(const Eigen::Vector3d&)>& sdf, const Eigen::Vector3d& lo,
                               const Eigen::Vector3d& hi, double h) {
  vtkNew<vtkImageData> img;
  const Eigen::Vector3d n = (hi - lo) / h;
  const int nx = int(n.x()), ny = int(n.y()), nz = int(n.z());
  img->SetDimensions(nx, ny, nz);
  img->SetOrigin(lo.x(), lo.y(), lo.z());
  img->SetSpacing(h, h, h);
  img->AllocateScalars(VTK_DOUBLE, 1);
  auto* v = static_cast<double*>(img->GetScalarPointer());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) v[(std::size_t(k) * ny + j) * nx + i] = sdf(lo + h * Eigen::Vector3d(i, j, k));
  vtkNew<vtkFlyingEdges3D> fe;
  fe->SetInputData(img);
  fe->SetValue(0, 0.0);
  fe->ComputeNormalsOff();
  fe->Update();
  const PolygonSoup soup = polydata_to_soup(fe->GetOutput());
  TriangleList t;
  t.points = soup.points;
  for (std::size_t f = 0; f + 1 < soup.face_start.size(); ++f) {
    const auto* c = &soup.corners[soup.face_start[f]];
    t.triangles.push_back({int(c[0]), int(c[1]), int(c[2])});
  }
  double vol = 0;
  for (const auto& tr : t.triangles) {
    const auto &a = t.points[tr[0]], &b = t.points[tr[1]], &c = t.points[tr[2]];
    vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (vol < 0)
    for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
  return t;
}

// Closed tube along x (radius 12 mm, 220 mm) with a wide pouch (sphere radius 28 mm) and a blind
// side branch (radius 5 mm, 35 mm long, leaving the tube at x = 150 along +y), at 1.2 mm.
inline TriangleList pouch_and_branch() {
  return surface_of(
      [](const Eigen::Vector3d& p) {
        const double tube = capsule(p, {0, 0, 0}, {200, 0, 0}, 12);
        const double pouch = (p - Eigen::Vector3d(70, 8, 0)).norm() - 28;
        const double branch = capsule(p, {150, 0, 0}, {150, 55, 0}, 5);
        return std::min({tube, pouch, branch});
      },
      {-25, -35, -35}, {225, 75, 35}, 1.2);
}

// Closed tube along x (radius 12 mm, 0..200 mm) and, behind a neck of radius `neck` mm (a channel
// from the tube at x = 120 along +y to y = 30), a blind pouch: a sphere of radius 22 mm at y = 50.
inline TriangleList pouch_behind_neck(double neck) {
  return surface_of(
      [neck](const Eigen::Vector3d& p) {
        const double tube = capsule(p, {0, 0, 0}, {200, 0, 0}, 12);
        const double channel = capsule(p, {120, 0, 0}, {120, 32, 0}, neck);
        const double pouch = (p - Eigen::Vector3d(120, 50, 0)).norm() - 22;
        return std::min({tube, channel, pouch});
      },
      {-15, -15, -25}, {215, 75, 25}, 1.0);
}

// Closed tube along x (radius 15 mm, 0..200 mm) with a pedunculated polyp: a head of radius 6 mm
// on a stalk of radius 1.6 mm rising 8 mm from the wall at x = 100 into the lumen (tissue).
inline TriangleList stalked_polyp() {
  return surface_of(
      [](const Eigen::Vector3d& p) {
        const double tube = capsule(p, {0, 0, 0}, {200, 0, 0}, 15);
        const double stalk = capsule(p, {100, 0, -16}, {100, 0, -6}, 1.6);
        const double head = (p - Eigen::Vector3d(100, 0, -2)).norm() - 6;
        return std::max(tube, -std::min(stalk, head));  // lumen = tube minus the polyp's tissue
      },
      {-18, -18, -18}, {218, 18, 18}, 0.8);
}

// Closed tube along x (radius 12 mm, 0..200 mm) with a wide pouch (sphere radius 28 mm at x = 70)
// and a strand stump: a finger of tissue of radius 1 mm rising 9 mm from the wall at x = 150 into
// the lumen (what denoise leaves where it cut a strand), at 0.8 mm. The pouch needs the whole-band
// area correction; the conformal map crushes the stump's tip to ~1e-7 of its area.
inline TriangleList pouch_and_stump() {
  return surface_of(
      [](const Eigen::Vector3d& p) {
        const double tube = std::min(capsule(p, {0, 0, 0}, {200, 0, 0}, 12), (p - Eigen::Vector3d(70, 8, 0)).norm() - 28);
        const double stump = capsule(p, {150, 0, -14}, {150, 0, -3}, 1.0);
        return std::max(tube, -stump);  // lumen = tube and pouch minus the stump's tissue
      },
      {-15, -22, -31}, {215, 38, 31}, 0.8);
}

// Closed tube along x (radius 12 mm, 0..200 mm) with a long strand stump: a finger of tissue of
// radius 1 mm leaving the wall at x ~ 100, z = -12 and rising into the lumen at 30 degrees to the
// tube's axis, `length` mm from its buried end (about length - 4 mm of it in the lumen), at 0.8 mm:
// what denoise leaves of a cut tissue bridge. The conformal map shrinks a finger of radius r by
// about exp(-depth / r) in length; at 35 mm that is far below what double precision resolves.
inline TriangleList tube_and_strand(double length) {
  return surface_of(
      [length](const Eigen::Vector3d& p) {
        const double tube = capsule(p, {0, 0, 0}, {200, 0, 0}, 12);
        const Eigen::Vector3d base(100, 0, -14), dir(std::cos(M_PI / 6), 0, std::sin(M_PI / 6));
        const double strand = capsule(p, base, base + length * dir, 1.0);
        return std::max(tube, -strand);  // lumen = tube minus the strand's tissue
      },
      {-15, -15, -15}, {215, 15, 15}, 0.8);
}

// Closed tube along x (radius 12 mm, 0..`tube` mm) forking at its middle into a blind limb of about
// its own girth (radius `limb` mm, `length` mm long along +y), at 1.0 mm: what denoise leaves where
// the limbs of a colon loop touched (the lumen forks; flatten cuts the limb off as a branch whose neck
// is about the band's girth, and the band keeps a hole of that size). A long limb (length >> its
// girth) is a severed colon: a whole colon stretch hanging off a contact.
inline TriangleList tube_with_limb(double limb, double length = 90, double tube = 200) {
  return surface_of(
      [limb, length, tube](const Eigen::Vector3d& p) {
        return std::min(capsule(p, {0, 0, 0}, {tube, 0, 0}, 12), capsule(p, {tube / 2, 0, 0}, {tube / 2, length, 0}, limb));
      },
      {-15, -15, -15}, {tube + 15, length + 15, 15}, 1.0);
}

}  // namespace cf::test_shapes
