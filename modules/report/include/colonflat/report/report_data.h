#pragma once
// The pieces of the report page's data (JSON embedded in report.html) and the images they point
// to. Used by write_review_report(); separate for tests.
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>
#include <string>

#include <nlohmann/json.hpp>

#include "colonflat/report/endoluminal.h"
#include "colonflat/report/image_layout.h"
#include "colonflat/report/report.h"
#include "colonflat/report/run_data.h"

namespace cf {

// Pixel size (mm) of the run's colon.png: from run_report.json (render result), else the
// candidates document, else 0.5.
double colon_image_pixel_size(const RunData& run);

// The lookup grid as JSON: {step_px, cols, rows, cells: [segment, mm along x10, L x10, P x10,
// S x10] per cell (segment -1: background)}, integers to keep the page small.
nlohmann::json lookup_json(const RunData& run, const LookupGrid& grid);

// One finding's JSON: key, id, known, lps_mm, size_mm, score, type, segment, along_mm, from,
// pixel, surface_distance_mm, match (the nearest finding of the other kind when within
// diameter/2 + 5 mm), without images.
nlohmann::json finding_json(const RunData& run, const ReportFinding& f, const ColonImageLayout* layout);

// Writes a finding's images into `files_dir` (CT planes in two windows, colon-image crop,
// endoluminal view when `endo` is given) and records their paths (relative to the run folder,
// under "report_files/") in `fj`. Returns the number of images written.
int write_finding_images(const RunData& run, const ReportFinding& f, const ReportOptions& opts,
                         const std::filesystem::path& files_dir, vtkImageData* colon_image,
                         EndoluminalRenderer* endo, nlohmann::json& fj);

// The run's colon.png: from memory, else read from the run folder; null when there is none.
ImagePtr colon_image_of(const RunData& run);

// Where the flat map lies in `colon` (the run's colon.png), checked against the image size and the
// candidates' pixels; nullopt (and `problem` says why) when it does not match or a piece is missing.
// The layout refers to run.flat: the run must outlive it.
std::optional<ColonImageLayout> colon_image_layout(const RunData& run, vtkImageData* colon, std::string* problem);

// The endoluminal renderer of the run's wall (`pixels` square views); null, with a warning added,
// when the run has no flat map or no display can be had.
std::unique_ptr<EndoluminalRenderer> make_endoluminal_renderer(const RunData& run, int pixels,
                                                               std::vector<std::string>& warnings);

// Run summary for the page: stages (time, memory, result), totals, snapshots, warnings.
nlohmann::json summary_json(const RunData& run);

}  // namespace cf
