#include "colonflat/report/report.h"

#include <vtkImageData.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <limits>
#include <optional>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/tool.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/report_data.h"
#include "colonflat/report/resources.h"
#include "colonflat/report/segmentation_qc.h"
#include "colonflat/report/slicer_markups.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

struct Builder {
  Builder(const ReportOptions& o, std::ostream* l, const RunData& r) : opts(o), log(l), run(r), warnings(r.warnings) {}
  const ReportOptions& opts;
  std::ostream* log;
  const RunData& run;
  std::vector<std::string> warnings;  // the run's, and the report's own
  fs::path files_dir;
  nlohmann::json data = nlohmann::json::object();
  std::optional<ColonImageLayout> layout;
  ImagePtr colon;
  ReportResult result;
  bool planes_drawn_ahead = false;

  // colon.png, its layout check and the hover/click lookup grid.
  void add_image() {
    const bool have_png = run.colon_image || run_has_file(run, "colon.png");
    if (!run.flat || !have_png) {
      if (!have_png) warnings.push_back("no colon.png in the run folder: no colon image");
      return;
    }
    colon = colon_image_of(run);
    int dims[3];
    colon->GetDimensions(dims);
    data["image"] = {{"file", "colon.png"}, {"width", dims[0]}, {"height", dims[1]},
                     {"pixel_size_mm", colon_image_pixel_size(run)}};
    std::string problem;
    const auto made = colon_image_layout(run, colon, &problem);
    if (!made) {
      warnings.push_back("colon image layout does not match the flat map (" + problem +
                         "): hover read-out and click-to-CT on the image are off");
      return;
    }
    layout.emplace(*made);
    data["lookup"] = lookup_json(run, build_lookup_grid(*run.flat, *layout, opts.lookup_step_px));
  }

  // The LPS box the CT planes a click on the map shows are spread over: the lumen's voxels when the
  // run has a lumen mask (known from segment on, so the run draws the planes beside the stages),
  // else the flat map's wall; a candidate or known polyp outside it widens it. False: nothing to show.
  bool plane_box(std::array<double, 3>& lo, std::array<double, 3>& hi) const {
    lo = {1e300, 1e300, 1e300}, hi = {-1e300, -1e300, -1e300};
    const auto grow = [&](const std::array<double, 3>& p) {
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
    };
    const MaskImage* lumen = run.volume_is_mask ? run.mask.GetPointer() : run.lumen.GetPointer();
    std::array<double, 3> mlo, mhi;
    if (lumen && mask_box_lps(*lumen, mlo, mhi)) grow(mlo), grow(mhi);
    else if (run.flat) for (const auto& p : run.flat->position) grow(p);
    for (const auto& f : run.candidates) grow(f.lps_mm);
    for (const auto& f : run.known) grow(f.lps_mm);
    return lo[0] <= hi[0];
  }

  // The CT geometry and the stacks of planes a click on the map shows (`drawn`: those drawn ahead,
  // written when they are of this box and these options).
  void add_ct(const DrawnPlaneStacks* drawn) {
    if (!has_ct(run) && !run.mask) return;
    data["ct"] = with_view_volume(run, [](const auto* volume) { return ct_geometry_json(volume); });
    data["ct"]["file"] = run.ct_path.string();
    data["ct"]["is_mask"] = run.volume_is_mask;
    std::array<double, 3> lo, hi;
    if (!plane_box(lo, hi)) return;
    SliceStackOptions so;
    so.step_mm = opts.stack_step_mm;
    so.pixel_mm = opts.stack_pixel_mm;
    if (run.volume_is_mask) so.window = &mask_window();
    const bool ahead = drawn && has_ct(run) && drawn->box_min == lo && drawn->box_max == hi && drawn->step_mm == so.step_mm &&
                       drawn->pixel_mm == so.pixel_mm && drawn->planes.size() == 3;
    int i = 0;
    for (Plane p : {Plane::axial, Plane::coronal, Plane::sagittal}) {
      nlohmann::json& stack = data["stacks"][plane_name(p)];
      if (ahead) stack = write_drawn_stack(drawn->planes[std::size_t(i++)], files_dir, "report_files/");
      else stack = with_view_volume(run, [&](const auto* volume) {
        return write_slice_stack(volume, p, lo, hi, so, files_dir, "report_files/");
      });
      result.images += int(stack["files"].size());
    }
    planes_drawn_ahead = ahead;
  }

  // The Segmentation section: montages with the lumen and the bodies segment rejected.
  void add_segmentation(const SegmentationQcDrawing* drawn) {
    if (!has_ct(run) || !run.lumen) {
      data["segmentation"] = {{"missing", run.volume_is_mask ? "the run started from a lumen mask (no segmentation)"
                                                             : "no CT or no lumen_mask.nrrd in the run folder"}};
      return;
    }
    nlohmann::json seg = nlohmann::json::object();
    for (const auto& s : run.run_report.value("stages", nlohmann::json::array()))
      if (s.value("stage", "") == "segment") seg = s.value("result", nlohmann::json::object());
    const SegmentationQcDrawing here = drawn ? SegmentationQcDrawing{}
                                       : run.ct ? draw_segmentation_qc(run.ct.GetPointer(), run.lumen.GetPointer(), seg)
                                                : draw_segmentation_qc(run.ct16.GetPointer(), run.lumen.GetPointer(), seg);
    data["segmentation"] = write_segmentation_qc(drawn ? *drawn : here, files_dir, "report_files/", &result.images);
  }

  void add_findings() {
    auto endo = opts.endoluminal ? make_endoluminal_renderer(run, opts.endoluminal_pixels, warnings) : nullptr;
    for (const bool known : {false, true}) {
      nlohmann::json list = nlohmann::json::array();
      for (const ReportFinding& f : known ? run.known : run.candidates) {
        nlohmann::json fj = finding_json(run, f, layout ? &*layout : nullptr);
        result.images += write_finding_images(run, f, opts, files_dir, colon, endo.get(), fj);
        if (fj.contains("endoluminal")) ++result.endoluminal_views;
        list.push_back(fj);
      }
      data[known ? "known" : "candidates"] = list;
    }
    result.candidates = int(run.candidates.size());
    result.known_polyps = int(run.known.size());
  }

  void add_files() {
    nlohmann::json files = nlohmann::json::array();
    const auto add = [&](const std::string& name, const std::string& what) {
      files.push_back({{"file", name}, {"what", what}});
    };
    add("polyps.mrk.json", "polyp candidates: 3D Slicer point list (LPS, mm)");
    if (!run.known.empty()) add("known_polyps.mrk.json", "known (truth) polyps: 3D Slicer point list (LPS, mm)");
    const std::pair<const char*, const char*> outputs[] = {
        {"lumen_mask.nrrd", "lumen mask: labelmap (0 outside, 1 lumen), load as segmentation"},
        {"surface.vtp", "reconstructed colon wall (LPS mm)"},
        {"denoised.vtp", "colon wall after topological denoising (LPS mm)"},
        {"loops.vtp", "cut handle/tunnel loops (polylines, LPS mm)"},
        {"flat.vtp", "flat map (x, y mm; point data position_lps_mm)"},
        {"candidates.json", "candidates (JSON)"},
        {"polyps.json", "candidates (JSON, older name)"},
        {"ct.nrrd", "CT volume (HU)"}};
    for (const auto& [name, what] : outputs)
      if (run_has_file(run, name)) add(name, what);
    if (!run.ct_path.empty() && !run_has_file(run, "ct.nrrd"))
      add(run.ct_path.string(), run.volume_is_mask ? "lumen mask the run read (no CT)" : "CT volume the run read (HU)");
    data["files"] = files;
  }
};

std::string replace_once(std::string text, const std::string& marker, const std::string& with) {
  const auto at = text.find(marker);
  if (at == std::string::npos) throw Error("report template has no " + marker);
  return text.replace(at, marker.size(), with);
}

std::vector<MarkupPoint> markup_points(const nlohmann::json& list) {
  std::vector<MarkupPoint> points;
  for (const auto& f : list) {
    MarkupPoint p;
    p.label = f["key"].get<std::string>();
    p.lps_mm = f["lps_mm"].get<std::array<double, 3>>();
    std::ostringstream d;
    d << std::fixed << std::setprecision(1) << f["size_mm"].get<double>() << " mm";
    if (f.contains("score")) d << std::setprecision(2) << ", score " << f["score"].get<double>();
    if (f.contains("type")) d << ", " << f["type"].get<std::string>();
    if (f.contains("along_mm"))
      d << std::setprecision(1) << ", " << f["along_mm"].get<double>() / 10 << " cm from " << f["from"].get<std::string>()
        << " (segment " << f["segment"].get<int>() + 1 << ")";
    if (!f["match"].is_null()) d << ", matches " << f["match"]["key"].get<std::string>();
    p.description = d.str();
    points.push_back(p);
  }
  return points;
}

// Test-only fault injection (docs/pipeline.md): COLONFLAT_TEST_FAIL=report makes the report fail
// after writing its images, to prove that a failing report leaves no run output.
void maybe_inject_fault() {
  const char* fail = std::getenv("COLONFLAT_TEST_FAIL");
  if (fail && std::string(fail) == "report") throw Error("report: failure injected by COLONFLAT_TEST_FAIL=report (test only)");
}

}  // namespace

std::string report_page_html(const std::string& title, const std::string& body_html, const nlohmann::json& data,
                             const std::string& page_css, const std::string& page_js) {
  std::string json = data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  for (std::size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at + 3)) json.insert(at + 1, "\\");
  std::string html = replace_once(report_resources::kPageHtml, "/*@TITLE@*/", title);
  html = replace_once(html, "/*@BODY@*/", body_html);
  html = replace_once(html, "/*@CSS@*/", std::string(report_resources::kCss) + page_css);
  html = replace_once(html, "/*@DATA@*/", "window.REPORT = " + json + ";");
  return replace_once(html, "/*@JS@*/", std::string(report_resources::kCardsJs) + "\n" + page_js);
}

nlohmann::json report_page_data(const fs::path& html) {
  std::ifstream in(html);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string marker = "window.REPORT = ";
  const auto at = text.find(marker);
  const auto end = text.find(";</script>", at);
  if (at == std::string::npos || end == std::string::npos) return nullptr;
  return nlohmann::json::parse(text.substr(at + marker.size(), end - at - marker.size()), nullptr, false);
}

ReportResult build_review_report(const RunData& run, const ReportOptions& opts, OutputTransaction& tx,
                                 std::ostream* log, const SegmentationQcDrawing* segmentation, const DrawnPlaneStacks* planes) {
  Stopwatch clock;
  ProgressScope scope(log, "report");
  const fs::path dir = run.dir;
  Builder b(opts, log, run);
  b.files_dir = tx.stage(dir / "report_files");
  fs::create_directories(b.files_dir);
  b.data["title"] = "ColonFlat review report";
  b.data["version"] = colonflat_version();
  b.data["run_dir"] = fs::absolute(dir).lexically_normal().string();
  b.data["candidates_file"] = b.run.candidates_file;
  b.add_image();
  phase_done("colon image and lookup grid");
  b.add_ct(planes);
  phase_done(std::string(b.run.volume_is_mask ? "mask" : "CT") + " planes (" + std::to_string(b.result.images) + " images" +
             (b.planes_drawn_ahead ? ", drawn beside the stages)" : ")"));
  const int before = b.result.images;
  b.add_segmentation(segmentation);
  phase_done("segmentation montages (" + std::to_string(b.result.images - before) + " images" +
             (segmentation ? ", drawn beside the stages)" : ")"));
  b.add_findings();
  phase_done(std::to_string(b.result.candidates) + " candidate and " + std::to_string(b.result.known_polyps) +
             " known-polyp cards");
  maybe_inject_fault();
  b.add_files();
  b.data["summary"] = summary_json(b.run);
  b.data["summary"]["warnings"] = b.warnings;
  std::ofstream(tx.stage(dir / "report.html")) << report_page_html("ColonFlat review report", report_resources::kHtml, b.data, "", report_resources::kJs);
  std::ofstream(tx.stage(dir / "polyps.mrk.json"))
      << slicer_point_list("ColonFlat candidates", markup_points(b.data["candidates"]), {1.0, 0.85, 0.0}).dump(2) << "\n";
  if (!b.run.known.empty())
    std::ofstream(tx.stage(dir / "known_polyps.mrk.json"))
        << slicer_point_list("Known polyps", markup_points(b.data["known"]), {0.25, 0.9, 0.4}).dump(2) << "\n";
  phase_done("page and Slicer files");
  for (const auto& p : scope.phases()) b.result.phases.emplace_back(p["phase"].get<std::string>(), p["time_s"].get<double>());
  b.result.warnings = b.warnings;
  b.result.seconds = clock.seconds();
  return b.result;
}

ReportResult write_review_report(const fs::path& run_dir, const ReportOptions& opts, std::ostream* log) {
  Stopwatch clock;
  ProgressScope scope(log, "report");
  RunData run = load_run(run_dir, {opts.ct, opts.truth});
  phase_done("read the run folder");
  OutputTransaction tx;
  ReportResult r = build_review_report(run, opts, tx, log);
  tx.commit();
  r.phases.insert(r.phases.begin(), {"read the run folder", scope.phases()[0]["time_s"].get<double>()});
  r.seconds = clock.seconds();
  return r;
}

}  // namespace cf
