#pragma once
// The cut loops of topological denoising, one type for every stage: denoise makes them, render
// draws them (in memory in `colonflat run`), `colonflat info` describes their file.
// The "loops" artifact file: closed polylines in a .vtp with cell data loop_id, iteration,
// length_mm, vertex_count, type (0 handle, 1 tunnel), separating, component, diameter_mm,
// cross_section_area_mm2, cap_intersections; point data input_vertex_id (-1 where the vertex was
// created by surgery); field data Units = mm, CoordinateSystem = LPS.
#include <filesystem>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "colonflat/core/mesh.h"
#include "colonflat/core/stage.h"

class vtkPolyData;

namespace cf {

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

// Largest distance between two of `points` (mm; 0 for fewer than two). O(n^2).
double points_diameter(const std::vector<Vec3>& points);

// Fills centroid, diameter_mm (points_diameter), cross_section_area_mm2 and cross_section_normal
// from `points`.
void describe_cross_section(LoopRecord* loop);

using LoopSet = std::vector<LoopRecord>;

// The loops as closed polylines with the cell, point and field data above (what the file holds).
vtkSmartPointer<vtkPolyData> loops_to_polydata(const LoopSet& loops);

void write_loops(const LoopSet& loops, const std::filesystem::path& path);  // atomic
LoopSet read_loops(const std::filesystem::path& path);                      // InputError on failure
const ArtifactType& loops_artifact();                                      // value LoopSet

}  // namespace cf
