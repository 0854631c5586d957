#include "colonflat/report/report_tool.h"

#include <iomanip>
#include <iostream>

#include "colonflat/core/error.h"

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

class ReportTool : public Tool {
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
      if (!quiet) {
        for (const auto& w : r.warnings) err << "colonflat report: warning: " << w << "\n";
        err << "report: phases";
        for (const auto& [phase, secs] : r.phases) err << " " << phase << " " << std::fixed << std::setprecision(2) << secs << " s";
        err << "\n";
      }
      out << "report: " << (std::filesystem::path(run_dir) / "report.html").string() << " (" << r.candidates
          << " candidates, " << r.known_polyps << " known polyps, " << r.images << " images, "
          << r.endoluminal_views << " endoluminal views) in " << std::fixed << std::setprecision(2) << r.seconds
          << " s\n";
      return kExitOk;
    });
  }
};

}  // namespace

std::unique_ptr<Tool> make_report_tool() { return std::make_unique<ReportTool>(); }

}  // namespace cf
