#include "colonflat/flatten/flat_artifact.h"

#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/vtk_convert.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {

namespace {

FlatSegment segment_from_json(const nlohmann::json& j) {
  FlatSegment s;
  s.id = j.at("id");
  s.component = j.value("component", 0);
  s.input_kind = j.value("input", "");
  const auto& r = j.at("rectangle_mm");
  s.x0 = r.at("x0");
  s.y0 = r.at("y0");
  s.length = r.at("length");
  s.period = r.at("period");
  s.area_3d = j.value("area_3d_mm2", 0.0);
  s.faces = j.value("faces", std::size_t(0));
  s.vertices = j.value("vertices", std::size_t(0));
  s.removed_faces = j.value("removed_end_faces", std::size_t(0));
  if (j.contains("end_a_lps_mm")) s.end_a = j["end_a_lps_mm"].get<std::array<double, 3>>();
  if (j.contains("end_b_lps_mm")) s.end_b = j["end_b_lps_mm"].get<std::array<double, 3>>();
  s.weights = j.value("weights", "");
  s.untangled_vertices = j.value("untangled_vertices", std::size_t(0));
  s.crowded_faces = j.value("crowded_faces_left_out", std::size_t(0));
  s.inverted_faces = j.value("inverted_faces_left_out", std::size_t(0));
  s.dirichlet_period_ratio = j.value("period_consistency", 1.0);
  if (j.contains("distortion")) {
    const auto& d = j["distortion"];
    s.stats.faces = d.value("faces", std::size_t(0));
    s.stats.flipped = d.value("flipped_triangles", std::size_t(0));
    s.stats.degenerate = d.value("degenerate_triangles", std::size_t(0));
    s.stats.qc_mean = d.value("quasi_conformal_mean", 0.0);
    s.stats.qc_p95 = d.value("quasi_conformal_p95", 0.0);
    s.stats.qc_max = d.value("quasi_conformal_max", 0.0);
    s.stats.area_p05 = d.value("area_ratio_p05", 0.0);
    s.stats.area_median = d.value("area_ratio_median", 0.0);
    s.stats.area_p95 = d.value("area_ratio_p95", 0.0);
    s.stats.area_log2_mean_abs = d.value("area_log2_mean_abs", 0.0);
  }
  s.map = j.value("map", "");
  if (j.contains("centreline_lps_mm")) s.centreline = j["centreline_lps_mm"].get<std::vector<std::array<double, 3>>>();
  s.centreline_length = j.value("centreline_length_mm", 0.0);
  if (j.contains("centreline_to_x_mm")) s.centreline_x = j["centreline_to_x_mm"].get<std::vector<std::array<double, 2>>>();
  s.x0_end = j.value("x0_end", "end A");
  s.x1_end = j.value("x1_end", "end B");
  s.order = j.value("order", s.id);
  s.centreline_offset = j.value("centreline_offset_mm", 0.0);
  s.balanced_vertices = j.value("balanced_vertices", std::size_t(0));
  s.corrected_iterations = j.value("area_correction_iterations", 0);
  s.balance_strength = j.value("balance_strength", 0.0);
  if (j.contains("coverage")) s.coverage = coverage_from_json(j["coverage"]);
  s.kind = j.value("kind", "colon");
  s.parent = j.value("parent", -1);
  s.attach_mm = j.value("attach_mm", 0.0);
  if (j.contains("attach_lps_mm")) s.attach_lps = j["attach_lps_mm"].get<std::array<double, 3>>();
  s.neck_mm = j.value("neck_mm", 0.0);
  s.holds = j.value("holds", "lumen");  // (files before session 19: every branch was a pouch of lumen)
  return s;
}

}  // namespace

vtkSmartPointer<vtkPolyData> flat_to_polydata(const FlatMap& flat) {
  const vtkIdType n = vtkIdType(flat.uv.size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  vtkNew<vtkDoubleArray> pos, nrm;
  pos->SetName("position_lps_mm");
  pos->SetNumberOfComponents(3);
  pos->SetNumberOfTuples(n);
  nrm->SetName("Normals");
  nrm->SetNumberOfComponents(3);
  nrm->SetNumberOfTuples(n);
  vtkNew<vtkIntArray> seg, src;
  seg->SetName("segment_id");
  seg->SetNumberOfTuples(n);
  src->SetName("source_vertex");
  src->SetNumberOfTuples(n);
  vtkNew<vtkDoubleArray> along, angle;
  along->SetName("centreline_mm");
  angle->SetName("angle_rad");
  const bool has_along = flat.centreline_mm.size() == flat.uv.size() && flat.angle_rad.size() == flat.uv.size();
  if (has_along) along->SetNumberOfTuples(n), angle->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i) {
    if (has_along) along->SetValue(i, flat.centreline_mm[i]), angle->SetValue(i, flat.angle_rad[i]);
    pts->SetPoint(i, flat.uv[i][0], flat.uv[i][1], 0.0);
    pos->SetTuple(i, flat.position[i].data());
    nrm->SetTuple(i, flat.normal[i].data());
    seg->SetValue(i, flat.segment[i]);
    src->SetValue(i, flat.source_vertex[i]);
  }
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(vtkIdType(flat.triangles.size()), vtkIdType(3 * flat.triangles.size()));
  for (const auto& t : flat.triangles) {
    vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  pd->GetPointData()->AddArray(pos);
  pd->GetPointData()->SetNormals(nrm);
  pd->GetPointData()->AddArray(seg);
  pd->GetPointData()->AddArray(src);
  if (has_along) pd->GetPointData()->AddArray(along), pd->GetPointData()->AddArray(angle);
  tag_polydata_space(pd, "mm", "LPS");
  vtkNew<vtkStringArray> js;
  js->SetName("FlatSegments");
  js->InsertNextValue(flat_report(flat).dump());
  pd->GetFieldData()->AddArray(js);
  return pd;
}

FlatMap polydata_to_flat(vtkPolyData* pd, const std::string& name) {
  FlatMap f;
  auto* pts = pd->GetPoints();
  auto* pos = vtkDoubleArray::SafeDownCast(pd->GetPointData()->GetArray("position_lps_mm"));
  auto* nrm = pd->GetPointData()->GetArray("Normals");
  auto* seg = pd->GetPointData()->GetArray("segment_id");
  auto* src = pd->GetPointData()->GetArray("source_vertex");
  auto* js = vtkStringArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray("FlatSegments"));
  if (!pts || !pos || !nrm || !seg || !src || !js || js->GetNumberOfValues() < 1)
    throw InputError(name, "not a flat colon map (needs point data position_lps_mm, Normals, segment_id, "
                           "source_vertex and field data FlatSegments; write it with `colonflat flatten`)");
  const vtkIdType n = pts->GetNumberOfPoints();
  if (pos->GetNumberOfTuples() != n || nrm->GetNumberOfTuples() != n || seg->GetNumberOfTuples() != n ||
      src->GetNumberOfTuples() != n || pos->GetNumberOfComponents() != 3 || nrm->GetNumberOfComponents() != 3)
    throw InputError(name, "flat map arrays do not match the number of points");
  f.uv.resize(n);
  f.position.resize(n);
  f.normal.resize(n);
  f.segment.resize(n);
  f.source_vertex.resize(n);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    pts->GetPoint(i, p);
    f.uv[i] = {p[0], p[1]};
    pos->GetTuple(i, f.position[i].data());
    nrm->GetTuple(i, f.normal[i].data());
    f.segment[i] = int(seg->GetTuple1(i));
    f.source_vertex[i] = int(src->GetTuple1(i));
  }
  auto* along = pd->GetPointData()->GetArray("centreline_mm");
  auto* angle = pd->GetPointData()->GetArray("angle_rad");
  if (along && angle && along->GetNumberOfTuples() == n && angle->GetNumberOfTuples() == n) {
    f.centreline_mm.resize(n);
    f.angle_rad.resize(n);
    for (vtkIdType i = 0; i < n; ++i) f.centreline_mm[i] = along->GetTuple1(i), f.angle_rad[i] = angle->GetTuple1(i);
  }
  vtkNew<vtkIdList> cell;
  vtkCellArray* polys = pd->GetPolys();
  if (!polys || polys->GetNumberOfCells() == 0) throw InputError(name, "flat map has no triangles");
  polys->InitTraversal();
  while (polys->GetNextCell(cell)) {
    if (cell->GetNumberOfIds() != 3) throw InputError(name, "flat map has a non-triangle cell");
    std::array<int, 3> t{int(cell->GetId(0)), int(cell->GetId(1)), int(cell->GetId(2))};
    for (int v : t)
      if (v < 0 || v >= n) throw InputError(name, "flat map triangle refers to a missing point");
    f.triangles.push_back(t);
  }
  nlohmann::json j = nlohmann::json::parse(js->GetValue(0), nullptr, false);
  if (j.is_discarded() || !j.contains("segments")) throw InputError(name, "FlatSegments field data is not valid JSON");
  try {
    for (const auto& s : j["segments"]) f.segments.push_back(segment_from_json(s));
    f.skipped_components = j.value("skipped_components", std::size_t(0));
    if (j.contains("coverage")) f.coverage = coverage_from_json(j["coverage"]);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(name, std::string("FlatSegments field data: ") + e.what());
  }
  for (int s : f.segment)
    if (s < 0 || s >= int(f.segments.size())) throw InputError(name, "segment_id out of range");
  f.stats = distortion_stats(f);
  return f;
}

void write_flat(const FlatMap& flat, const std::filesystem::path& path) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    VtkMessageCapture msgs;
    auto pd = flat_to_polydata(flat);
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetFileName(tmp.c_str());
    w->SetInputData(pd);
    use_fast_compression(w);
    if (!w->Write() || !msgs.first_problem().empty())
      throw Error(path.string() + ": cannot write flat map: " + msgs.write_problem(w, tmp.string()));
  });
}

FlatMap read_flat(const std::filesystem::path& path) {
  const std::string name = path.string();
  if (!std::filesystem::exists(path)) throw InputError(name, "no such file");
  if (path.extension() != ".vtp") throw InputError(name, "a flat colon map must be a .vtp file");
  VtkMessageCapture msgs;
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  if (!msgs.first_problem().empty() || r->GetErrorCode() != 0)
    throw InputError(name, "cannot read VTK XML PolyData: " +
                               (msgs.first_problem().empty() ? std::string("parse error") : msgs.first_problem()));
  return polydata_to_flat(r->GetOutput(), name);
}

const ArtifactType& flat_artifact() {
  static const ArtifactType t{
      "flat", "flat colon map (.vtp: 2D points in mm, position_lps_mm, Normals, segment_id)",
      [](const std::filesystem::path& p) { return std::any(read_flat(p)); },
      [](const std::any& v, const std::filesystem::path& tmp, const std::filesystem::path&) {
        write_flat(std::any_cast<const FlatMap&>(v), tmp);
      }};
  return t;
}

}  // namespace cf
