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
#include "colonflat/core/params.h"
#include "colonflat/core/topology.h"

namespace cf {

struct DenoiseOptions {
  std::string method = "exact";      // exact | paper
  std::string policy = "shortest";   // shortest | cut (handle loops only) | fill (tunnel loops only)
  double max_loop_length = kInf;     // mm; only loops shorter than this are cut
  int target_genus = 0;              // stop when the total genus reaches this
  double ring_pull = 0.25;           // 0..0.5; how far each ring moves into its own side (0 = paper's caps)
  double initial_radius = 0;         // mm; first search radius for "exact" (0 = 10 x mean edge length)
  bool check_caps = true;            // test each cap for intersections with the surface and try
                                     // other placements until none remains
  bool strict = false;               // fail (cf::Error) when a cap still intersects the surface
  int threads = 1;                   // 1 or 2: with 2, "exact" runs two independent loop searches
                                     // at once when searches are large (same loops either way)
  double remove_stumps = 0;          // mm; 0 = off. Else ("exact" only) remove the finger-like
                                     // stumps up to this long that cutting thin strands leaves
                                     // (stumps.h); changes vertex ids
};

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
DenoiseResult denoise(const Mesh& input, const DenoiseOptions& options, const DenoiseProgress& progress = {});

// Validates options (ranges and choices); throws UsageError.
void validate_denoise_options(const DenoiseOptions& o);

}  // namespace cf
