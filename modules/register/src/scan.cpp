#include "colonflat/register/scan.h"

#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <cmath>
#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
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

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "cannot open");
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) throw InputError(path.string(), "not valid JSON");
  return j;
}

// A 3-vector from the first key of `keys` present in `e`.
bool vector3_from(const nlohmann::json& e, std::initializer_list<const char*> keys, Eigen::Vector3d& v) {
  for (const char* k : keys) {
    if (!e.contains(k)) continue;
    const auto& a = e[k];
    if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number()) return false;
    v = {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    return std::isfinite(v.sum());
  }
  return false;
}

double number_from(const nlohmann::json& e, std::initializer_list<const char*> keys, double fallback) {
  for (const char* k : keys)
    if (e.contains(k) && e[k].is_number()) return e[k].get<double>();
  return fallback;
}

void read_vector_array(vtkDataArray* a, std::vector<Eigen::Vector3d>& out) {
  out.resize(size_t(a->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i) a->GetTuple(i, out[size_t(i)].data());
}

}  // namespace

std::vector<ScanCandidate> scan_candidates_from_json(const nlohmann::json& j, const std::string& name) {
  const nlohmann::json* list = &j;
  if (j.is_object()) {
    if (!j.contains("candidates") || !j["candidates"].is_array())
      throw InputError(name, "no \"candidates\" list");
    list = &j["candidates"];
  } else if (!j.is_array()) {
    throw InputError(name, "expected a candidate list or an object with \"candidates\"");
  }
  std::vector<ScanCandidate> out;
  for (size_t k = 0; k < list->size(); ++k) {
    const auto& e = (*list)[k];
    ScanCandidate c;
    if (!e.is_object() || !vector3_from(e, {"position_lps_mm", "center_lps_mm", "center", "position"}, c.lps))
      throw InputError(name, "candidate " + std::to_string(k + 1) + " has no position_lps_mm [L, P, S]");
    c.id = e.contains("id") && e["id"].is_number_integer() ? e["id"].get<int>() : int(k + 1);
    c.size_mm = number_from(e, {"size_mm", "diameter_mm"}, 0.0);
    c.score = number_from(e, {"score"}, 1.0);
    out.push_back(c);
  }
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
  for (const char* file : {"candidates.json", "polyps.json"}) {
    if (!fs::exists(dir / file)) continue;
    s.candidates = scan_candidates_from_json(read_json(dir / file), (dir / file).string());
    s.candidates_file = file;
    break;
  }
  if (fs::exists(dir / "run_report.json")) {
    s.run_report = read_json(dir / "run_report.json");
    if (!s.run_report.is_object()) throw InputError((dir / "run_report.json").string(), "not a JSON object");
  }
  return s;
}

void write_run_dir(const ColonScan& scan, const fs::path& dir) {
  fs::create_directories(dir);
  OutputTransaction tx;
  const fs::path flat_tmp = tx.stage(dir / "flat.vtp");
  {
    VtkMessageCapture msgs;
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetFileName(flat_tmp.c_str());
    w->SetInputData(scan.flat);
    w->SetDataModeToAppended();
    if (!w->Write() || !msgs.first_problem().empty())
      throw Error((dir / "flat.vtp").string() + ": cannot write: " + msgs.first_problem());
  }
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : scan.candidates)
    cands.push_back({{"id", c.id}, {"position_lps_mm", {c.lps.x(), c.lps.y(), c.lps.z()}},
                     {"size_mm", c.size_mm}, {"score", c.score}});
  std::ofstream(tx.stage(dir / "candidates.json"))
      << nlohmann::json{{"units", "mm"}, {"coordinate_system", "LPS"}, {"candidates", cands}}.dump(1);
  std::ofstream(tx.stage(dir / "run_report.json")) << scan.run_report.dump(1);
  tx.commit();
}

}  // namespace cf
