#include "colonflat/dicom/dicom_tool.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include <vtkImageData.h>

#include "colonflat/core/error.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/pair_finisher.h"
#include "colonflat/core/run_finisher.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/dicom/results.h"
#include "colonflat/report/run_data.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr const char* kSeg = "seg.dcm";
constexpr const char* kSr = "candidates_sr.dcm";
constexpr const char* kSc = "colon_image_sc.dcm";
constexpr const char* kDicomArtifact = "dicom_results";  // what finish() leaves for finish_pair()

// A scan's SR as written by finish(): rewritten with the supine-prone pairing after registration.
struct ScanSr {
  SourceSeries src;
  std::vector<SrCandidate> candidates;
  fs::path staged_sr;  // the SR's temporary in the run's transaction
};

// "prone candidate 4 (12 mm along the colon)" / "supine only" for every candidate of one scan,
// from registration.json's candidate matching.
void set_pairing(std::vector<SrCandidate>& cands, const nlohmann::json& matching, bool supine) {
  const std::string self = supine ? "supine_id" : "prone_id", other = supine ? "prone_id" : "supine_id";
  for (SrCandidate& c : cands) {
    c.pairing = supine ? "supine only" : "prone only";
    for (const auto& p : matching.value("pairs", nlohmann::json::array()))
      if (p.value(self, -1) == c.id) {
        std::ostringstream s;
        s << (supine ? "prone" : "supine") << " candidate " << p.value(other, -1) << " ("
          << std::lround(p.value("along_mm", 0.0)) << " mm along the colon)";
        c.pairing = s.str();
      }
  }
}

// The report's candidates with their place along the colon (cm from the rectum when flatten
// named that end).
std::vector<SrCandidate> sr_candidates(const RunData& run) {
  std::vector<SrCandidate> out;
  for (const ReportFinding& f : run.candidates) {
    SrCandidate c;
    c.id = f.id;
    c.lps_mm = f.lps_mm;
    c.size_mm = f.size_mm;
    if (f.score >= 0) c.score = f.score;
    if (run.flat && f.flat_vertex >= 0) {
      const ColonPosition p = colon_position(run, f.flat_vertex);
      if (p.from == "rectum") c.from_rectum_cm = p.mm / 10.0;
    }
    out.push_back(c);
  }
  return out;
}

// The three objects of a run into `stage(name)` (a path per final file); the record of what was written.
template <class Stage>
nlohmann::json write_results(const RunData& run, const MaskImage* mask, const SourceSeries& src, Stage stage) {
  nlohmann::json files = nlohmann::json::object();
  files["seg"] = {{"file", std::string("dicom/") + kSeg}, {"sop_instance_uid", write_lumen_seg(mask, src, stage(kSeg))}};
  files["sr"] = {{"file", std::string("dicom/") + kSr},
                 {"candidates", run.candidates.size()},
                 {"sop_instance_uid", write_candidates_sr(sr_candidates(run), src, stage(kSr))}};
  ImagePtr image = run.colon_image;
  if (!image && fs::exists(run.dir / "colon.png")) image = read_png(run.dir / "colon.png");
  if (image)
    files["sc"] = {{"file", std::string("dicom/") + kSc},
                   {"sop_instance_uid", write_secondary_capture(image, src, stage(kSc), "ColonFlat flat colon image")}};
  return {{"study_uid", src.study_uid}, {"patient_id", src.patient_id},
          {"frame_of_reference_uid", src.frame_of_reference_uid}, {"source_series_uid", src.series_uid},
          {"objects", files}};
}

// The lumen mask of a run: the report's when it kept it, else the file as written (staged).
MaskImage::Pointer run_mask(const RunData* data, const FinishedRun& run, const OutputTransaction& tx) {
  if (data && data->volume_is_mask && data->mask) return data->mask;
  if (run.artifacts && run.artifacts->has("mask")) return expanded<MaskImage::Pointer>(*run.artifacts, "mask", mask_artifact());
  const fs::path staged = tx.staging_folder(run.dir) / "lumen_mask.nrrd";
  std::error_code ec;
  if (!fs::exists(staged, ec)) throw Error((run.dir / "dicom").string() + ": the run wrote no lumen mask");
  return read_mask(staged);
}

class DicomTool : public Tool, public RunFinisher, public PairFinisher {
 public:
  std::string name() const override { return "dicom"; }
  std::string summary() const override {
    return "DICOM results of a run in its source study: lumen SEG, candidates SR, colon image Secondary Capture";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app("Writes RUN_DIR/dicom/: seg.dcm (the lumen mask as a DICOM Segmentation of the source CT), "
                 "candidates_sr.dcm (the polyp candidates as a Comprehensive 3D SR) and colon_image_sc.dcm (the flat "
                 "colon image as a Secondary Capture), in the source study (same patient, study and frame of "
                 "reference), new series. `colonflat run` on a DICOM input does this itself.",
                 "colonflat dicom");
    app.set_version_flag("--version", colonflat_version());
    std::string run_dir, source;
    app.add_option("run_dir", run_dir, "output folder of `colonflat run`")->required()->type_name("RUN_DIR");
    app.add_option("--source", source, "the CT series the run read (DIR or DIR/SERIES_UID)")
        ->required()
        ->type_name("SERIES");
    return run_cli(app, name(), args, out, err, [&]() -> int {
      const fs::path dir(run_dir);
      PathPlan paths;
      for (const auto& f : planned_outputs(dir)) paths.output(f, "RUN_DIR/dicom");
      paths.check();
      const SourceSeries src = read_source_series(source);
      const RunData data = load_run(dir);
      const MaskImage::Pointer mask = read_mask(dir / "lumen_mask.nrrd");
      OutputTransaction tx;
      const nlohmann::json r = write_results(data, mask.GetPointer(), src, [&](const char* f) { return tx.stage(dir / "dicom" / f); });
      tx.commit();
      out << "dicom: " << (dir / "dicom").string() << " (" << r["objects"].size() << " objects in study " << src.study_uid
          << ")\n";
      return kExitOk;
    });
  }

  // After render (the candidates and the colon image), on a DICOM input (checked in finish()).
  bool applies_to(const std::vector<std::string>& stages_run) const override {
    return !stages_run.empty() && stages_run.front() == "segment" && stages_run.back() == "render";
  }
  std::vector<fs::path> planned_outputs(const fs::path& dir) const override {
    return {dir / "dicom" / kSeg, dir / "dicom" / kSr, dir / "dicom" / kSc};
  }
  std::vector<fs::path> planned_folders(const fs::path&) const override { return {}; }
  nlohmann::json finish(FinishedRun& run, OutputTransaction& tx) override {
    Stopwatch clock;
    if (!is_dicom_series_input(run.input)) return {{"step", "dicom"}, {"skipped", "the input is not a DICOM series"}};
    const SourceSeries src = read_source_series(run.input);
    std::shared_ptr<const RunData> data;
    if (run.artifacts->has(kRunDataArtifact)) data = run.artifacts->get<std::shared_ptr<const RunData>>(kRunDataArtifact);
    if (!data) throw Error((run.dir / "dicom").string() + ": the run's report data is missing");
    const MaskImage::Pointer mask = run_mask(data.get(), run, tx);
    nlohmann::json r = write_results(*data, mask.GetPointer(), src, [&](const char* f) { return tx.stage(run.dir / "dicom" / f); });
    run.artifacts->put(kDicomArtifact, std::make_shared<const ScanSr>(ScanSr{
                                           src, sr_candidates(*data), tx.staging_folder(run.dir / "dicom") / kSr}));
    r["step"] = "dicom";
    r["time_s"] = clock.seconds();
    if (run.log) *run.log << "    DICOM results (" << r["objects"].size() << " objects) -> " << (run.dir / "dicom").string() << "\n";
    return r;
  }

  // `run SUPINE --prone PRONE` (and an exam): after the registration, both SRs say how their
  // candidates pair (registration.json's matching).
  std::vector<fs::path> pair_outputs(const fs::path&) const override { return {}; }
  std::vector<fs::path> pair_folders(const fs::path&) const override { return {}; }
  nlohmann::json finish_pair(FinishedRun& supine, FinishedRun& prone, const fs::path& dir,
                             OutputTransaction& tx) override {
    if (!supine.artifacts->has(kDicomArtifact) || !prone.artifacts->has(kDicomArtifact))
      return {{"step", "dicom pairing"}, {"skipped", "no DICOM results"}};
    const fs::path reg = tx.staging_folder(dir) / "registration.json";
    const nlohmann::json matching = read_json_file(reg).value("candidates", nlohmann::json::object());
    for (auto [run, is_supine] : {std::pair<FinishedRun*, bool>{&supine, true}, {&prone, false}}) {
      ScanSr sr = *run->artifacts->get<std::shared_ptr<const ScanSr>>(kDicomArtifact);
      set_pairing(sr.candidates, matching, is_supine);
      write_candidates_sr(sr.candidates, sr.src, sr.staged_sr);
    }
    return {{"step", "dicom pairing"}, {"pairs", matching.value("pairs", nlohmann::json::array()).size()}};
  }
};

}  // namespace

std::unique_ptr<Tool> make_dicom_tool() { return std::make_unique<DicomTool>(); }

}  // namespace cf
