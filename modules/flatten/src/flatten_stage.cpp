#include "colonflat/flatten/flatten_stage.h"

#include <iomanip>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/run_stats.h"

namespace cf {

const StageSpec& FlattenStage::spec() const {
  static const StageSpec s{
      "flatten",
      "flattening of the colon wall onto bands: x from the rectum along the centreline, y around; area-balanced "
      "or conformal",
      {{"denoised", &mesh_artifact(), "genus-0 colon surface (after denoise)", "denoised.vtp", true, true}},
      {{"flat", &flat_artifact(), "flat colon map", "flat.vtp"}}};
  return s;
}

const ParamTable<FlattenOptions>& flatten_param_table() {
  static const ParamTable<FlattenOptions> table = [](ParamTable<FlattenOptions> t) {
#define COLONFLAT_PARAMS "colonflat/flatten/flatten_params.def"
#include "colonflat/core/params_as_rows.h"
    return t;
  }({});
  return table;
}

namespace {
// ", left out of the map N faces (M folded over)" when a segment has faces too small for its map
// ("flipped" counts the faces in the map only).
std::string left_out(const FlatSegment& s) {
  if (s.crowded_faces == 0) return "";
  return ", left out of the map " + std::to_string(s.crowded_faces) + " faces (" + std::to_string(s.inverted_faces) +
         " folded over)";
}
}  // namespace

void FlattenStage::run(ArtifactBag& bag, RunContext& ctx) {
  // Oriented as orient_mesh_input does; the list and its topology (denoise's, handed on in the
  // run) go to flatten_colon, which converts and analyses nothing again.
  OrientedMesh in = oriented_mesh_input(bag, "denoised", ctx, "flatten");
  Stopwatch sw;
  FlatMap flat = flatten_colon(in.triangles(), opts_, &in.topology);
  ctx.report = flat_report(flat);
  ctx.report["orientation"] = std::move(in.orientation);
  for (const auto& s : flat.skipped) ctx.progress("flatten: skipped " + s);
  ctx.report["flatten_time_s"] = sw.seconds();
  for (const auto& s : flat.segments) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << "flatten: segment " << s.id << " (" << s.input_kind << ", "
         << s.faces << " faces): " << s.length << " x " << s.period << " mm, flipped " << s.stats.flipped
         << left_out(s)
         << ", quasi-conformal mean " << std::setprecision(3) << s.stats.qc_mean << " p95 " << s.stats.qc_p95
         << " max " << s.stats.qc_max << ", area p05 " << s.stats.area_p05 << " p95 " << s.stats.area_p95
         << ", shown " << std::setprecision(2) << 100 * s.coverage.fraction << " % of the wall, ends "
         << s.x0_end << " (left) / " << s.x1_end << " (right), centreline " << std::setprecision(0)
         << s.centreline_length << " mm";
    ctx.progress(line.str());
  }
  if (flat.stats.flipped > 0)
    ctx.progress("flatten: warning: " + std::to_string(flat.stats.flipped) + " flipped triangles");
  std::size_t inverted = 0;
  for (const auto& s : flat.segments) inverted += s.inverted_faces;
  if (inverted > 0)
    ctx.progress("flatten: warning: " + std::to_string(inverted) + " triangles folded over, left out of the map");
  bag.put("flat", std::move(flat));
}

std::unique_ptr<Stage> make_flatten_stage() { return std::make_unique<FlattenStage>(); }

}  // namespace cf
