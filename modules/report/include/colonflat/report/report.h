#pragma once
// The review report of a run folder: report.html (one static page, no network: plain HTML, CSS
// and JS with the data embedded as JSON; images beside it under report_files/), polyps.mrk.json
// (3D Slicer point list of the candidates, LPS) and, for a phantom, known_polyps.mrk.json.
//
//   cf::ReportResult r = cf::write_review_report("run_dir");   // after `colonflat run -o run_dir`
//
// Pre: run_dir holds a run's files (contract 3; at least run_report.json). Post: the three outputs
// appear together or not at all (an existing report is replaced).
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace cf {

struct RunData;
struct SegmentationQcDrawing;
struct DrawnPlaneStacks;
class OutputTransaction;

struct ReportOptions {
  std::string ct;                  // CT volume (empty: ct.nrrd in the run folder, else the run's input)
  std::string truth;               // known polyps JSON (empty: polyps.json beside a phantom CT)
  int lookup_step_px = 6;          // px, cell of the hover/click lookup grid over colon.png
  double stack_step_mm = 5;        // mm between the pre-rendered CT planes used for clicks on the map
  double stack_pixel_mm = 1.0;     // mm, pixel of those planes
  int tile_pixels = 160;           // px, side of a finding's CT views
  double min_fov_mm = 30;          // mm, smallest field of view of a finding's CT views
  double fov_per_size = 4;         // field of view = this x the finding's diameter, within [min, max]
  double max_fov_mm = 80;          // mm
  int thumbnail_pixels = 200;      // px, side of a finding's crop of the colon image
  bool endoluminal = true;         // endoluminal 3D views (need an X display or Xvfb)
  int endoluminal_pixels = 256;    // px
};

struct ReportResult {
  int candidates = 0, known_polyps = 0;
  int images = 0;               // PNGs written under report_files/
  int endoluminal_views = 0;
  double seconds = 0;
  std::vector<std::pair<std::string, double>> phases;  // (phase, wall s), in order
  std::vector<std::string> warnings;  // also shown on the page
};

// Throws InputError (not a run folder, unreadable file), Error (cannot write). `log`: progress
// lines "report: <phase> N s".
ReportResult write_review_report(const std::filesystem::path& run_dir, const ReportOptions& opts = {},
                                 std::ostream* log = nullptr);

// The report of a loaded run (load_run() from files, or run_from_artifacts() from the memory of
// `colonflat run`): report.html, polyps.mrk.json, known_polyps.mrk.json (with truth) and the
// folder report_files/ in run.dir, staged through `tx`; nothing appears until the caller commits.
// `segmentation`: the Segmentation section drawn already from the run's CT, lumen and segment
// result (`colonflat run` draws it beside its later stages); null: drawn here. `planes`: the CT
// planes a click on the map shows, drawn ahead from the run's CT over its lumen's box (the same
// run), written when their box and options are the report's own (draw_plane_stacks); else drawn here.
ReportResult build_review_report(const RunData& run, const ReportOptions& opts, OutputTransaction& tx,
                                 std::ostream* log = nullptr, const SegmentationQcDrawing* segmentation = nullptr,
                                 const DrawnPlaneStacks* planes = nullptr);

// A report page: the shared skeleton (resources/page.html: head, footer, scripts) titled `title`
// around `body_html`, with the report's style sheet followed by `page_css`, `window.REPORT = data`,
// and the shared card script (colonflatCards, resources/cards.js) followed by `page_js`. The run
// report and register's supine-prone review are both built with it.
std::string report_page_html(const std::string& title, const std::string& body_html, const nlohmann::json& data,
                             const std::string& page_css, const std::string& page_js);
// The data embedded in such a page (window.REPORT); null when the file holds none.
nlohmann::json report_page_data(const std::filesystem::path& html);

}  // namespace cf
