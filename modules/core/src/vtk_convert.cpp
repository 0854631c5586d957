#include "colonflat/core/vtk_convert.h"

#include "colonflat/core/threads.h"

#include <algorithm>

#include <vtkCellArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLWriter.h>

namespace cf {

vtkSmartPointer<vtkPolyData> mesh_to_polydata(const Mesh& mesh) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(mesh.n_vertices()));
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    pts->SetPoint(v.idx(), p[0], p[1], p[2]);
  }
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(mesh.n_faces()), static_cast<vtkIdType>(3 * mesh.n_faces()));
  for (auto f : mesh.faces()) {
    vtkIdType ids[3];
    int k = 0;
    for (auto v : mesh.fv_range(f)) ids[k++] = v.idx();
    polys->InsertNextCell(3, ids);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

vtkSmartPointer<vtkPolyData> triangles_to_polydata(const TriangleList& t) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(static_cast<vtkIdType>(t.points.size()));
  double* xyz = static_cast<double*>(pts->GetVoidPointer(0));
  vtkNew<vtkIdTypeArray> ids;
  ids->SetNumberOfValues(static_cast<vtkIdType>(3 * t.triangles.size()));
  vtkIdType* c = ids->GetPointer(0);
  parallel_for(std::max(t.points.size(), t.triangles.size()), [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < std::min(i1, t.points.size()); ++i) std::copy_n(t.points[i].data(), 3, xyz + 3 * i);
    for (std::size_t i = i0; i < std::min(i1, t.triangles.size()); ++i) std::copy_n(t.triangles[i].data(), 3, c + 3 * i);
  });
  vtkNew<vtkCellArray> polys;
  polys->SetData(3, ids);  // fixed-size cells: the offsets are made from the ids
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

PolygonSoup polydata_to_soup(vtkPolyData* pd) {
  PolygonSoup soup;
  vtkPoints* pts = pd->GetPoints();
  const vtkIdType np = pts ? pts->GetNumberOfPoints() : 0;
  soup.points.resize(static_cast<std::size_t>(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double p[3];
    pts->GetPoint(i, p);
    soup.points[i] = {p[0], p[1], p[2]};
  }
  std::vector<std::int64_t> ids;
  vtkNew<vtkIdList> cell;
  if (vtkCellArray* polys = pd->GetPolys()) {
    polys->InitTraversal();
    while (polys->GetNextCell(cell)) {
      ids.assign(cell->GetPointer(0), cell->GetPointer(0) + cell->GetNumberOfIds());
      soup.add_face(ids.data(), ids.size());
    }
  }
  if (vtkCellArray* strips = pd->GetStrips()) {
    strips->InitTraversal();
    while (strips->GetNextCell(cell)) {
      for (vtkIdType k = 0; k + 2 < cell->GetNumberOfIds(); ++k) {
        std::int64_t t[3] = {cell->GetId(k), cell->GetId(k + 1), cell->GetId(k + 2)};
        if (k % 2) std::swap(t[0], t[1]);
        soup.add_face(t, 3);
      }
    }
  }
  return soup;
}

void tag_polydata_space(vtkPolyData* pd, const std::string& units, const std::string& space) {
  auto set = [&](const char* name, const std::string& value) {
    vtkNew<vtkStringArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    pd->GetFieldData()->RemoveArray(name);
    pd->GetFieldData()->AddArray(a);
  };
  set("Units", units);
  set("CoordinateSystem", space);
}

void use_fast_compression(vtkXMLWriter* writer) {
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToLZ4();
  writer->SetCompressionLevel(1);
}

}  // namespace cf
