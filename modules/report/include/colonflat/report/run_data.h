#pragma once
// The files of a `colonflat run` output folder, loaded for the review report (contract 3):
// run_report.json, candidates.json (or the older polyps.json), flat.vtp, the CT the run read and,
// for a phantom, its truth polyps.json. Every piece but run_report.json is optional: what is
// missing is listed in `warnings` and the report leaves the matching section out.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/stage.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/volume/volume_io.h"

class vtkPolyData;

namespace cf {

// A polyp candidate of the run or a known (truth) polyp, with where it sits on the flat map.
struct ReportFinding {
  std::string key;                        // "P3" (candidate 3) or "K2" (known polyp 2)
  int id = 0;
  bool known = false;                     // truth polyp (else a candidate)
  std::array<double, 3> lps_mm{0, 0, 0};  // LPS mm
  double size_mm = 0;                     // estimated (candidate) or true (known) diameter
  double score = -1;                      // candidates: 0..1; known polyps: -1
  std::string type;                       // known polyps: "sessile", "pedunculated", ...
  int flat_vertex = -1;                   // nearest flat-map vertex (-1 without a flat map)
  double surface_distance_mm = 0;         // distance to that vertex (mm)
};

struct RunLoadOptions {
  std::filesystem::path ct;     // CT volume; empty: ct.nrrd in the run folder, else the run's input
  std::filesystem::path truth;  // known polyps JSON; empty: polyps.json beside a phantom CT
  vtkPolyData* flat = nullptr;  // the run's flat.vtp when already read (not read again), else null
};

struct RunData {
  std::filesystem::path dir;
  nlohmann::json run_report = nlohmann::json::object();
  std::string candidates_file;                 // "candidates.json", "polyps.json" or "" (none)
  nlohmann::json candidates_doc = nlohmann::json::object();
  std::vector<ReportFinding> candidates;       // sorted by decreasing score
  std::vector<ReportFinding> known;            // truth polyps, by id
  std::optional<FlatMap> flat;
  std::vector<double> centreline_mm;           // per flat vertex (contract 1); empty when absent
  nlohmann::json flat_segments = nlohmann::json::array();  // FlatSegments "segments" (as written)
  CtImage::Pointer ct;                         // null when no CT was found, or held in ct16
  CompactCtImage::Pointer ct16;                // the CT in 16 bits as `colonflat run` holds it (the same HU), else null
  MaskImage::Pointer mask;                     // without a CT: the lumen mask the run started from
  bool volume_is_mask = false;                 // the views show `mask` (0/1), not a CT
  MaskImage::Pointer lumen;                    // with a CT: the run's lumen mask (segment's output), else null
  ImagePtr colon_image;                        // colon.png in memory; null: read from the run folder
  std::filesystem::path ct_path, truth_path;
  std::vector<std::string> warnings;           // what is missing or inconsistent, for the page
  std::vector<std::string> staged_files;       // run-folder files of the same (uncommitted) transaction
};

// Whether the run has a CT (float or in 16 bits).
inline bool has_ct(const RunData& run) { return run.ct || run.ct16; }
// f(volume) on the volume the views show: the CT (float or in 16 bits), else the lumen mask
// (volume_is_mask). Pre: has_ct(run) or run.mask. f takes a const CtImage*, CompactCtImage* or MaskImage*.
template <class F>
decltype(auto) with_view_volume(const RunData& run, F&& f) {
  if (run.ct) return f(run.ct.GetPointer());
  if (run.ct16) return f(run.ct16.GetPointer());
  return f(run.mask.GetPointer());
}

// The bag name under which the report finisher of `colonflat run` leaves the run's RunData
// (std::shared_ptr<const RunData>) for a later step on the same memory (the supine-prone review).
inline constexpr const char* kRunDataArtifact = "report_run";

// Whether the run folder has (or, once committed, will have) the file `name`.
bool run_has_file(const RunData& run, const std::string& name);

// Loads a run folder. Throws InputError when `dir` is not a run folder (no run_report.json) or a
// file that is there cannot be read.
RunData load_run(const std::filesystem::path& dir, const RunLoadOptions& opts = {});

// The same from the artifacts `colonflat run` still holds after its last stage (no file is read
// but the truth polyps.json): "flat" is moved out of `bag`; the view volume is "ct" (shared as it
// is held: float, or in 16 bits in ct16, never expanded), else the lumen mask "mask"
// (volume_is_mask); "colon_image" and "candidates" are shared.
// `run_report` is the run's report so far; `input` the run's input (shown as the CT's file).
RunData run_from_artifacts(ArtifactBag& bag, const std::filesystem::path& dir, const nlohmann::json& run_report,
                           const std::string& input, const RunLoadOptions& opts = {});

// The candidates of a candidates.json / polyps.json document, read with core's
// candidate_list_from_json (core/candidate_list.h), sorted by decreasing score. Throws InputError.
std::vector<ReportFinding> candidates_from_json(const nlohmann::json& doc, const std::string& name_for_errors);

// Position along the colon of flat vertex v: mm from the rectal end (or end A), with the label of
// the end it is measured from ("rectum", "end A", ...).
struct ColonPosition {
  int segment = 0;
  double mm = 0;
  std::string from;
};
ColonPosition colon_position(const RunData& run, int flat_vertex);

}  // namespace cf
