#pragma once
// A small run folder built in-process for the report tests: two synthetic colon segments
// (flattened, rendered: flat.vtp, colon.png, candidates.json), a CT volume of air with a bright
// 3 mm ball at the top candidate and marker balls 12 mm to its patient-left (+L) and superior
// (+S), truth polyps beside it (phantom layout: phantom/ct.nrrd, phantom.json, polyps.json) and
// run_report.json.
#include <array>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "colonflat/report/run_data.h"
#include "colonflat/volume/volume_io.h"

namespace cf::testing {

struct SyntheticRun {
  std::filesystem::path dir;
  nlohmann::json candidates;                  // candidates.json as written
  std::array<double, 3> top_candidate{0, 0, 0};  // LPS of the highest-scoring candidate (the CT ball)
  int known_polyps = 0;
};

// A CT of air (-1000 HU, 1 mm voxels) covering `lo`..`hi` (+15 mm), with +1000 HU balls of
// radius 1.5 mm at `centre`, centre + 12 mm L and centre + 12 mm S.
CtImage::Pointer ball_ct(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                         const std::array<double, 3>& centre);

// Builds the run folder in `dir` (created).
SyntheticRun make_synthetic_run(const std::filesystem::path& dir);

}  // namespace cf::testing
