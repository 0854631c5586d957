#include "colonflat/register/register_tool.h"

#include <array>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>

#include "colonflat/core/error.h"
#include "colonflat/core/pair_finisher.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/register/register_output.h"
#include "colonflat/register/review.h"
#include "colonflat/register/scan.h"

namespace cf {
namespace fs = std::filesystem;

const ParamTable<RegisterParams>& register_param_table() {
  static const ParamTable<RegisterParams> t = [] {
    ParamTable<RegisterParams> p;
    using P = RegisterParams;
    p.real("bin-mm", &P::bin_mm, "mm", "length bin of the colon profiles", 0.5, 20)
        .real("smooth-mm", &P::smooth_mm, "mm", "Gaussian sigma smoothing each centre line", 0, 100)
        .real("band-mm", &P::band_mm, "mm", "largest departure of the length warping from proportional", 10, 2000)
        .real("prior-weight", &P::prior_weight, "", "cost of leaving the proportional length map", 0, 100)
        .real("warp-smooth-mm", &P::warp_smooth_mm, "mm", "Gaussian sigma smoothing the length map", 0, 200)
        .real("max-twist", &P::max_twist_deg, "deg", "search range of the rotation around the colon (0 = none)", 0, 180)
        .real("twist-window-mm", &P::twist_window_mm, "mm", "colon length per rotation estimate", 10, 500)
        .choice("orientation", &P::orientation, {"auto", "same", "reverse"},
                "prone run direction: auto (tried both ways unless both maps label the rectum), same, reverse")
        .real("match-along-mm", &P::match_along_mm, "mm", "largest distance along the colon of a candidate pair", 0, 500)
        .real("match-around-deg", &P::match_around_deg, "deg", "largest angle around the colon of a candidate pair", 0, 180)
        .real("match-size-ratio", &P::match_size_ratio, "", "largest size ratio of a candidate pair", 1, 100)
        .real("position-sigma-mm", &P::position_sigma_mm, "mm", "organ motion between the scans: scale of the centre lines' distance in the length alignment", 1, 500)
        .real("support-radius-mm", &P::support_radius_mm, "mm", "centre points of the two scans farther apart than this (after the table shift) do not support the alignment", 1, 1000)
        .real("max-unsupported-mm", &P::max_unsupported_mm, "mm", "a candidate farther than this along the colon from supported alignment is never paired", 0, 1000)
        .real("match-3d-mm", &P::match_3d_mm, "mm", "largest LPS distance of a candidate pair after the table shift", 1, 2000)
        .real("pixel-mm", &P::pixel_mm, "mm", "pixel size of the side-by-side image", 0.1, 10)
        .flag("review", &P::review,
              "supine-prone review page OUT/report.html + OUT/report_files/: per candidate both scans' views, or the "
              "other scan's views where it maps (reads both runs' CTs)");
    return p;
  }();
  return t;
}

RegisterOptions register_options(const RegisterParams& p) {
  RegisterOptions o;
  o.profile.bin_mm = p.bin_mm;
  o.profile.smooth_mm = p.smooth_mm;
  o.align.band_mm = p.band_mm;
  o.align.prior_weight = p.prior_weight;
  o.align.warp_smooth_mm = p.warp_smooth_mm;
  o.twist.max_twist_deg = p.max_twist_deg;
  o.twist.window_mm = p.twist_window_mm;
  o.orientation = p.orientation;
  o.match_along_mm = p.match_along_mm;
  o.match_around_deg = p.match_around_deg;
  o.match_size_ratio = p.match_size_ratio;
  o.align.position_sigma_mm = p.position_sigma_mm;
  o.support_radius_mm = p.support_radius_mm;
  o.max_unsupported_mm = p.max_unsupported_mm;
  o.match_3d_mm = p.match_3d_mm;
  return o;
}

namespace {

// One scan as registered (ColonScan) and as reviewed (the report's RunData; null without review).
struct PairScan {
  ColonScan scan;
  std::shared_ptr<const RunData> run;
};

// From a run folder: flat.vtp is read once, for both.
PairScan scan_from_folder(const std::string& dir, bool review, std::vector<std::string>& warnings) {
  PairScan p{read_run_dir(dir), nullptr};
  if (!review) return p;
  if (!fs::exists(fs::path(dir) / "run_report.json")) {
    warnings.push_back(dir + ": no run_report.json (not a `colonflat run` folder): no review page");
    return p;
  }
  RunLoadOptions o;
  o.flat = p.scan.flat.GetPointer();
  p.run = std::make_shared<RunData>(load_run(dir, o));
  return p;
}

// From the memory of `colonflat run`: the RunData its report left, else made from the artifacts.
PairScan scan_from_memory(FinishedRun& fr) {
  PairScan p;
  if (fr.artifacts->has(kRunDataArtifact)) p.run = fr.artifacts->get<std::shared_ptr<const RunData>>(kRunDataArtifact);
  else p.run = std::make_shared<RunData>(run_from_artifacts(*fr.artifacts, fr.dir, *fr.report, fr.input));
  const RunData& run = *p.run;
  if (!run.flat) throw Error(fr.dir.string() + ": the run made no flat map to register");
  p.scan = scan_from_polydata(flat_to_polydata(*run.flat), (fr.dir / "flat.vtp").string());
  p.scan.name = fr.dir.string();
  if (!run.candidates_file.empty()) p.scan.candidates = scan_candidates_from_json(run.candidates_doc, run.candidates_file);
  p.scan.candidates_file = run.candidates_file;
  p.scan.run_report = run.run_report;
  return p;
}

class RegisterTool : public Tool, public PairFinisher {
 public:
  std::string name() const override { return "register"; }
  std::string summary() const override {
    return "supine-prone registration of two runs: length and rotation alignment, point maps, matched candidates, "
           "review page";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app(
        "Registers the prone run to the supine run (each a `colonflat run` output folder with flat.vtp and "
        "candidates.json or polyps.json). Writes OUT/registration.json (length alignment, rotation, candidate "
        "pairs and singles), OUT/supine_to_prone.vtp and OUT/prone_to_supine.vtp (per-vertex correspondence), "
        "OUT/supine_prone.png (both flat colons on one length axis) and the review page OUT/report.html "
        "(+ OUT/report_files/: per candidate both scans' views, or the other scan's views where it maps).",
        "colonflat register");
    app.set_version_flag("--version", colonflat_version());
    RegisterParams params;
    std::string supine, prone, dir;
    bool quiet = false;
    app.add_option("SUPINE_RUN_DIR", supine, "supine run folder")->required();
    app.add_option("PRONE_RUN_DIR", prone, "prone run folder")->required();
    app.add_option("-o,--output", dir, "output folder")->required()->type_name("DIR");
    register_param_table().add_to(app, params);
    app.add_flag("-q,--quiet", quiet, "no progress or summary lines");
    return run_cli(app, name(), args, out, err, [&]() -> int {
      register_param_table().validate(params);
      Stopwatch clock;
      std::vector<std::string> warnings;
      const PairScan sup = scan_from_folder(supine, params.review, warnings);
      const PairScan pro = scan_from_folder(prone, params.review, warnings);
      const double read_s = clock.seconds();
      const nlohmann::json record = register_and_write(sup, pro, params, dir, quiet ? nullptr : &err, warnings);
      if (!quiet) report(record, read_s, clock.seconds(), dir, err);
      return kExitOk;
    });
  }

  std::vector<fs::path> pair_outputs(const fs::path& dir) const override {
    return {dir / "registration.json", dir / "supine_to_prone.vtp", dir / "prone_to_supine.vtp",
            dir / "supine_prone.png", dir / "report.html"};
  }
  std::vector<fs::path> pair_folders(const fs::path& dir) const override { return {dir / "report_files"}; }

  // `colonflat run SUPINE --prone PRONE`: both runs' memory, the defaults, staged in the run's transaction.
  nlohmann::json finish_pair(FinishedRun& supine, FinishedRun& prone, const fs::path& dir,
                             OutputTransaction& tx) override {
    Stopwatch clock;
    const PairScan sup = scan_from_memory(supine), pro = scan_from_memory(prone);
    const double prepare_s = clock.seconds();
    std::vector<std::string> warnings;
    nlohmann::json record = register_and_stage(sup, pro, RegisterParams{}, dir, tx, supine.log, warnings);
    record["timing_s"]["scans_from_memory"] = prepare_s;
    record["time_s"] = clock.seconds();
    return record;
  }

 private:
  // Registration, its files and the review page, staged in `tx`; returns the summary record.
  static nlohmann::json register_and_stage(const PairScan& sup, const PairScan& pro, const RegisterParams& params,
                                           const fs::path& dir, OutputTransaction& tx, std::ostream* log,
                                           std::vector<std::string>& warnings) {
    Stopwatch clock;
    ColonRegistration reg(sup.scan, pro.scan, register_options(params));
    reg.run();
    const double register_s = clock.seconds();
    const SideBySideOptions image{params.pixel_mm};
    stage_registration(reg, dir, image, register_param_table().to_json(params), tx);
    const double files_s = clock.seconds() - register_s;
    nlohmann::json record = {{"step", "register"}, {"pairs", reg.matching().pairs.size()},
                             {"supine_only", reg.matching().supine_only.size()},
                             {"prone_only", reg.matching().prone_only.size()},
                             {"supine_length_mm", reg.supine_coordinates().profile.length_mm()},
                             {"prone_length_mm", reg.prone_coordinates().profile.length_mm()},
                             {"prone_reversed", reg.prone_reversed()},
                             {"timing_s", {{"register", register_s}, {"image_and_files", files_s}}}};
    if (sup.run && pro.run) {
      ReviewOptions ro;
      ro.image = image;
      const ReviewResult rr = stage_review(reg, *sup.run, *pro.run, ro, dir, tx, log);
      record["review"] = {{"time_s", rr.seconds}, {"images", rr.images}, {"endoluminal_views", rr.endoluminal_views}};
      record["timing_s"]["review"] = rr.seconds;
      warnings.insert(warnings.end(), rr.warnings.begin(), rr.warnings.end());
    }
    record["warnings"] = warnings;
    return record;
  }

  // The command's own transaction: the output folder is removed again when it made it and failed.
  static nlohmann::json register_and_write(const PairScan& sup, const PairScan& pro, const RegisterParams& params,
                                           const std::string& dir, std::ostream* log,
                                           std::vector<std::string>& warnings) {
    std::error_code ec;
    const bool created = !fs::exists(dir);
    fs::create_directories(dir, ec);
    if (ec) throw Error(dir + ": cannot create folder: " + ec.message());
    try {
      OutputTransaction tx;
      nlohmann::json record = register_and_stage(sup, pro, params, dir, tx, log, warnings);
      tx.commit();
      return record;
    } catch (...) {
      if (created) fs::remove_all(dir, ec);
      throw;
    }
  }

  static void report(const nlohmann::json& r, double read_s, double total_s, const std::string& dir, std::ostream& err) {
    for (const auto& w : r["warnings"]) err << "colonflat register: warning: " << w.get<std::string>() << "\n";
    const auto& t = r["timing_s"];
    err << std::fixed << std::setprecision(0) << "register: supine " << r["supine_length_mm"].get<double>()
        << " mm, prone " << r["prone_length_mm"].get<double>() << " mm"
        << (r["prone_reversed"].get<bool>() ? " (reversed)" : "") << "; " << r["pairs"] << " candidate pairs, "
        << r["supine_only"] << " supine-only, " << r["prone_only"] << " prone-only; " << std::setprecision(1) << total_s
        << " s (read " << read_s << ", register " << t["register"].get<double>() << ", image and files "
        << t["image_and_files"].get<double>();
    if (t.contains("review")) err << ", review page " << t["review"].get<double>();
    err << ") -> " << dir << "\n";
  }
};

}  // namespace

std::unique_ptr<Tool> make_register_tool() { return std::make_unique<RegisterTool>(); }

}  // namespace cf
