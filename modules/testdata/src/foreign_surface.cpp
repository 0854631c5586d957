#include "colonflat/testdata/foreign_surface.h"

#include <vtkCellArray.h>
#include <vtkDiscreteMarchingCubes.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <fstream>
#include <stdexcept>

#include "colonflat/volume/volume_io.h"

namespace cf::testing {
namespace {

// The mask's voxels (every step-th) in a grid padded by one empty voxel on every side.
vtkNew<vtkImageData> padded_grid(const MaskImage* m, int step, int dims[3]) {
  const auto size = m->GetLargestPossibleRegion().GetSize();
  for (int k = 0; k < 3; ++k) dims[k] = int((size[k] + step - 1) / step) + 2;
  vtkNew<vtkImageData> img;
  img->SetDimensions(dims);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* out = static_cast<unsigned char*>(img->GetScalarPointer());
  std::fill(out, out + std::size_t(dims[0]) * dims[1] * dims[2], 0);
  const unsigned char* in = m->GetBufferPointer();
  for (int z = 1; z + 1 < dims[2]; ++z)
    for (int y = 1; y + 1 < dims[1]; ++y)
      for (int x = 1; x + 1 < dims[0]; ++x) {
        const std::size_t i = std::size_t(x - 1) * step, j = std::size_t(y - 1) * step, k = std::size_t(z - 1) * step;
        out[(std::size_t(z) * dims[1] + y) * dims[0] + x] = in[(k * size[1] + j) * size[0] + i] == 1 ? 1 : 0;
      }
  return img;
}

double signed_volume6(const TriangleList& t) {
  double v = 0;
  for (const auto& tr : t.triangles) {
    const auto &a = t.points[tr[0]], &b = t.points[tr[1]], &c = t.points[tr[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v;
}

vtkNew<vtkPolyData> to_polydata(const TriangleList& t) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const auto& p : t.points) pts->InsertNextPoint(p[0], p[1], p[2]);
  vtkNew<vtkCellArray> polys;
  for (const auto& tr : t.triangles) {
    const vtkIdType ids[3] = {tr[0], tr[1], tr[2]};
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

}  // namespace

TriangleList foreign_marching_cubes(const std::filesystem::path& mask, int step) {
  const MaskImage::Pointer m = read_mask(mask);
  int dims[3];
  vtkNew<vtkImageData> img = padded_grid(m.GetPointer(), step, dims);
  vtkNew<vtkDiscreteMarchingCubes> mc;
  mc->SetInputData(img);
  mc->SetValue(0, 1);
  mc->ComputeNormalsOff();
  mc->ComputeGradientsOff();
  mc->ComputeScalarsOff();
  mc->Update();
  vtkPolyData* pd = mc->GetOutput();
  TriangleList t;
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i) {
    double g[3];
    pd->GetPoint(i, g);  // padded grid index -> mask voxel index -> LPS mm
    MaskImage::PointType lps;
    itk::ContinuousIndex<double, 3> idx;
    for (int k = 0; k < 3; ++k) idx[k] = (g[k] - 1.0) * step;
    m->TransformContinuousIndexToPhysicalPoint(idx, lps);
    t.points.push_back({double(float(lps[0])), double(float(lps[1])), double(float(lps[2]))});
  }
  vtkNew<vtkIdList> cell;
  pd->GetPolys()->InitTraversal();
  while (pd->GetPolys()->GetNextCell(cell))
    t.triangles.push_back({int(cell->GetId(0)), int(cell->GetId(1)), int(cell->GetId(2))});
  return signed_volume6(t) < 0 ? reversed_faces(std::move(t)) : t;
}

TriangleList reversed_faces(TriangleList t) {
  for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
  return t;
}

void write_foreign(const TriangleList& t, const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".off") {
    std::ofstream o(file);
    o.precision(17);
    o << "OFF\n" << t.points.size() << " " << t.triangles.size() << " 0\n";
    for (const auto& p : t.points) o << p[0] << " " << p[1] << " " << p[2] << "\n";
    for (const auto& tr : t.triangles) o << "3 " << tr[0] << " " << tr[1] << " " << tr[2] << "\n";
    if (!o) throw std::runtime_error(file.string() + ": cannot write");
    return;
  }
  vtkNew<vtkPolyData> pd = to_polydata(t);
  int ok = 0;
  if (ext == ".ply") {
    vtkNew<vtkPLYWriter> w;
    w->SetFileName(file.c_str());
    w->SetInputData(pd);
    w->SetFileTypeToBinary();
    ok = w->Write();
  } else if (ext == ".vtk") {
    vtkNew<vtkPolyDataWriter> w;
    w->SetFileName(file.c_str());
    w->SetInputData(pd);
    w->SetFileTypeToBinary();
    ok = w->Write();
  } else if (ext == ".vtp") {
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetFileName(file.c_str());
    w->SetInputData(pd);
    ok = w->Write();
  } else {
    throw std::runtime_error(file.string() + ": unknown extension");
  }
  if (!ok) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace cf::testing
