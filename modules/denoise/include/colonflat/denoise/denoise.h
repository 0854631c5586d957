#pragma once
// Topological denoising: removes handles (genus -> 0 or a target) by topological surgery along
// short loops, after the seed paper (cut graph, shortest loops, surgery), made exact and fast.
//
//   Mesh in = load_mesh("colon.vtp").mesh;
//   DenoiseResult r = denoise(in, DenoiseOptions{});          // one shot
//   // r.mesh: genus 0 per component; r.loops: the cut loops; r.report: JSON
//
// Methods:
//   "exact" (default): at every step cuts the shortest non-separating edge cycle of the current
//     mesh (Euclidean edge lengths; loops avoid boundary vertices). Each cut lowers its
//     component's genus by exactly one and keeps the component connected; both are checked after
//     every surgery, and a violation throws cf::Error.
//   "paper": the seed paper's Algorithms 1-4 as published: cut graph from a breadth-first dual
//     spanning tree, slicing into a disk, the shortest path between split copies of a cut-graph
//     vertex, g iterations. Its loop may be separating (then the mesh splits and genus remains).
//
// Preconditions: a 2-manifold, orientable triangle mesh (several components and boundary loops
// allowed for "exact"; "paper" needs closed components). Postconditions ("exact"): same
// components, same boundary loops, genus of each component = max(0, ...) per the stopping rules.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh.h"
#include "colonflat/core/loops.h"
#include "colonflat/core/params.h"
#include "colonflat/core/topology.h"

namespace cf {

// The options of denoise: every field is a parameter declared once, with its default, unit, range and
// help, in denoise_params.def (also the source of `colonflat denoise`'s options and docs/denoise.md's table).
struct DenoiseOptions {
#define COLONFLAT_PARAMS "colonflat/denoise/denoise_params.def"
#include "colonflat/core/params_as_fields.h"
};

// The table of DenoiseOptions (generated from denoise_params.def): option names, units, help, ranges.
const ParamTable<DenoiseOptions>& denoise_param_table();

struct DenoiseResult {
  Mesh mesh;
  std::vector<LoopRecord> loops;
  TopologyReport before, after;
  nlohmann::json report;  // genus per component before/after, loops, totals, times per phase
};

using DenoiseProgress = std::function<void(int removed, int total)>;

// Thrown by denoise() with `strict` when caps still intersect the surface (exit code 1).
// problem(): the message without the "denoise: " prefix, for callers that name the input file.
class CapIntersectionError : public Error {
 public:
  explicit CapIntersectionError(const std::string& problem) : Error("denoise: " + problem), problem_(problem) {}
  const std::string& problem() const { return problem_; }

 private:
  std::string problem_;
};

// Throws PreconditionError on invalid input, UsageError on invalid options, Error when a
// postcondition fails, CapIntersectionError when `strict` and a cap intersects the surface.
// `input_topology` (optional): analyze_topology(input), when the caller has it (the stage gets it
// from orient_mesh_input): used instead of analysing the input again if it has the input's
// vertex and face counts and the input has no deleted elements; the result is the same.
DenoiseResult denoise(const Mesh& input, const DenoiseOptions& options, const DenoiseProgress& progress = {},
                      const TopologyReport* input_topology = nullptr);

// denoise() with the result's mesh built in `out` (precondition: empty, else PreconditionError)
// instead of DenoiseResult::mesh, which is returned empty; the same mesh element by element. For
// a caller that keeps the mesh elsewhere (DenoiseStage: in the std::any its bag holds): OpenMesh
// meshes have no move operations, so handing DenoiseResult::mesh on copies every array.
DenoiseResult denoise_into(Mesh& out, const Mesh& input, const DenoiseOptions& options,
                           const DenoiseProgress& progress = {}, const TopologyReport* input_topology = nullptr);

// Validates options: the table's ranges and choices (denoise_param_table()), then the rules
// between parameters; throws UsageError.
void validate_denoise_options(const DenoiseOptions& o);

}  // namespace cf
