#include "colonflat/report/run_data.h"

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>


#include <algorithm>
#include <cmath>
#include <limits>

#include "colonflat/core/candidate_list.h"
#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/vtk_messages.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/render/polyps.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// flat.vtp (read here unless `pd` holds it already) with the optional contract-1 extras
// (centreline_mm, FlatSegments as written).
void load_flat(RunData& run, const fs::path& path, vtkPolyData* pd) {
  vtkNew<vtkXMLPolyDataReader> reader;
  if (!pd) {
    VtkMessageCapture msgs;
    reader->SetFileName(path.c_str());
    reader->Update();
    if (!msgs.first_problem().empty() || reader->GetErrorCode() != 0)
      throw InputError(path.string(), "cannot read VTK XML PolyData: " + msgs.first_problem());
    pd = reader->GetOutput();
  }
  run.flat = polydata_to_flat(pd, path.string());
  if (vtkDataArray* cl = pd->GetPointData()->GetArray("centreline_mm")) {
    run.centreline_mm.resize(cl->GetNumberOfTuples());
    for (vtkIdType i = 0; i < cl->GetNumberOfTuples(); ++i) run.centreline_mm[i] = cl->GetTuple1(i);
  }
  // FlatSegments as written (it may hold fields this build's FlatMap does not keep).
  if (auto* js = vtkStringArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray("FlatSegments"))) {
    const auto j = nlohmann::json::parse(js->GetValue(0), nullptr, false);
    if (!j.is_discarded() && j.contains("segments")) run.flat_segments = j["segments"];
  }
}

void attach_to_flat(const FlatMap& flat, std::vector<ReportFinding>& findings) {
  for (auto& f : findings) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < flat.position.size(); ++i) {
      const auto& p = flat.position[i];
      const double d = (p[0] - f.lps_mm[0]) * (p[0] - f.lps_mm[0]) + (p[1] - f.lps_mm[1]) * (p[1] - f.lps_mm[1]) +
                       (p[2] - f.lps_mm[2]) * (p[2] - f.lps_mm[2]);
      if (d < best) best = d, f.flat_vertex = int(i);
    }
    f.surface_distance_mm = std::sqrt(best);
  }
}

fs::path find_ct(const RunData& run, const RunLoadOptions& opts) {
  if (!opts.ct.empty()) {
    if (!fs::exists(opts.ct)) throw InputError(opts.ct.string(), "no such file");
    return opts.ct;
  }
  if (fs::exists(run.dir / "ct.nrrd")) return run.dir / "ct.nrrd";
  const std::string input = run.run_report.value("input", std::string());
  if (input.empty()) return {};
  for (const fs::path& p : {fs::path(input), run.dir / input, run.dir / "phantom" / fs::path(input).filename()})
    if (fs::exists(p) && looks_like_volume(p)) return p;
  return {};
}

fs::path find_truth(const RunData& run, const RunLoadOptions& opts) {
  if (!opts.truth.empty()) {
    if (!fs::exists(opts.truth)) throw InputError(opts.truth.string(), "no such file");
    return opts.truth;
  }
  if (run.ct_path.empty()) return {};
  const fs::path folder = fs::is_directory(run.ct_path) ? run.ct_path : run.ct_path.parent_path();
  if (fs::exists(folder / "phantom.json") && fs::exists(folder / "polyps.json")) return folder / "polyps.json";
  return {};
}

// A run that started from a lumen mask (its first stage is reconstruct): its input is no CT.
bool run_started_from_mask(const nlohmann::json& run_report) {
  const auto stages = run_report.value("stages", nlohmann::json::array());
  return !stages.empty() && stages[0].value("stage", "") == "reconstruct";
}

void set_flat(RunData& run, FlatMap flat) {
  if (flat.centreline_mm.size() == flat.uv.size()) run.centreline_mm = flat.centreline_mm;
  run.flat_segments = flat_report(flat).value("segments", nlohmann::json::array());
  run.flat = std::move(flat);
}

void load_candidates(RunData& run) {
  const fs::path file = find_candidate_file(run.dir);
  if (file.empty()) {
    run.warnings.push_back("no candidates.json (nor polyps.json) in the run folder: no candidate cards");
    return;
  }
  run.candidates_file = file.filename().string();
  run.candidates_doc = read_json_file(file);
  run.candidates = candidates_from_json(run.candidates_doc, file.string());
}

void load_truth(RunData& run, const RunLoadOptions& opts) {
  run.truth_path = find_truth(run, opts);
  if (run.truth_path.empty()) return;
  for (const KnownPolyp& k : read_known_polyps(run.truth_path)) {
    ReportFinding f;
    f.id = k.id;
    f.key = "K" + std::to_string(k.id);
    f.known = true;
    f.lps_mm = k.center_lps_mm;
    f.size_mm = k.diameter_mm;
    f.type = k.type;
    run.known.push_back(f);
  }
}

// What both loaders share: the truth polyps, findings placed on the flat map, missing pieces.
void complete_run(RunData& run, const RunLoadOptions& opts) {
  if (!run.flat) run.warnings.push_back("no flat map: no colon map lookup, no positions along the colon");
  if (!has_ct(run) && !run.mask) run.warnings.push_back("the CT the run read was not found (pass --ct): no CT views");
  else if (run.volume_is_mask) run.warnings.push_back("the run started from a lumen mask: the views show the mask, not a CT");
  load_truth(run, opts);
  if (run.flat) {
    attach_to_flat(*run.flat, run.candidates);
    attach_to_flat(*run.flat, run.known);
  }
}

}  // namespace

std::vector<ReportFinding> candidates_from_json(const nlohmann::json& doc, const std::string& name) {
  std::vector<ReportFinding> out;
  for (const CandidateEntry& c : candidate_list_from_json(doc, name)) {
    ReportFinding f;
    f.id = c.id;
    f.key = "P" + std::to_string(f.id);
    f.lps_mm = c.lps_mm;
    f.size_mm = c.size_mm;
    f.score = c.score.value_or(0.0);
    out.push_back(f);
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  return out;
}

RunData load_run(const fs::path& dir, const RunLoadOptions& opts) {
  RunData run;
  run.dir = dir;
  if (!fs::is_directory(dir)) throw InputError(dir.string(), "no such run folder");
  if (!fs::exists(dir / "run_report.json"))
    throw InputError(dir.string(), "not a run folder (no run_report.json; write one with `colonflat run -o DIR`)");
  run.run_report = read_json_file(dir / "run_report.json");
  if (!run.run_report.is_object()) throw InputError((dir / "run_report.json").string(), "not a JSON object");
  load_candidates(run);
  if (opts.flat || fs::exists(dir / "flat.vtp")) load_flat(run, dir / "flat.vtp", opts.flat);
  run.ct_path = find_ct(run, opts);
  if (!run.ct_path.empty()) {
    run.volume_is_mask = opts.ct.empty() && run_started_from_mask(run.run_report) &&
                         fs::path(run.run_report.value("input", "")).filename() == run.ct_path.filename();
    if (run.volume_is_mask) run.mask = read_mask(run.ct_path);
    else run.ct = read_ct_volume(run.ct_path);
  }
  if (run.ct && fs::exists(dir / "lumen_mask.nrrd")) run.lumen = read_mask(dir / "lumen_mask.nrrd");
  complete_run(run, opts);
  return run;
}

RunData run_from_artifacts(ArtifactBag& bag, const fs::path& dir, const nlohmann::json& run_report,
                           const std::string& input, const RunLoadOptions& opts) {
  RunData run;
  run.dir = dir;
  run.run_report = run_report;
  if (bag.has("candidates")) {
    run.candidates_file = "candidates.json";
    run.candidates_doc = bag.get<nlohmann::json>("candidates");
    run.candidates = candidates_from_json(run.candidates_doc, "candidates");
  } else {
    run.warnings.push_back("the run made no candidates: no candidate cards");
  }
  if (bag.has("flat")) set_flat(run, bag.take<FlatMap>("flat"));
  if (bag.has("colon_image")) run.colon_image = bag.get<ImagePtr>("colon_image");
  if (!opts.ct.empty()) {
    run.ct_path = opts.ct;
    run.ct = read_ct_volume(opts.ct);
  } else if (bag.has("ct")) {
    // As read, or in 16 bits as `colonflat run` holds it from segment's crop on
    // (pipeline/src/artifact_parking.h): the views read either, the same pixels. The lumen mask, held
    // in one bit per voxel from reconstruct on, is expanded here (after the report freed the meshes)
    // and put back in its place, so its compact copy is freed at once.
    if (const auto* ct16 = std::any_cast<CompactCtImage::Pointer>(&bag.raw("ct"))) run.ct16 = *ct16;
    else run.ct = bag.get<CtImage::Pointer>("ct");
    run.ct_path = input;
  } else if (bag.has("mask")) {
    run.mask = expanded<MaskImage::Pointer>(bag, "mask", mask_artifact());
    run.ct_path = input;
    run.volume_is_mask = true;
  }
  if (has_ct(run) && bag.has("mask")) run.lumen = expanded<MaskImage::Pointer>(bag, "mask", mask_artifact());
  complete_run(run, opts);
  return run;
}

bool run_has_file(const RunData& run, const std::string& name) {
  return std::find(run.staged_files.begin(), run.staged_files.end(), name) != run.staged_files.end() ||
         fs::exists(run.dir / name);
}

ColonPosition colon_position(const RunData& run, int v) {
  ColonPosition p;
  const FlatMap& flat = *run.flat;
  p.segment = flat.segment[v];
  const FlatSegment& s = flat.segments[p.segment];
  p.from = "end A";
  if (p.segment < int(run.flat_segments.size()))
    p.from = run.flat_segments[p.segment].value("x0_end", std::string("end A"));
  if (!run.centreline_mm.empty()) {
    p.mm = run.centreline_mm[v];
  } else {
    p.mm = flat.uv[v][0] - s.x0;
  }
  return p;
}

}  // namespace cf
