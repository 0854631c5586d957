#include "colonflat/denoise/denoise_stage.h"

#include <any>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/denoise/loops_io.h"

namespace cf {

const StageSpec& DenoiseStage::spec() const {
  static const StageSpec s{
      "denoise",
      "topological denoising: cut handles along shortest non-separating loops until genus 0",
      {{"surface", &mesh_artifact(), "surface to denoise (closed or open, any genus)", "surface.vtp"}},
      {{"denoised", &mesh_artifact(), "denoised surface (LPS mm)", "denoised.vtp"},
       {"loops", &loops_artifact(), "the cut loops as polylines", "loops.vtp"}}};
  return s;
}

const ParamTable<DenoiseOptions>& denoise_param_table() {
  static const ParamTable<DenoiseOptions> table = [](ParamTable<DenoiseOptions> t) {
#define COLONFLAT_PARAMS "colonflat/denoise/denoise_params.def"
#include "colonflat/core/params_as_rows.h"
    return t;
  }({});
  return table;
}

void DenoiseStage::run(ArtifactBag& bag, RunContext& ctx) {
  TopologyReport topology;  // the input's, made on the way: denoise() need not analyse it again
  const nlohmann::json orientation = orient_mesh_input(bag, "surface", ctx, "denoise", &topology);
  const Mesh& in = bag.get<Mesh>("surface");
  int last_shown = -1;
  auto progress = [&](int removed, int total) {
    const int step = std::max(1, total / 20);
    if (removed == total || removed / step != last_shown) {
      last_shown = removed / step;
      ctx.progress("denoise: " + std::to_string(removed) + "/" + std::to_string(total) + " handles removed");
    }
  };
  // The result's mesh is built where the bag keeps it: a Mesh has no move operations, so
  // `r = denoise(...)` and bag.put(std::move(r.mesh)) each copied it (2.1 M faces: every array
  // written again into fresh pages).
  std::any denoised;
  Mesh& out = denoised.emplace<Mesh>();
  DenoiseResult r;
  try {
    r = denoise_into(out, in, opts_, progress, &topology);
  } catch (const CapIntersectionError& e) {  // --strict: the error line names the input file
    if (!bag.has("surface.file")) throw;  // not read from a file (pipeline run)
    throw Error(bag.get<std::string>("surface.file") + ": " + e.problem());
  }
  std::ostringstream msg;
  msg << "denoise: genus " << r.report["genus_before"].dump() << " -> " << r.report["genus_after"].dump() << ", "
      << r.loops.size() << " loops (" << r.report["stop_reason"].get<std::string>() << ")";
  if (!r.report["stumps"].is_null())
    msg << ", " << r.report["stumps"]["removed"].get<std::size_t>() << " stumps removed ("
        << r.report["stumps"]["faces_removed"].get<std::size_t>() << " faces)";
  const std::size_t unclean = r.report["totals"]["loops_with_cap_intersections"].get<std::size_t>();
  if (unclean > 0)
    msg << "; WARNING: " << unclean << " loop(s) with caps intersecting the surface ("
        << r.report["totals"]["cap_intersections"].get<std::size_t>() << " triangle pairs; --strict makes this an error)";
  ctx.progress(msg.str());
  ctx.report = r.report;
  ctx.report["orientation"] = orientation;
  bag.put("denoised", std::move(denoised));
  // The output's topology (the verification's analysis) for the next stage (flatten), which then
  // need not analyse the mesh again: core oriented_mesh_input.
  bag.put(topology_entry("denoised"), std::move(r.after));
  bag.put("loops", LoopSet(std::move(r.loops)));
}

std::unique_ptr<Stage> make_denoise_stage() { return std::make_unique<DenoiseStage>(); }

}  // namespace cf
