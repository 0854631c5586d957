#pragma once
// The supine-prone review page (docs/register.md, "Review page"): OUT/report.html and
// OUT/report_files/ next to the registration files, built with the report module's cards
// (report_data.h: finding_json, write_finding_images; the page script shares cards.js).
//
//   cf::ReviewResult r = cf::stage_review(reg, supine_run, prone_run, cf::ReviewOptions{}, "out", tx);
//
// On top the side-by-side image (supine_prone.png) with a clickable mark per candidate; then one
// row per candidate pair: both scans' cards side by side (colon-map crop, axial / coronal /
// sagittal CT in the lung and soft-tissue windows, endoluminal view), each with its registered
// position (cm along the colon, degrees from anterior) and where it maps in the other scan, the
// pair's distances and raised score; and one row per candidate seen in one scan only: its card
// next to the other scan's views at the registered position of its point, labelled "not found in
// prone - check here" (stool or fluid moves between the scans, a polyp does not).
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "colonflat/register/register.h"
#include "colonflat/register/side_by_side.h"
#include "colonflat/report/report.h"
#include "colonflat/report/run_data.h"

namespace cf {

class OutputTransaction;

struct ReviewOptions {
  ReportOptions views;                 // view sizes, fields of view, endoluminal on/off (report's defaults)
  SideBySideOptions image;             // as given to the side-by-side image (for the marks)
  std::string side_by_side_file = "supine_prone.png";  // the image, relative to the output folder
  double check_min_fov_mm = 60;        // mm, smallest field of view of the "check here" CT views (the
                                       // registration's error, ~10 mm along / 20 deg around, stays in view)
};

struct ReviewResult {
  int pairs = 0, singles = 0;  // cards rows: candidate pairs, one-scan-only candidates
  int images = 0;              // PNGs under report_files/
  int endoluminal_views = 0;
  double seconds = 0;
  std::vector<std::pair<std::string, double>> phases;  // (phase, wall s)
  std::vector<std::string> warnings;                   // also shown on the page
};

// Stages `dir`/report.html and `dir`/report_files/ in `tx` (the caller commits). Pre: reg.run()
// has completed; `supine` / `prone` are the runs whose flat maps and candidates reg registered
// (their flat vertices in the same order as reg's scans, else found again by LPS position).
// Throws Error. COLONFLAT_TEST_FAIL=review makes it fail after writing its images (tests).
ReviewResult stage_review(const ColonRegistration& reg, const RunData& supine, const RunData& prone,
                          const ReviewOptions& opts, const std::filesystem::path& dir, OutputTransaction& tx,
                          std::ostream* log = nullptr);

}  // namespace cf
