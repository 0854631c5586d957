#include "colonflat/core/loops.h"

#include <algorithm>
#include <cmath>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/vtk_convert.h"
#include "colonflat/core/vtk_messages.h"

namespace fs = std::filesystem;

namespace cf {

double points_diameter(const std::vector<Vec3>& points) {
  double d = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    for (std::size_t j = i + 1; j < points.size(); ++j) d = std::max(d, (points[i] - points[j]).sqrnorm());
  return std::sqrt(d);
}

void describe_cross_section(LoopRecord* loop) {
  const auto& p = loop->points;
  if (p.empty()) return;
  Vec3 c(0, 0, 0);
  for (const auto& q : p) c += q;
  c /= double(p.size());
  Vec3 area(0, 0, 0);  // vector area: half the sum of (p_i - c) x (p_i+1 - c)
  for (std::size_t i = 0; i < p.size(); ++i) area += OpenMesh::cross(p[i] - c, p[(i + 1) % p.size()] - c);
  area *= 0.5;
  loop->centroid = c;
  loop->diameter_mm = points_diameter(p);
  loop->cross_section_area_mm2 = area.norm();
  loop->cross_section_normal = area.norm() > 0 ? area / area.norm() : Vec3(0, 0, 0);
}

vtkSmartPointer<vtkPolyData> loops_to_polydata(const LoopSet& loops) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  auto make_int = [](const char* name) {
    auto a = vtkSmartPointer<vtkIntArray>::New();
    a->SetName(name);
    return a;
  };
  auto id = make_int("loop_id"), iteration = make_int("iteration"), count = make_int("vertex_count"),
       type = make_int("type"), sep = make_int("separating"), comp = make_int("component"),
       input_id = make_int("input_vertex_id");
  vtkNew<vtkDoubleArray> length, diameter, area, caps_x;
  length->SetName("length_mm");
  diameter->SetName("diameter_mm");
  area->SetName("cross_section_area_mm2");
  caps_x->SetName("cap_intersections");
  for (const auto& L : loops) {
    std::vector<vtkIdType> ids;
    for (std::size_t i = 0; i < L.points.size(); ++i) {
      ids.push_back(pts->InsertNextPoint(L.points[i][0], L.points[i][1], L.points[i][2]));
      input_id->InsertNextValue(L.vertex_ids[i]);
    }
    if (!ids.empty()) ids.push_back(ids.front());  // closed polyline
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    id->InsertNextValue(L.id);
    iteration->InsertNextValue(L.iteration);
    count->InsertNextValue(static_cast<int>(L.vertex_ids.size()));
    type->InsertNextValue(L.type == "handle" ? 0 : 1);
    sep->InsertNextValue(L.separating ? 1 : 0);
    comp->InsertNextValue(L.component);
    length->InsertNextValue(L.length);
    diameter->InsertNextValue(L.diameter_mm);
    area->InsertNextValue(L.cross_section_area_mm2);
    caps_x->InsertNextValue(static_cast<double>(L.cap_intersections));
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetLines(lines);
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(id), static_cast<vtkDataArray*>(iteration),
                          static_cast<vtkDataArray*>(count), static_cast<vtkDataArray*>(type),
                          static_cast<vtkDataArray*>(sep), static_cast<vtkDataArray*>(comp),
                          static_cast<vtkDataArray*>(length.GetPointer()), static_cast<vtkDataArray*>(diameter.GetPointer()),
                          static_cast<vtkDataArray*>(area.GetPointer()), static_cast<vtkDataArray*>(caps_x.GetPointer())})
    pd->GetCellData()->AddArray(a);
  pd->GetPointData()->AddArray(input_id);
  tag_polydata_space(pd, "mm", "LPS");
  return pd;
}

namespace {

void write_loops_to(const LoopSet& loops, const fs::path& file, const fs::path& target) {
  vtkSmartPointer<vtkPolyData> pd = loops_to_polydata(loops);
  VtkMessageCapture capture;
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(file.c_str());
  w->SetInputData(pd);
  use_fast_compression(w);
  if (!w->Write() || !capture.errors().empty())
    throw Error(target.string() + ": cannot write loops: " + capture.write_problem(w, file.string()));
}

// Declared sizes agree with the data: one value per point and per line, line ids within the
// points (a damaged or hand-made file must not be read out of bounds).
void check_loop_arrays(vtkPolyData* pd, const fs::path& path) {
  const vtkIdType points = pd->GetNumberOfPoints(), lines = pd->GetNumberOfLines();
  if (pd->GetNumberOfCells() != lines)
    throw InputError(path.string(), "a loops file holds closed polylines only (found other cells)");
  if (pd->GetPointData()->GetArray("input_vertex_id")->GetNumberOfTuples() != points)
    throw InputError(path.string(), "input_vertex_id has not one value per point");
  vtkCellData* cd = pd->GetCellData();
  for (int a = 0; a < cd->GetNumberOfArrays(); ++a)
    if (cd->GetArray(a) && cd->GetArray(a)->GetNumberOfTuples() != lines)
      throw InputError(path.string(), std::string("cell array ") + cd->GetArrayName(a) + " has not one value per loop");
  vtkNew<vtkIdList> cell;
  pd->GetLines()->InitTraversal();
  while (pd->GetLines()->GetNextCell(cell))
    for (vtkIdType k = 0; k < cell->GetNumberOfIds(); ++k)
      if (cell->GetId(k) < 0 || cell->GetId(k) >= points) throw InputError(path.string(), "a loop refers to a missing point");
}

}  // namespace

void write_loops(const LoopSet& loops, const fs::path& path) {
  write_atomically(path, [&](const fs::path& tmp) { write_loops_to(loops, tmp, path); });
}

LoopSet read_loops(const fs::path& path) {
  if (!fs::exists(path)) throw InputError(path.string(), "no such file");
  VtkMessageCapture capture;
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  if (!capture.first_problem().empty() || r->GetErrorCode())
    throw InputError(path.string(), "cannot read loops .vtp: " + capture.first_problem());
  vtkPolyData* pd = r->GetOutput();
  auto* cd = pd->GetCellData();
  auto geti = [&](const char* n) { return vtkIntArray::SafeDownCast(cd->GetArray(n)); };
  auto* len = vtkDoubleArray::SafeDownCast(cd->GetArray("length_mm"));
  auto* input_id = vtkIntArray::SafeDownCast(pd->GetPointData()->GetArray("input_vertex_id"));
  if (!geti("loop_id") || !len || !geti("type") || !input_id)
    throw InputError(path.string(), "not a ColonFlat loops file (missing loop_id/length_mm/type arrays)");
  check_loop_arrays(pd, path);
  LoopSet loops;
  vtkNew<vtkIdList> cell;
  pd->GetLines()->InitTraversal();
  for (vtkIdType c = 0; pd->GetLines()->GetNextCell(cell); ++c) {
    LoopRecord L;
    L.id = geti("loop_id")->GetValue(c);
    L.iteration = geti("iteration") ? geti("iteration")->GetValue(c) : 0;
    L.component = geti("component") ? geti("component")->GetValue(c) : 0;
    L.length = len->GetValue(c);
    L.type = geti("type")->GetValue(c) == 0 ? "handle" : "tunnel";
    L.separating = geti("separating") && geti("separating")->GetValue(c);
    for (vtkIdType k = 0; k + 1 < cell->GetNumberOfIds(); ++k) {
      double p[3];
      pd->GetPoint(cell->GetId(k), p);
      L.points.emplace_back(p[0], p[1], p[2]);
      L.vertex_ids.push_back(input_id->GetValue(cell->GetId(k)));
    }
    describe_cross_section(&L);  // centroid, diameter and area follow from the points
    if (auto* x = vtkDoubleArray::SafeDownCast(cd->GetArray("cap_intersections")))
      L.cap_intersections = static_cast<std::size_t>(x->GetValue(c));
    loops.push_back(std::move(L));
  }
  return loops;
}

const ArtifactType& loops_artifact() {
  static const ArtifactType t{
      "loops", "closed polylines (.vtp) with loop_id, length_mm, vertex_count, type (0 handle, 1 tunnel)",
      [](const fs::path& p) { return std::any(read_loops(p)); },
      [](const std::any& v, const fs::path& tmp, const fs::path& target) {
        write_loops_to(std::any_cast<const LoopSet&>(v), tmp, target);
      }};
  return t;
}

}  // namespace cf
