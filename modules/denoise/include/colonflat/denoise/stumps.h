#pragma once
// Stump removal. Cutting a thin strand (a tissue bridge across the colon lumen, a thin handle of
// any surface) leaves a finger on each side of the cut, ending in a cap; a conformal map crushes
// such fingers (flatten leaves their faces out). remove_stumps() removes each finger whole.
//
// From a cap's ring it grows the region of the surface within geodesic distance d (cap included)
// and follows the length of the region's boundary, the front. Along a finger the front stays
// about as long as the ring; at the finger's base it grows. The largest region before the front
// first gets longer than `growth` x the ring is removed, and its boundary (the base) is capped
// with a minimum-area triangulation that intersects nothing (cap_triangulation.h).
//
// A ring is left as it is when: no base within `max_length`; the base closer than half the
// ring's radius (no finger); the region is not a disk with one simple boundary, or touches the
// mesh boundary; the base cannot be capped without an intersection.
// Postconditions: topology unchanged (a disk replaced by a disk); closed, manifold, oriented as
// before. Vertex and face ids change (the mesh is garbage-collected).
#include <cstddef>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

struct StumpOptions {
  double max_length = 20;  // mm; longest finger removed (geodesic distance from its ring to its base)
  double growth = 1.5;     // the base is where the front first gets longer than growth x the ring
};

struct StumpRecord {
  std::size_t ring = 0;          // index into `rings`
  double length_mm = 0;          // geodesic distance from the ring to the base
  double ring_length_mm = 0;     // perimeter of the ring
  double base_length_mm = 0;     // perimeter of the base (the new cap's boundary)
  std::size_t faces_removed = 0;
  std::size_t cap_faces = 0;
};

// rings: ring vertices of caps in cyclic order (SurgeryResult::left_ring / right_ring); rings
// with a vertex removed by an earlier stump are skipped. Returns one record per removed stump.
std::vector<StumpRecord> remove_stumps(Mesh& mesh, const std::vector<std::vector<Mesh::VertexHandle>>& rings,
                                       const StumpOptions& options = {});

}  // namespace cf
