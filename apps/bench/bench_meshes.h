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

// A ball of radius `radius` mm pierced by a straight strand of radius `strand_radius` mm along a
// chord (the lumen with a tissue bridge across it): genus 1, the strand a tunnel through the
// ball. Flying edges at `voxel` mm.
Mesh sphere_with_strand(double radius, double strand_radius, double voxel);

}  // namespace cf::bench
