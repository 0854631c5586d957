// Shared meshes for the benchmark apps (compiled into each *_bench executable).
#include "bench_meshes.h"

#include "colonflat/core/synthetic.h"

#include <vtkFlyingEdges3D.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "colonflat/core/topology.h"
#include "colonflat/core/validation.h"
#include "colonflat/core/vtk_convert.h"

namespace cf::bench {

namespace {
// An n^3 grid of voxel size `voxel` from (lo, lo, lo) carrying a float scalar "sdf"; returns the values.
float* sdf_grid(vtkImageData* img, double lo, int n, double voxel) {
  img->SetDimensions(n, n, n);
  img->SetSpacing(voxel, voxel, voxel);
  img->SetOrigin(lo, lo, lo);
  vtkNew<vtkFloatArray> f;
  f->SetName("sdf");
  f->SetNumberOfValues(static_cast<vtkIdType>(n) * n * n);
  img->GetPointData()->SetScalars(f);
  return f->GetPointer(0);
}

// The zero level set of `sdf` (negative inside) by VTK flying edges, as a consistently oriented mesh.
Mesh iso_surface(vtkImageData* img) {
  vtkNew<vtkFlyingEdges3D> fe;
  fe->SetInputData(img);
  fe->SetValue(0, 1e-4);  // off the grid values: no vertex exactly on the iso-surface
  fe->ComputeNormalsOff();
  fe->ComputeGradientsOff();
  fe->ComputeScalarsOff();
  fe->Update();
  PolygonSoup soup = polydata_to_soup(fe->GetOutput());
  MeshDiagnosis diag = diagnose_soup(soup);
  TriangleList t = soup_to_triangles(soup, LoadPolicy{}, diag);
  return triangles_to_mesh(t, analyze_topology(t), true);
}
}  // namespace

Mesh sphere_with_handles(double radius, int handles, double voxel, unsigned seed) {
  const double R = 3.0, r = 1.0, margin = R + r + 2 * voxel;
  const double lo = -radius - margin;
  const int n = static_cast<int>(std::ceil(2 * (radius + margin) / voxel)) + 1;
  vtkNew<vtkImageData> img;
  float* d = sdf_grid(img, lo, n, voxel);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = lo + i * voxel, y = lo + j * voxel, z = lo + k * voxel;
        d[(static_cast<std::size_t>(k) * n + j) * n + i] = static_cast<float>(std::sqrt(x * x + y * y + z * z) - radius);
      }
  // Torus centres on the sphere, far enough apart; axis tangent to the sphere, so half of each
  // ring sticks out as an arch.
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::vector<std::array<double, 3>> centres;
  while (static_cast<int>(centres.size()) < handles) {
    double c[3] = {g(rng), g(rng), g(rng)};
    const double nc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    std::array<double, 3> p{radius * c[0] / nc, radius * c[1] / nc, radius * c[2] / nc};
    bool ok = true;
    for (const auto& q : centres)
      ok = ok && (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]) >
                     4 * (R + r + 1) * (R + r + 1);
    if (!ok) continue;
    centres.push_back(p);
    // Orthonormal frame: nrm (radial), axis a (tangent), b = nrm x a.
    const double nx = p[0] / radius, ny = p[1] / radius, nz = p[2] / radius;
    double ax = -ny, ay = nx, az = 0;
    if (std::fabs(nz) > 0.9) ax = 1, ay = 0, az = 0;
    const double dot = ax * nx + ay * ny + az * nz;
    ax -= dot * nx, ay -= dot * ny, az -= dot * nz;
    const double na = std::sqrt(ax * ax + ay * ay + az * az);
    ax /= na, ay /= na, az /= na;
    const int i0 = std::max(0, static_cast<int>((p[0] - margin - lo) / voxel)), i1 = std::min(n - 1, static_cast<int>((p[0] + margin - lo) / voxel) + 1);
    const int j0 = std::max(0, static_cast<int>((p[1] - margin - lo) / voxel)), j1 = std::min(n - 1, static_cast<int>((p[1] + margin - lo) / voxel) + 1);
    const int k0 = std::max(0, static_cast<int>((p[2] - margin - lo) / voxel)), k1 = std::min(n - 1, static_cast<int>((p[2] + margin - lo) / voxel) + 1);
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const double x = lo + i * voxel - p[0], y = lo + j * voxel - p[1], z = lo + k * voxel - p[2];
          const double h = x * ax + y * ay + z * az;                                  // along the axis
          const double px = x - h * ax, py = y - h * ay, pz = z - h * az;             // in the ring plane
          const double q = std::sqrt(px * px + py * py + pz * pz) - R;
          const double sdf = std::sqrt(q * q + h * h) - r;
          float& v = d[(static_cast<std::size_t>(k) * n + j) * n + i];
          v = std::min(v, static_cast<float>(sdf));
        }
  }
  return iso_surface(img);
}

Mesh sphere_with_strand(double radius, double strand_radius, double voxel) {
  const double lo = -radius - 2 * voxel;
  const int n = static_cast<int>(std::ceil(2 * (radius + 2 * voxel) / voxel)) + 1;
  vtkNew<vtkImageData> img;
  float* d = sdf_grid(img, lo, n, voxel);
  // The strand's axis: a chord through (0, 0.3 R, 0.2 R) along x, slightly tilted.
  const double cy = 0.3 * radius, cz = 0.2 * radius, ty = 0.1;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = lo + i * voxel, y = lo + j * voxel, z = lo + k * voxel;
        const double ball = std::sqrt(x * x + y * y + z * z) - radius;
        const double dy = y - cy - ty * x, dz = z - cz;
        const double strand = strand_radius - std::sqrt(dy * dy + dz * dz) / std::sqrt(1 + ty * ty);
        d[(static_cast<std::size_t>(k) * n + j) * n + i] = static_cast<float>(std::max(ball, strand));
      }
  return iso_surface(img);
}

namespace {
struct P3 {
  double x, y, z;
};
// Distance from q to the segment ab minus r (a capsule's signed distance).
double capsule(const P3& q, const P3& a, const P3& b, double r) {
  const double abx = b.x - a.x, aby = b.y - a.y, abz = b.z - a.z;
  const double t0 = ((q.x - a.x) * abx + (q.y - a.y) * aby + (q.z - a.z) * abz) / (abx * abx + aby * aby + abz * abz);
  const double t = std::clamp(t0, 0.0, 1.0);
  const double dx = q.x - a.x - t * abx, dy = q.y - a.y - t * aby, dz = q.z - a.z - t * abz;
  return std::sqrt(dx * dx + dy * dy + dz * dz) - r;
}

// Signed distance (< 0 in the lumen) of the colon-like shape at q.
double colon_like_sdf(const ColonLikeOptions& o, const P3& q) {
  constexpr double kRadius = 18, kLength = 200, kHalfGap = 1.5, kPi = 3.14159265358979323846;
  const double s = kRadius + kHalfGap;  // limb axes at x = -s, +s
  double d = std::min(capsule(q, {-s, 0, 0}, {-s, 0, kLength}, kRadius), capsule(q, {s, 0, 0}, {s, 0, kLength}, kRadius));
  // The bend: a half torus of major radius s in the xz-plane above z = kLength.
  if (q.z >= kLength) {
    const double rho = std::sqrt(q.x * q.x + (q.z - kLength) * (q.z - kLength));
    d = std::min(d, std::sqrt((rho - s) * (rho - s) + q.y * q.y) - kRadius);
  }
  if (o.contact_length > 0)
    d = std::min(d, capsule(q, {0, 0, 70}, {0, 0, 70 + o.contact_length}, kHalfGap + 0.5));
  if (o.bridge) {
    const double by = kRadius + 30;  // small-bowel loop along z beside limb A
    d = std::min(d, capsule(q, {-s, by, 30}, {-s, by, 170}, 10));
    d = std::min(d, capsule(q, {-s, 0, 40}, {-s, by, 40}, 4));
    d = std::min(d, capsule(q, {-s, 0, 160}, {-s, by, 160}, 4));
  }
  if (o.hooks)
    for (double z : {25.0, 185.0}) {
      const double out = -s - kRadius - 8;  // outside limb A, opposite the contact
      const double h = std::min({capsule(q, {-s - kRadius + 3, -4, z - 6}, {out, -4, z - 6}, 2),
                                 capsule(q, {out, -4, z - 6}, {out, -4, z + 6}, 2),
                                 capsule(q, {out, -4, z + 6}, {-s - kRadius + 3, -4, z + 6}, 2)});
      d = std::min(d, h);
    }
  if (o.strands) {  // tissue: removed from the lumen
    const double straight = capsule(q, {s, -kRadius - 2, 120}, {s + 4, kRadius + 2, 126}, 6);
    double curved = 1e9;
    const P3 c{s, 0, 40};
    for (int i = 0; i < 6; ++i) {  // an arc of radius 14 mm in the limb's cross-section plane, bowed
      const double a0 = kPi * (0.15 + 0.7 * i / 6.0), a1 = kPi * (0.15 + 0.7 * (i + 1) / 6.0);
      curved = std::min(curved, capsule(q, {c.x + 16 * std::cos(a0) - 8, c.y + 20 * std::sin(a0) - 10, c.z + 3 * i},
                                        {c.x + 16 * std::cos(a1) - 8, c.y + 20 * std::sin(a1) - 10, c.z + 3 * (i + 1)}, 4));
    }
    d = std::max(d, -std::min(straight, curved));
  }
  return d;
}
}  // namespace

Mesh colon_like_surface(const ColonLikeOptions& o) {
  const double v = o.voxel, margin = 3 * v;
  const double x0 = -70 - margin, y0 = -25 - margin, z0 = -20 - margin;
  const int nx = static_cast<int>(std::ceil((140 + 2 * margin) / v)) + 1;
  const int ny = static_cast<int>(std::ceil((85 + 2 * margin) / v)) + 1;
  const int nz = static_cast<int>(std::ceil((260 + 2 * margin) / v)) + 1;
  vtkNew<vtkImageData> img;
  img->SetDimensions(nx, ny, nz);
  img->SetSpacing(v, v, v);
  img->SetOrigin(x0, y0, z0);
  vtkNew<vtkFloatArray> f;
  f->SetName("mask");
  f->SetNumberOfValues(static_cast<vtkIdType>(nx) * ny * nz);
  img->GetPointData()->SetScalars(f);
  float* d = f->GetPointer(0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const bool lumen = colon_like_sdf(o, {x0 + i * v, y0 + j * v, z0 + k * v}) < 0;
        d[(static_cast<std::size_t>(k) * ny + j) * nx + i] = lumen ? -1.0f : 1.0f;  // a binary mask
      }
  return iso_surface(img);
}

namespace {

// Torus whose tube radius is r0 (1 - amp cos(u - thin_at)) (thinnest at u = thin_at).
TriangleList varying_torus(double R, double r0, double amp, double thin_at, int nu, int nv) {
  constexpr double kPi = 3.14159265358979323846;
  TriangleList t;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu, r = r0 * (1 - amp * std::cos(u - thin_at));
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      t.points.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  }
  auto id = [&](int i, int j) { return (i % nu) * nv + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return t;
}

// A closed tube of radius rt along the circle of radius R in the xy plane, from angle u0 to u1
// (nu sections of nv vertices), each end closed by a flat fan to a vertex on the circle: a
// genus-0 surface, oriented like varying_torus.
TriangleList core_arc(double R, double rt, double u0, double u1, int nu, int nv) {
  constexpr double kPi = 3.14159265358979323846;
  TriangleList t;
  for (int i = 0; i <= nu; ++i) {
    const double u = u0 + (u1 - u0) * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      t.points.push_back({(R + rt * std::cos(v)) * std::cos(u), (R + rt * std::cos(v)) * std::sin(u), rt * std::sin(v)});
    }
  }
  const int tip0 = static_cast<int>(t.points.size()), tip1 = tip0 + 1;
  t.points.push_back({R * std::cos(u0), R * std::sin(u0), 0});
  t.points.push_back({R * std::cos(u1), R * std::sin(u1), 0});
  auto id = [&](int i, int j) { return i * nv + (j % nv); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
    t.triangles.push_back({tip0, id(0, j), id(0, j + 1)});
    t.triangles.push_back({tip1, id(nu, j + 1), id(nu, j)});
  }
  return t;
}

}  // namespace

Mesh blocked_torus(Blocker kind) {
  constexpr double kPi = 3.14159265358979323846;
  const TriangleList outer = varying_torus(4, 1, 0.15, 0, 64, 16);
  TriangleList blocker;
  if (kind == Blocker::kRod) {
    blocker = synthetic::sphere(1, 16, 8);
    for (auto& p : blocker.points) p = {4 + 0.15 * p[0], 1.4 * p[1], 0.15 * p[2]};
  } else if (kind == Blocker::kCoreBlob) {
    blocker = synthetic::sphere(1, 16, 8);
    for (auto& p : blocker.points) p = {4 + 0.3 * p[0], 0.6 * p[1], 0.3 * p[2]};
  } else if (kind == Blocker::kWaistPlugAndRod) {
    const double step = 2 * kPi / 64;  // one section of the torus
    blocker = synthetic::disjoint_union(core_arc(4, 0.72, -step, step, 2, 16),
                                        core_arc(4, 0.15, 4 * step, 2 * kPi - 4 * step, 56, 8));
  } else {
    blocker = varying_torus(4, 0.15, 0.15, kPi, 64, 8);
  }
  if (kind == Blocker::kCoreAndLinkRings || kind == Blocker::kWaistPlugAndRod) {
    TriangleList link = varying_torus(2.5, 0.15, 0, 0, 48, 8);  // axis z, in the xy plane
    for (auto& p : link.points) p = {4 + p[0], -p[2], p[1]};  // a rotation: axis y, around the tube at u = 0
    blocker = synthetic::disjoint_union(blocker, link);
  }
  return synthetic::to_mesh(synthetic::disjoint_union(outer, blocker));
}

}  // namespace cf::bench
