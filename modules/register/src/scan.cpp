#include "colonflat/register/scan.h"

#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>

#include "colonflat/core/candidate_list.h"
#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {
namespace fs = std::filesystem;

namespace {

vtkSmartPointer<vtkPolyData> read_vtp(const fs::path& path) {
  const std::string name = path.string();
  if (!fs::is_regular_file(path)) throw InputError(name, "no such file (a run directory needs flat.vtp)");
  VtkMessageCapture msgs;
  // VTK 9.1 also logs reader failures through vtkLogger (not the output window): silence it so
  // that a bad file gives only our one error line.
  const vtkLogger::Verbosity saved = vtkLogger::GetCurrentVerbosityCutoff();
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkLogger::SetStderrVerbosity(saved);
  if (!msgs.first_problem().empty() || reader->GetErrorCode() != 0)
    throw InputError(name, "cannot read VTK XML PolyData: " +
                               (msgs.first_problem().empty() ? std::string("parse error") : msgs.first_problem()));
  vtkSmartPointer<vtkPolyData> pd = reader->GetOutput();
  return pd;
}

void read_vector_array(vtkDataArray* a, std::vector<Eigen::Vector3d>& out) {
  out.resize(size_t(a->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i) a->GetTuple(i, out[size_t(i)].data());
}

}  // namespace

std::vector<ScanCandidate> scan_candidates_from_json(const nlohmann::json& j, const std::string& name) {
  std::vector<ScanCandidate> out;
  for (const CandidateEntry& e : candidate_list_from_json(j, name))
    out.push_back({e.id, Eigen::Vector3d(e.lps_mm[0], e.lps_mm[1], e.lps_mm[2]), e.size_mm, e.score.value_or(1.0)});
  return out;
}

ColonScan scan_from_polydata(vtkSmartPointer<vtkPolyData> pd, const std::string& name) {
  ColonScan s;
  s.name = name;
  s.flat = pd;
  vtkPointData* data = pd->GetPointData();
  vtkDataArray* pos = data->GetArray("position_lps_mm");
  const vtkIdType n = pd->GetNumberOfPoints();
  if (n == 0) throw InputError(name, "flat map has no points");
  if (!pos || pos->GetNumberOfComponents() != 3 || pos->GetNumberOfTuples() != n)
    throw InputError(name, "not a flat colon map (needs point data position_lps_mm with 3 components per point; "
                           "write it with `colonflat flatten`)");
  read_vector_array(pos, s.lps);
  s.uv.resize(size_t(n));
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    pd->GetPoint(i, p);
    s.uv[size_t(i)] = {p[0], p[1]};
  }
  vtkDataArray* nrm = data->GetArray("Normals");
  if (nrm && nrm->GetNumberOfComponents() == 3 && nrm->GetNumberOfTuples() == n) read_vector_array(nrm, s.normal);
  else s.normal.assign(size_t(n), Eigen::Vector3d::Zero());
  s.segment.assign(size_t(n), 0);
  if (vtkDataArray* seg = data->GetArray("segment_id"); seg && seg->GetNumberOfTuples() == n)
    for (vtkIdType i = 0; i < n; ++i) s.segment[size_t(i)] = int(seg->GetTuple1(i));
  if (vtkDataArray* cl = data->GetArray("centreline_mm"); cl && cl->GetNumberOfTuples() == n) {
    s.centreline_mm.resize(size_t(n));
    for (vtkIdType i = 0; i < n; ++i) s.centreline_mm[size_t(i)] = cl->GetTuple1(i);
  }
  for (const auto& p : s.lps)
    if (!std::isfinite(p.sum())) throw InputError(name, "position_lps_mm has a non-finite value");
  auto* js = vtkStringArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray("FlatSegments"));
  if (js && js->GetNumberOfValues() > 0) {
    nlohmann::json j = nlohmann::json::parse(js->GetValue(0), nullptr, false);
    if (j.is_discarded()) throw InputError(name, "FlatSegments field data is not valid JSON");
    if (j.contains("segments") && j["segments"].is_array()) s.segments = j["segments"];
  }
  return s;
}

ColonScan read_run_dir(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "no such run directory");
  ColonScan s = scan_from_polydata(read_vtp(dir / "flat.vtp"), (dir / "flat.vtp").string());
  s.name = dir.string();
  if (const fs::path file = find_candidate_file(dir); !file.empty()) {
    s.candidates = scan_candidates_from_json(read_json_file(file), file.string());
    s.candidates_file = file.filename().string();
  }
  if (fs::exists(dir / "run_report.json")) {
    s.run_report = read_json_file(dir / "run_report.json");
    if (!s.run_report.is_object()) throw InputError((dir / "run_report.json").string(), "not a JSON object");
  }
  return s;
}

const nlohmann::json* segment_entry(const ColonScan& scan, int id) {
  for (const auto& seg : scan.segments)
    if (seg.value("id", -1) == id) return &seg;
  return nullptr;
}

bool is_branch_entry(const nlohmann::json& seg) { return seg.value("kind", std::string("colon")) == "branch"; }

bool is_branch(const ColonScan& scan, int id) {
  const auto* e = segment_entry(scan, id);
  return e && is_branch_entry(*e);
}

bool holds_tissue(const ColonScan& scan, int id) {
  const auto* e = segment_entry(scan, id);
  return e && e->value("holds", std::string("lumen")) == "tissue";
}

}  // namespace cf
