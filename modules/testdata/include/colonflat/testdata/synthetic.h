#pragma once
// Synthetic meshes of known topology, for tests and benchmarks (test-support library
// colonflat_testdata: linked by every test and bench, never by the colonflat binary). All closed
// surfaces are consistently oriented with outward normals.
#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"

namespace cf::synthetic {

// UV sphere of radius r: nu >= 3 around, nv >= 2 bands pole to pole. Genus 0, closed.
TriangleList sphere(double r, int nu, int nv);
// Torus with axis z: major radius R, minor radius r, nu x nv quads. Genus 1, closed.
TriangleList torus(double R, double r, int nu, int nv);
// Flat disk of radius r in the xy plane: rings x sectors. Genus 0, one boundary loop.
TriangleList disk(double r, int rings, int sectors);
// Open cylinder (tube) of radius r, height h along z. Genus 0, two boundary loops.
TriangleList open_cylinder(double r, double h, int nu, int nv);
// g tori in a row along x (centres g*spacing apart), each joined to the next by a straight
// square tube through a hole of one grid quad on each outer equator. Genus g, closed, embedded
// for spacing > 2(R + r). The neck loops around the tubes are separating.
TriangleList torus_chain(int g, double R, double r, int nu, int nv, double spacing);
// Disjoint union (vertex ids of b shifted).
TriangleList disjoint_union(const TriangleList& a, const TriangleList& b);
// Translate every point.
TriangleList translated(TriangleList m, double dx, double dy, double dz);
// A consistently oriented OpenMesh mesh of a valid manifold triangle list.
Mesh to_mesh(const TriangleList& t);

}  // namespace cf::synthetic
