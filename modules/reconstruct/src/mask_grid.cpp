// The mask's voxel grid: crop and padding, the (6,18) Euler characteristic, the VTK isosurface,
// the index -> LPS map of its points, and the distance of a surface to the mask's voxel boundary.
#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkFlyingEdges3D.h>
#include <vtkMarchingCubes.h>
#include <vtkNew.h>
#include <vtkPoints.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "colonflat/core/error.h"
#include "colonflat/core/vtk_messages.h"
#include "reconstruct_internal.h"

namespace cf {
namespace reconstruct_detail {
namespace {

// Contribution of one 2x2x2 block (bit b = corner (b&1, b>>1&1, b>>2&1)) anchored at its lowest
// corner to the (6,18) Euler characteristic: the anchor voxel, its three face-adjacent pairs,
// three 2x2 squares and the block, plus one for a block whose only two background voxels are
// opposite corners (marching cubes closes that block: the background is 18-, not 26-connected).
struct EulerTable {
  int v[256];
  EulerTable() {
    for (int c = 0; c < 256; ++c) {
      auto b = [c](int i) { return (c >> i) & 1; };
      int x = b(0);
      x -= (b(0) & b(1)) + (b(0) & b(2)) + (b(0) & b(4));
      x += (b(0) & b(1) & b(2) & b(3)) + (b(0) & b(1) & b(4) & b(5)) + (b(0) & b(2) & b(4) & b(6));
      x -= (c == 255);
      int bg = 0;
      for (int i = 0; i < 8; ++i) bg += !b(i);
      if (bg == 2)
        for (int i = 0; i < 4; ++i)
          if (!b(i) && !b(7 - i)) x += 1;
      v[c] = x;
    }
  }
};

}  // namespace

long long euler_6_18(const unsigned char* d, std::size_t nx, std::size_t ny, std::size_t nz) {
  static const EulerTable table;
  long long chi = 0;
  const std::size_t sy = nx, sz = nx * ny;
  for (std::size_t k = 0; k + 1 < nz; ++k)
    for (std::size_t j = 0; j + 1 < ny; ++j) {
      const unsigned char* r = d + k * sz + j * sy;
      for (std::size_t i = 0; i + 1 < nx; ++i) {
        const unsigned char* p = r + i;
        const int c = p[0] | p[1] << 1 | p[sy] << 2 | p[sy + 1] << 3 | p[sz] << 4 | p[sz + 1] << 5 | p[sz + sy] << 6 |
                      p[sz + sy + 1] << 7;
        chi += table.v[c];
      }
    }
  return chi;
}

vtkSmartPointer<vtkImageData> padded_crop(const unsigned char* d, const std::array<std::size_t, 3>& n, const Box& b,
                                          int pad) {
  const int px = int(b.hi[0] - b.lo[0]) + 1 + 2 * pad, py = int(b.hi[1] - b.lo[1]) + 1 + 2 * pad,
            pz = int(b.hi[2] - b.lo[2]) + 1 + 2 * pad;
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(px, py, pz);
  img->SetOrigin(double(b.lo[0]) - pad, double(b.lo[1]) - pad, double(b.lo[2]) - pad);
  img->SetSpacing(1, 1, 1);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* out = static_cast<unsigned char*>(img->GetScalarPointer());
  std::memset(out, 0, std::size_t(px) * py * pz);
  const std::size_t w = b.hi[0] - b.lo[0] + 1;
  for (std::size_t k = b.lo[2]; k <= b.hi[2]; ++k)
    for (std::size_t j = b.lo[1]; j <= b.hi[1]; ++j) {
      const unsigned char* src = d + (k * n[1] + j) * n[0] + b.lo[0];
      unsigned char* dst = out + ((k - b.lo[2] + pad) * py + (j - b.lo[1] + pad)) * std::size_t(px) + pad;
      for (std::size_t i = 0; i < w; ++i) dst[i] = src[i] != 0;
    }
  return img;
}

vtkSmartPointer<vtkPolyData> isosurface(vtkImageData* img, const std::string& method) {
  if (method == "discrete-flying-edges" && img->GetScalarType() != VTK_UNSIGNED_CHAR)
    throw UsageError("method discrete-flying-edges extracts labels and cannot place a sub-voxel surface (use --subvoxel off)");
  VtkMessageCapture capture;
  vtkSmartPointer<vtkPolyData> out;
  if (method == "flying-edges") {
    vtkNew<vtkFlyingEdges3D> f;
    f->SetInputData(img);
    f->SetValue(0, 0.5);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->InterpolateAttributesOff();
    f->Update();
    out = f->GetOutput();
  } else if (method == "discrete-flying-edges") {
    vtkNew<vtkDiscreteFlyingEdges3D> f;
    f->SetInputData(img);
    f->SetValue(0, 1);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->Update();
    out = f->GetOutput();
  } else if (method == "marching-cubes") {
    vtkNew<vtkMarchingCubes> f;
    f->SetInputData(img);
    f->SetValue(0, 0.5);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->Update();
    out = f->GetOutput();
  } else {
    throw UsageError("unknown reconstruction method '" + method + "'");
  }
  if (!capture.errors().empty()) throw Error(method + " failed: " + capture.first_problem());
  return out;
}

TriangleList to_lps(vtkPolyData* pd, const IndexToLps& map, bool flip) {
  TriangleList t;
  vtkPoints* pts = pd->GetPoints();
  const vtkIdType np = pts ? pts->GetNumberOfPoints() : 0;
  t.points.resize(std::size_t(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double x[3];
    pts->GetPoint(i, x);
    t.points[std::size_t(i)] = map(x);
  }
  vtkCellArray* polys = pd->GetPolys();
  t.triangles.reserve(std::size_t(polys->GetNumberOfCells()));
  auto it = vtk::TakeSmartPointer(polys->NewIterator());
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell()) {
    vtkIdType n;
    const vtkIdType* ids;
    it->GetCurrentCell(n, ids);
    if (n != 3) throw Error("isosurface produced a polygon with " + std::to_string(n) + " vertices");
    if (flip) t.triangles.push_back({int(ids[0]), int(ids[2]), int(ids[1])});
    else t.triangles.push_back({int(ids[0]), int(ids[1]), int(ids[2])});
  }
  return t;
}

std::vector<std::array<double, 3>> staircase_positions(vtkPolyData* pd, const IndexToLps& map) {
  vtkPoints* pts = pd->GetPoints();
  const vtkIdType np = pts ? pts->GetNumberOfPoints() : 0;
  std::vector<std::array<double, 3>> out(static_cast<std::size_t>(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double x[3];
    pts->GetPoint(i, x);
    int along = 0;  // the edge's axis: the coordinate farthest from an integer
    for (int a = 1; a < 3; ++a)
      if (std::abs(x[a] - std::round(x[a])) > std::abs(x[along] - std::round(x[along]))) along = a;
    for (int a = 0; a < 3; ++a) x[a] = a == along ? std::floor(x[a]) + 0.5 : std::round(x[a]);
    out[std::size_t(i)] = map(x);
  }
  return out;
}

}  // namespace reconstruct_detail

using namespace reconstruct_detail;

long long mask_euler_characteristic_6_18(const MaskImage* mask) {
  if (!mask) throw PreconditionError("no mask");
  const auto size = mask->GetBufferedRegion().GetSize();
  const std::array<std::size_t, 3> n{size[0], size[1], size[2]};
  const Box b = nonzero_box(mask->GetBufferPointer(), n);
  if (!b.count) return 0;
  auto img = padded_crop(mask->GetBufferPointer(), n, b);
  int dims[3];
  img->GetDimensions(dims);
  return euler_6_18(static_cast<const unsigned char*>(img->GetScalarPointer()), dims[0], dims[1], dims[2]);
}

nlohmann::json BoundaryDistance::to_json() const {
  return {{"max_mm", max_mm}, {"mean_mm", mean_mm}, {"vertices", vertices}, {"far", far}, {"max_spacing_mm", max_spacing_mm},
          {"max_voxels", max_voxels}, {"mean_voxels", mean_voxels}};
}

BoundaryDistance distance_to_mask_boundary(const Mesh& surface, const MaskImage* mask) {
  if (!mask) throw PreconditionError("no mask");
  const auto region = mask->GetBufferedRegion();
  const long n[3] = {long(region.GetSize()[0]), long(region.GetSize()[1]), long(region.GetSize()[2])};
  const unsigned char* d = mask->GetBufferPointer();
  const auto sp = mask->GetSpacing();
  const auto org = mask->GetOrigin();
  const auto dir = mask->GetDirection();
  auto at = [&](long i, long j, long k) -> bool {
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return false;
    return d[(k * n[1] + j) * n[0] + i] != 0;
  };
  BoundaryDistance out;
  out.max_spacing_mm = std::max({sp[0], sp[1], sp[2]});
  const int R = 3;
  double sum = 0, sum_voxels = 0;
  for (auto v : surface.vertices()) {
    const auto& p = surface.point(v);
    // Continuous buffer index: x = diag(1/s) D^T (p - origin) - start.
    double x[3];
    for (int a = 0; a < 3; ++a) {
      double t = 0;
      for (int r = 0; r < 3; ++r) t += dir(r, a) * (p[r] - org[r]);
      x[a] = t / sp[a] - double(region.GetIndex()[a]);
    }
    const long c[3] = {std::lround(x[0]), std::lround(x[1]), std::lround(x[2])};
    double best = kInf, best_voxels = kInf;
    for (long k = c[2] - R; k <= c[2] + R; ++k)
      for (long j = c[1] - R; j <= c[1] + R; ++j)
        for (long i = c[0] - R; i <= c[0] + R; ++i) {
          if (!at(i, j, k)) continue;
          const long q[3] = {i, j, k};
          for (int a = 0; a < 3; ++a)
            for (int s = -1; s <= 1; s += 2) {
              long nb[3] = {i, j, k};
              nb[a] += s;
              if (at(nb[0], nb[1], nb[2])) continue;
              // The face between q and nb: plane x_a = q_a + s/2, the other two coordinates
              // within half a voxel of q.
              double d2 = 0, d2_voxels = 0;
              for (int b = 0; b < 3; ++b) {
                const double e = b == a ? x[b] - (double(q[b]) + 0.5 * s)
                                        : std::max(0.0, std::abs(x[b] - double(q[b])) - 0.5);
                d2 += (e * sp[b]) * (e * sp[b]);
                d2_voxels += e * e;
              }
              best = std::min(best, d2);
              best_voxels = std::min(best_voxels, d2_voxels);
            }
        }
    ++out.vertices;
    if (!std::isfinite(best)) {
      ++out.far;
      continue;
    }
    const double dd = std::sqrt(best);
    out.max_mm = std::max(out.max_mm, dd);
    out.max_voxels = std::max(out.max_voxels, std::sqrt(best_voxels));
    sum += dd;
    sum_voxels += std::sqrt(best_voxels);
  }
  if (out.vertices > out.far) {
    out.mean_mm = sum / double(out.vertices - out.far);
    out.mean_voxels = sum_voxels / double(out.vertices - out.far);
  }
  return out;
}

}  // namespace cf
