#include "colonflat/denoise/denoise_stage.h"

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

const ParamTable<DenoiseOptions>& DenoiseStage::table() const {
  static const ParamTable<DenoiseOptions> t = [] {
    ParamTable<DenoiseOptions> t;
    t.choice("method", &DenoiseOptions::method, {"exact", "paper"},
             "exact: shortest non-separating loop each step; paper: the seed paper's Algorithms 1-4");
    t.choice("policy", &DenoiseOptions::policy, {"shortest", "cut", "fill"},
             "which loops: shortest of any type, handle loops only (cut), tunnel loops only (fill)");
    t.real("max-loop-length", &DenoiseOptions::max_loop_length, "mm", "cut only loops shorter than this", 1e-9);
    t.integer("target-genus", &DenoiseOptions::target_genus, "", "stop when the total genus reaches this", 0);
    t.real("ring-pull", &DenoiseOptions::ring_pull, "",
           "fraction of the way each cut ring moves into its own side (separates the two caps; 0 = paper)", 0.0, 0.5);
    t.flag("check-caps", &DenoiseOptions::check_caps,
           "check every cap for intersections with the surface and try other placements");
    t.flag("strict", &DenoiseOptions::strict,
           "fail (non-zero exit, no output) when a cap still intersects the surface after every placement; default: report it");
    t.real("remove-stumps", &DenoiseOptions::remove_stumps, "mm",
           "remove the finger-like stumps up to this long that cutting thin strands leaves (0 = keep; exact only)", 0.0);
    t.integer("threads", &DenoiseOptions::threads, "",
              "threads of the exact method's loop search (2: two independent searches at once when they are large; same loops)", 1, 2);
    t.real("initial-radius", &DenoiseOptions::initial_radius, "mm",
           "first loop-search radius of the exact method (0 = 10 x mean edge length)", 0.0);
    return t;
  }();
  return t;
}

void DenoiseStage::run(ArtifactBag& bag, RunContext& ctx) {
  validate_denoise_options(opts_);
  const Mesh& in = bag.get<Mesh>("surface");
  int last_shown = -1;
  auto progress = [&](int removed, int total) {
    const int step = std::max(1, total / 20);
    if (removed == total || removed / step != last_shown) {
      last_shown = removed / step;
      ctx.progress("denoise: " + std::to_string(removed) + "/" + std::to_string(total) + " handles removed");
    }
  };
  DenoiseResult r;
  try {
    r = denoise(in, opts_, progress);
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
  bag.put("denoised", std::move(r.mesh));
  bag.put("loops", LoopSet(std::move(r.loops)));
}

std::unique_ptr<Stage> make_denoise_stage() { return std::make_unique<DenoiseStage>(); }

}  // namespace cf
