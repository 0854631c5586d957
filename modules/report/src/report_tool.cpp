#include "colonflat/report/report_tool.h"

#include <future>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>

#include "colonflat/core/error.h"
#include "colonflat/core/malloc_tunables.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/run_finisher.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/run_data.h"
#include "colonflat/report/segmentation_qc.h"

namespace cf {

const ParamTable<ReportOptions>& report_param_table() {
  static const ParamTable<ReportOptions> t = [] {
    ParamTable<ReportOptions> t;
    t.text("ct", &ReportOptions::ct, "CT volume of the run (default: ct.nrrd in RUN_DIR, else the run's input)");
    t.text("truth", &ReportOptions::truth,
           "known polyps JSON (default: polyps.json beside a phantom CT); shown as known-polyp cards");
    t.integer("lookup-step", &ReportOptions::lookup_step_px, "px", "cell of the hover/click lookup grid", 1, 64);
    t.real("stack-step", &ReportOptions::stack_step_mm, "mm", "spacing of the CT planes shown on clicks", 0.5, 50);
    t.real("stack-pixel", &ReportOptions::stack_pixel_mm, "mm", "pixel of those CT planes", 0.2, 5);
    t.integer("tile-pixels", &ReportOptions::tile_pixels, "px", "side of a finding's CT views", 32, 1024);
    t.real("min-fov", &ReportOptions::min_fov_mm, "mm", "smallest field of view of a finding's CT views", 5, 500);
    t.real("fov-per-size", &ReportOptions::fov_per_size, "", "field of view / finding diameter", 1, 50);
    t.real("max-fov", &ReportOptions::max_fov_mm, "mm", "largest field of view of a finding's CT views", 5, 500);
    t.integer("thumbnail-pixels", &ReportOptions::thumbnail_pixels, "px", "side of a finding's colon-image crop", 32,
              2048);
    t.flag("endoluminal", &ReportOptions::endoluminal, "render endoluminal 3D views (X display or Xvfb)");
    t.integer("endoluminal-pixels", &ReportOptions::endoluminal_pixels, "px", "side of an endoluminal view", 64, 2048);
    return t;
  }();
  return t;
}

namespace {

// `colonflat report RUN_DIR` reads a run's files; as the run's finisher it gets the run's memory.
class ReportTool : public Tool, public RunFinisher {
 public:
  std::string name() const override { return "report"; }
  std::string summary() const override {
    return "review report of a run folder: report.html (+ report_files/), polyps.mrk.json (3D Slicer)";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app("Builds RUN_DIR/report.html (a static page: colon image with hover read-out and click-to-CT, one "
                 "card per candidate with CT planes and an endoluminal view, run summary), RUN_DIR/report_files/ "
                 "and RUN_DIR/polyps.mrk.json (3D Slicer point list, LPS mm) from the files of `colonflat run`.",
                 "colonflat report");
    app.set_version_flag("--version", colonflat_version());
    std::string run_dir;
    bool quiet = false;
    ReportOptions opts;
    app.add_option("run_dir", run_dir, "output folder of `colonflat run`")->required()->type_name("RUN_DIR");
    app.add_flag("-q,--quiet", quiet, "no progress output");
    report_param_table().add_to(app, opts);
    return run_cli(app, name(), args, out, err, [&]() -> int {
      report_param_table().validate(opts);
      if (opts.min_fov_mm > opts.max_fov_mm) throw UsageError("--min-fov must not exceed --max-fov");
      const ReportResult r = write_review_report(run_dir, opts, quiet ? nullptr : &err);
      if (!quiet)
        for (const auto& w : r.warnings) err << "colonflat report: warning: " << w << "\n";
      out << "report: " << (std::filesystem::path(run_dir) / "report.html").string() << " (" << r.candidates
          << " candidates, " << r.known_polyps << " known polyps, " << r.images << " images, "
          << r.endoluminal_views << " endoluminal views) in " << std::fixed << std::setprecision(2) << r.seconds
          << " s\n";
      return kExitOk;
    });
  }

  // After render (the report needs the colon image and its candidates).
  bool applies_to(const std::vector<std::string>& stages_run) const override {
    return !stages_run.empty() && stages_run.back() == "render";
  }
  std::vector<std::filesystem::path> planned_outputs(const std::filesystem::path& dir) const override {
    return {dir / "report.html", dir / "polyps.mrk.json", dir / "known_polyps.mrk.json"};
  }
  std::vector<std::filesystem::path> planned_folders(const std::filesystem::path& dir) const override {
    return {dir / "report_files"};
  }
  // After segment: the Segmentation section is drawn on a second thread while the later stages
  // run (it needs only the CT, the lumen and segment's decisions), from the CT as the bag holds it
  // (in 16 bits once the run has parked it during segment). The thread drops its CT and lumen
  // references when done, so the run can park the mask (and a float CT) after reconstruct.
  // The CT planes a click on the map shows are drawn on the same thread next: their box is the
  // lumen's (build_review_report), known now.
  void stage_done(const std::string& stage, const ArtifactBag& bag, const nlohmann::json& record) override {
    if (stage != "segment" || !bag.has("ct") || !bag.has("mask")) return;
    const std::any& ct_held = bag.raw("ct");
    if (const auto* ct = std::any_cast<CtImage::Pointer>(&ct_held)) draw_ahead(*ct, bag, record);
    // the run holds the CT in 16 bits from segment's crop on: the same drawings
    else if (const auto* ct16 = std::any_cast<CompactCtImage::Pointer>(&ct_held)) draw_ahead(*ct16, bag, record);
  }

 private:
  // The Segmentation section and the CT planes drawn on a second thread (stage_done).
  template <class CtPointer>
  void draw_ahead(const CtPointer& ct_held, const ArtifactBag& bag, const nlohmann::json& record) {
    drawn_ = std::async(std::launch::async, [ct = ct_held, lumen = bag.get<MaskImage::Pointer>("mask"),
                                             result = record.value("result", nlohmann::json::object())]() mutable {
      DrawnAhead d;
      d.segmentation = draw_segmentation_qc(ct.GetPointer(), lumen.GetPointer(), result);
      std::array<double, 3> lo, hi;
      if (mask_box_lps(*lumen, lo, hi)) {
        const ReportOptions defaults;  // the finisher's (finish below)
        SliceStackOptions so;
        so.step_mm = defaults.stack_step_mm;
        so.pixel_mm = defaults.stack_pixel_mm;
        d.planes = draw_plane_stacks(ct.GetPointer(), lo, hi, so);
      }
      ct = nullptr, lumen = nullptr;
      release_free_memory();  // the CT's or mask's pages, when the run parked them meanwhile, back now
      return d;
    });
  }

 public:
  nlohmann::json finish(FinishedRun& run, OutputTransaction& tx) override {
    Stopwatch clock;
    ProgressScope scope(run.log, "report");
    // The meshes are written; free them before the report's views allocate.
    for (const char* done : {"surface", "denoised", "loops"}) run.artifacts->erase(done);
    phase_done("meshes released");
    auto data = std::make_shared<RunData>(run_from_artifacts(*run.artifacts, run.dir, *run.report, run.input));
    for (const auto& target : tx.targets())
      if (target.parent_path() == run.dir) data->staged_files.push_back(target.filename().string());
    phase_done("run data from memory");
    std::optional<DrawnAhead> drawn;
    if (drawn_.valid()) drawn = drawn_.get();
    const ReportResult r = build_review_report(*data, ReportOptions{}, tx, run.log, drawn ? &drawn->segmentation : nullptr,
                                               drawn && drawn->planes ? &*drawn->planes : nullptr);
    // Left for what follows on the same memory (`colonflat run --prone`: the supine-prone review);
    // the lumen mask is not needed any more when the views show the CT.
    if (!data->volume_is_mask) run.artifacts->erase("mask");
    run.artifacts->put(kRunDataArtifact, std::shared_ptr<const RunData>(data));
    for (const auto& w : r.warnings)
      if (run.log) *run.log << "colonflat report: warning: " << w << "\n";
    nlohmann::json phases = scope.phases();
    for (const auto& [phase, secs] : r.phases) phases.push_back({{"phase", phase}, {"time_s", secs}});
    return {{"step", "report"}, {"time_s", clock.seconds()}, {"phases", phases}, {"candidates", r.candidates},
            {"known_polyps", r.known_polyps}, {"images", r.images}, {"endoluminal_views", r.endoluminal_views},
            {"warnings", r.warnings}};
  }

 private:
  // Drawn beside the stages after segment: the Segmentation section and the CT planes.
  struct DrawnAhead {
    SegmentationQcDrawing segmentation;
    std::optional<DrawnPlaneStacks> planes;  // none when the lumen is empty
  };
  std::future<DrawnAhead> drawn_;
};

}  // namespace

std::unique_ptr<Tool> make_report_tool() { return std::make_unique<ReportTool>(); }

}  // namespace cf
