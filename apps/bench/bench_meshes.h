#pragma once
// Large synthetic surfaces for the benchmark apps.
#include <cstddef>

#include "colonflat/core/mesh.h"

namespace cf::bench {

// A sphere of radius `radius` mm with `handles` small tori (ring radius 3 mm, tube 1 mm) half
// sunk into its surface, each adding one handle, extracted with VTK flying edges at voxel size
// `voxel` mm (faces ~ 7e5 * (radius / 100)^2 / (voxel / 0.42)^2). Genus = handles (checked by
// the caller). Deterministic for a seed.
Mesh sphere_with_handles(double radius, int handles, double voxel, unsigned seed = 1);

}  // namespace cf::bench
