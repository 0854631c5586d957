#pragma once
// A triangulated disk with interior vertices spanning a closed 3D polygon: the geometry of the
// sheet caps of surgery (surgery_caps.cpp, step 7b; docs/denoise.md "Surgery geometry").
#include <array>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

struct SpanningDisk {
  std::vector<Vec3> points;                   // points[0..ring size) = the ring, then interior vertices
  std::vector<std::array<int, 3>> triangles;  // oriented like the ring; listed so that each one shares an
                                              // edge with the ring or an earlier one (ready for add_face)
  std::vector<Vec3> normals;                  // unit vertex normals (area-weighted), one per point
};

// Liepa-style hole filling: the minimum-area triangulation of `ring` (no interior vertex), every
// chord between two ring vertices split (so no cap edge can duplicate a mesh edge), interior edges
// split until none is longer than 4/3 `edge`, Delaunay edge flips, and the interior vertices
// relaxed by umbrella (uniform Laplacian) steps with the ring fixed, which moves them towards a
// discrete minimal surface. Empty when the ring has fewer than 3 points or no triangulation.
SpanningDisk spanning_disk(const std::vector<Vec3>& ring, double edge);

}  // namespace cf
