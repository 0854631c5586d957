#pragma once
// Flattening of a colon surface onto rectangles (one per colon segment).
//
// Default map "area-balanced" (see docs/flatten.md): the conformal map below, then x
// reparametrised as L * A(u) / A (L the centreline length from the level sets of u, A(u) the wall
// area below level u), y scaled so the band's area is the wall area, then a local,
// injectivity-preserving symmetric-Dirichlet correction of the regions still out of bounds. `map = "conformal"` keeps the pure
// conformal map.
//
// Per segment (connected component of genus 0): the two ends are found as geodesic extremes and
// opened (a cap of geodesic radius `end_cut_radius` removed around each), giving an annulus; an
// open tube is used as it is. On the annulus a harmonic function u (0 on one end, 1 on the other;
// cotangent Laplacian) and its conjugate v (harmonic with zero normal derivative on both ends and
// a period around the tube) form a holomorphic 1-form du + i dv (Hong et al. 2006, Zeng et al.
// 2010). Integrating it and cutting along a line v = const maps the wall onto a rectangle:
// x along the colon (mm, from end A to end B), y around it (mm). The scale makes the rectangle's
// area equal the 3D wall area. Solvers: Eigen SimplicialLDLT.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/topology.h"

#include "colonflat/core/params.h"
namespace cf {

// The options of flatten: every field is a parameter declared once, with its default, unit, range and
// help, in flatten_params.def (also the source of `colonflat flatten`'s options and docs/flatten.md's table).
struct FlattenOptions {
#define COLONFLAT_PARAMS "colonflat/flatten/flatten_params.def"
#include "colonflat/core/params_as_fields.h"
};

// The table of FlattenOptions (generated from flatten_params.def): option names, units, help, ranges.
const ParamTable<FlattenOptions>& flatten_param_table();

// How much of the 3D wall the map shows.
struct Coverage {
  double wall_area_mm2 = 0;      // wall area outside the removed end caps
  double shown_area_mm2 = 0;     // in the map with area ratio >= coverage_min_ratio
  double compressed_area_mm2 = 0;  // in the map, area ratio below coverage_min_ratio
  double missing_area_mm2 = 0;   // not in the map at all (outside the end caps)
  double end_cap_area_mm2 = 0;   // the removed end caps (not counted as wall)
  double fraction = 1;           // shown / wall
  struct Cluster {
    std::array<double, 3> centroid_lps_mm{0, 0, 0};
    double area_mm2 = 0;
    std::size_t faces = 0;
  };
  std::vector<Cluster> not_shown;  // largest first (at most 20)
};

// Distortion of the 3D -> 2D map, per triangle.
struct DistortionStats {
  std::size_t faces = 0;
  std::size_t flipped = 0;                        // triangles with non-positive 2D signed area
  std::size_t degenerate = 0;                     // input triangles with ~zero 3D area (not counted above)
  double qc_mean = 0, qc_p95 = 0, qc_max = 0;     // quasi-conformal ratio sigma1/sigma2 (1 = conformal)
  double area_p05 = 0, area_median = 0, area_p95 = 0;  // 2D area / 3D area (area-preserving scale: mean ~1)
  double area_log2_mean_abs = 0;                  // mean |log2(area ratio)|, area-weighted
};

struct FlatSegment {
  int id = 0;               // segment index (0-based) = "segment_id" of its vertices
  int component = 0;        // component of the input mesh it comes from
  std::string input_kind;   // "closed", "one open end", "tube"
  double x0 = 0, y0 = 0;    // rectangle origin in the 2D layout (mm)
  double length = 0;        // mm along the colon (x), end A at x0, end B at x0 + length
  double period = 0;        // mm around the colon (y); the map is periodic in y with this period
  double area_3d = 0;       // mm^2 of wall mapped
  std::size_t faces = 0, vertices = 0;   // of the flattened annulus (before the cut duplicates)
  std::size_t removed_faces = 0;         // faces removed when opening the closed ends
  std::array<double, 3> end_a{0, 0, 0}, end_b{0, 0, 0};  // LPS mm, centres of the end loops
  double dirichlet_period_ratio = 1;     // period from u's energy / period from v's energy (1 = consistent)
  std::string weights;      // weights used ("cotan" or "clamped")
  std::size_t untangled_vertices = 0;    // vertices re-embedded (Tutte) to undo fold-overs
  std::size_t crowded_faces = 0;         // faces left out: area factor < 1e-7 or folded (thin protrusions)
  std::size_t inverted_faces = 0;        // of those: folded over (negative 2D area), however small
  DistortionStats stats;
  // area-balanced map (empty / 0 for older files and the conformal map)
  std::string map;                                   // "area-balanced", "conformal" or "disk" (disk_map.h: x, y in
                                                     // the disk's own mm, length x period its bounding box)
  std::vector<std::array<double, 3>> centreline;     // LPS mm, from the x0 end to the x1 end
  double centreline_length = 0;                      // mm
  std::vector<std::array<double, 2>> centreline_x;   // (centreline mm from the x0 end, band x mm), increasing
  std::string x0_end = "end A", x1_end = "end B";    // "rectum", "cecum", "end A", "end B", "neck", "tip", "rim"
  int order = 0;                                     // position rectum -> cecum among segments
  double centreline_offset = 0;                      // mm of centreline of the segments before it
  std::size_t balanced_vertices = 0;                 // vertices moved by the local symmetric-Dirichlet balancing
  int corrected_iterations = 0;                      // Newton steps of the area correction (0: band within bounds)
  double balance_strength = 0;                       // beta of the x axis: 0 conformal spacing, 1 area fraction
  Coverage coverage;
  // side branches (a pouch cut off at its neck and shown as a band of its own: x0 = neck, x1 = tip)
  std::string kind = "colon";                        // "colon" or "branch"
  int parent = -1;                                   // branch: id of the band it hangs from
  double attach_mm = 0;                              // branch: centreline mm of its neck on the parent band
  std::array<double, 3> attach_lps{0, 0, 0};         // branch: centre of the neck, LPS mm
  double neck_mm = 0;                                // branch: 3D length of the neck (mm)
  std::string holds = "lumen";                       // branch: what the region closed over its neck holds:
                                                     // "lumen" (a pouch: diverticulum, blind loop), "tissue"
                                                     // (a crushed strand stump: a tissue bridge cut by denoise)
                                                     // or "wall" (a patch: wall the parent band's map hid, cut
                                                     // out and shown on its own; its "neck" is the cut's rim)
};

// The flattened colon: a triangle mesh in the plane, cut open along one line per segment (vertices
// on the cut are duplicated), with the 3D correspondence per vertex.
struct FlatMap {
  std::vector<std::array<double, 2>> uv;        // 2D position (mm) in the layout
  std::vector<std::array<double, 3>> position;  // 3D position, LPS mm
  std::vector<std::array<double, 3>> normal;    // unit 3D normal pointing out of the lumen (into the wall)
  std::vector<int> segment;                     // segment id per vertex
  std::vector<int> source_vertex;               // vertex id in the flattened input mesh
  std::vector<double> centreline_mm;            // arc length of the vertex's centreline slice from the x0 end (mm)
  std::vector<double> angle_rad;                // angle around the colon, [0, 2 pi) (y / period)
  std::vector<std::array<int, 3>> triangles;    // counter-clockwise in 2D
  std::vector<FlatSegment> segments;
  DistortionStats stats;                        // over all segments
  Coverage coverage;                            // over all segments
  std::size_t skipped_components = 0;           // small components and cavity walls not flattened
  std::vector<std::string> skipped;             // each skipped component with its size and reason
  std::size_t input_vertices = 0, input_faces = 0;
};

// Flattens every colon segment of `mesh` (LPS mm; normals out of the lumen: the stage orients its
// input first with core's orient_outward). Throws PreconditionError naming the component, its
// size and the cause when a component has genus > 0 ("run denoise first"), more than two boundary
// loops, is not a manifold or has its normals into the lumen, and when no component is left to
// flatten (each skipped one named: too small, a cavity's wall). `topology` (optional):
// analyze_topology(mesh) when the caller has it (the stage gets it from oriented_mesh_input), used
// instead of a new analysis when it fits the mesh (core topology_fits); the map is the same.
FlatMap flatten_colon(const Mesh& mesh, const FlattenOptions& opts = {});
FlatMap flatten_colon(const TriangleList& mesh, const FlattenOptions& opts = {}, const TopologyReport* topology = nullptr);

// Distortion of a flat map's triangles (3D positions vs uv).
DistortionStats distortion_stats(const FlatMap& flat, int segment = -1);

// The 3D surface of a flat map: vertices merged back by source_vertex (the cut closed again).
// `flat_to_3d` (optional) receives the 3D vertex of each flat vertex.
TriangleList flat_to_surface(const FlatMap& flat, std::vector<int>* flat_to_3d = nullptr);

nlohmann::json distortion_to_json(const DistortionStats& s);
nlohmann::json segment_to_json(const FlatSegment& s);
nlohmann::json flat_report(const FlatMap& f);
nlohmann::json coverage_to_json(const Coverage& c);
Coverage coverage_from_json(const nlohmann::json& j);

}  // namespace cf
