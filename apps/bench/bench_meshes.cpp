// Shared meshes for the benchmark apps (compiled into each *_bench executable).
#include "bench_meshes.h"

#include <vtkFlyingEdges3D.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>

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

}  // namespace cf::bench
