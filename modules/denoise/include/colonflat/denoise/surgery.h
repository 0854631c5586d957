#pragma once
// Topological surgery along an edge loop (Algorithm 3 of the seed paper, with separated caps).
//
// cut_and_cap() slices the mesh along a simple edge cycle, which splits each loop vertex into a
// left and a right copy and opens two boundary rings, then fills each ring with a fan to a new
// vertex. Unlike the paper, whose two centroid fans coincide in space, each ring is first pulled
// a fraction of the way into its own side (towards its own neighbours), and each cap is a small
// disk relaxed to a discrete minimal surface spanning its pulled ring (centre vertex at the
// centroid for a plain fan), so the two caps are disjoint and follow non-planar loops. With a
// guard, caps are first minimum-area triangulations of the pulled rings, restricted when needed
// to triangles that intersect nothing (cap_triangulation.h, face_grid.h; surgery.cpp, step 7a). Nothing is deleted: the input's
// vertex ids stay valid (right copies keep the original ids; left copies and caps are appended).
#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/denoise/run_both.h"
#include "colonflat/denoise/face_grid.h"

namespace cf {

class HomologyBasis;

struct SurgeryOptions {
  double ring_pull = 0.25;  // fraction (0..0.5) of the way from a ring vertex to the centroid of
                            // its same-side neighbours; 0 gives the paper's coincident caps
  int cap_rings = 4;        // concentric rings of a cap (1 = the paper's fan to the centroid)
  FaceGrid* guard = nullptr;  // when set: try placements until the new geometry intersects
                              // nothing (see SurgeryResult::intersections), and update the grid
  bool restricted = true;  // with a guard: also the triangulations restricted to clean triangles
  bool front = true;       // with a guard: also front caps (grown from the ring, steered off the surface)
  bool trial = false;      // with a guard: the caller keeps the result only when it intersects
                           // nothing, so concentric caps stay in their first placement and their
                           // pairs are counted up to the first (intersections is 0 or 1)
  bool triangulated = true;  // with a guard: try the triangulated caps (plain, collar, front,
                             // restricted) before the concentric ones; off when they are known to
                             // fail (the same loop on the same mesh failed them before)
  bool mincut = false;  // with a guard, not a trial: before the concentric caps, caps from the
                        // minimum cut of free space around the loop (free_space_cut.h; kept when clean)
  double mincut_cell = 0.25;  // mm: cell edge of that cut's graph
  double mincut_widen = 1.5;  // cells: when that cut's disk has holes (a left and a right wall within a
                              // cell), the surface's walls there are moved apart by up to this much
                              // each (then 2/3 and 1/3 of it) and the cut made again; 0 = never
                              // (surgery_mincut_widen.cpp; kept only with clean caps)
  bool probe_concentric = false;  // with a guard, not a trial: the concentric placements are only
                                  // searched for a clean one (each count stops at its first pair);
                                  // without one the caps stay in the first placement, whose pairs
                                  // are reported (the caller undoes such a cut)
  // With a helper thread (run_both.h; empty: one thread), the restricted caps
  // triangulate the left ring alone on the helper beside the right ring's triangulation,
  // and use it only where the one-thread order computes that same triangulation within the same
  // query budget: the caps are the same for any thread count.
  RunBoth run_both;
};

// What undo_surgery() needs to put the mesh back as it was before cut_and_cap(): the element
// counts (everything the surgery created comes after them), the connectivity it rewired and the
// positions it moved.
struct SurgeryUndo {
  std::size_t vertices = 0, edges = 0, faces = 0;
  std::vector<std::pair<Mesh::HalfedgeHandle, Mesh::VertexHandle>> targets;  // fan halfedges' old to-vertex
  std::vector<std::pair<Mesh::FaceHandle, std::array<Mesh::HalfedgeHandle, 3>>> face_cycles;
  std::vector<std::pair<Mesh::VertexHandle, Mesh::HalfedgeHandle>> vertex_halfedges;
  std::vector<std::pair<Mesh::VertexHandle, Vec3>> positions;
};

struct SurgeryResult {
  std::vector<Mesh::VertexHandle> left_ring, right_ring;  // copies, in loop order
  Mesh::VertexHandle left_cap, right_cap;                 // cap centres
  std::size_t intersections = 0;  // triangle pairs the chosen placement still intersects (guard only)
  const char* caps = "concentric";  // which step made the caps: plain, collar, front, restricted, mincut or concentric
  int placement = -1;  // index of the ring placement the triangulated caps were made in (0 = the first); -1: concentric
  double widened = 0;  // mm: the largest move of a surface vertex the minimum-cut caps kept (walls moved
                       // apart at the cut's holes, surgery_mincut_widen.cpp); 0: the surface was not moved
  int left_caps_ahead = 0;  // left-ring restricted triangulations taken from the helper thread's (run_both)
  SurgeryUndo undo;
};

// Preconditions (checked, PreconditionError otherwise): `loop` is a simple cycle of >= 3
// vertices, consecutive vertices share an edge, and no loop vertex lies on the boundary.
// When `homology` is given, new edges get classes consistent with it modulo the loop's class.
SurgeryResult cut_and_cap(Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop, const SurgeryOptions& opts,
                          HomologyBasis* homology = nullptr);

// Puts the mesh back as it was before the cut_and_cap() that returned `undo`, which must be the
// last change to the mesh. A FaceGrid guard that saw the surgery holds stale faces afterwards:
// rebuild it. Edge classes set by the surgery are left (those ids are reused by the next one).
void undo_surgery(Mesh& mesh, const SurgeryUndo& undo);

// True when a and b are connected in the mesh graph (bidirectional breadth-first search, which
// stops early when both sides meet: cheap for the small handles of denoising).
bool vertices_connected(const Mesh& mesh, Mesh::VertexHandle a, Mesh::VertexHandle b);

}  // namespace cf
