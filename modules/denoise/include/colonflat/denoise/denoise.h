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

#include "colonflat/core/mesh.h"
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

struct LoopRecord {
  int id = 0;                   // 0-based, in cutting order
  int iteration = 0;            // 1-based step of the greedy loop
  int component = 0;            // component of the input (largest first, as in TopologyReport)
  std::vector<int> vertex_ids;  // input vertex ids; -1 for vertices created by earlier surgery
  std::vector<Vec3> points;     // positions when the loop was cut (LPS mm)
  double length = 0;            // Euclidean length (mm)
  std::string type;             // "handle" | "tunnel"
  bool separating = false;      // only "paper" can cut separating loops
  std::size_t cap_intersections = 0;  // triangle pairs its caps still intersect (0 unless no placement worked)
  // Set when this loop replaces the shortest one, whose caps intersected the surface in every
  // placement: another loop of the same class (modulo the classes cut before), away from it.
  double replaced_length = 0;               // mm: length of the shortest loop it replaces (0: none)
  std::size_t replaced_intersections = 0;   // triangle pairs that loop's caps intersected
  // Where it is and what it cuts (describe_cross_section):
  Vec3 centroid{0, 0, 0};              // mean of its points (LPS mm)
  double diameter_mm = 0;              // largest distance between two of its points
  double cross_section_area_mm2 = 0;   // |vector area| = area of the loop projected on its best plane
  Vec3 cross_section_normal{0, 0, 0};  // unit normal of that plane (direction of the cut tube or bridge)
};

// Fills centroid, diameter_mm, cross_section_area_mm2 and cross_section_normal from `points`.
void describe_cross_section(LoopRecord* loop);

struct DenoiseResult {
  Mesh mesh;
  std::vector<LoopRecord> loops;
  TopologyReport before, after;
  nlohmann::json report;  // genus per component before/after, loops, totals, times per phase
};

using DenoiseProgress = std::function<void(int removed, int total)>;

// Throws PreconditionError on invalid input, UsageError on invalid options, Error when a
// postcondition fails.
DenoiseResult denoise(const Mesh& input, const DenoiseOptions& options, const DenoiseProgress& progress = {});

// Validates options: the table's ranges and choices (denoise_param_table()), then the rules
// between parameters; throws UsageError.
void validate_denoise_options(const DenoiseOptions& o);

}  // namespace cf
