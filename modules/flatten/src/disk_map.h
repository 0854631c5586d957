#pragma once
// A free-boundary map of a disk-shaped piece (a patch of hidden wall, a pouch cut at its neck) as one
// band (flatten, internal; issue 26, docs/history/flatten.md session 33 "patchmap").
//
// A disk is flattened today as a tube, from its rim to a tip cap or a slit: a harmonic map from one
// boundary to another shrinks a long or branched disk exponentially away from the rim. Here the disk
// itself is mapped, with no cap removed: the least squares conformal map (LSCM: Levy et al. 2002;
// Desbrun et al. 2002: the cotangent Dirichlet energy of (x, y) minus the map's signed area, zero for
// a conformal map) with two boundary vertices far apart pinned, its boundary free; scaled so that its
// area is the wall's; then the area correction (whole band when its area ratios are out of bounds,
// then the local passes) and the balance, with one pinned vertex held and the boundary free. The map
// is kept only when it is injective: no face folded and its boundary a simple curve (a free boundary
// can overlap itself globally while every face is positive).
//
// The band: x and y are the disk map's own (mm, area-preserving), the band's rectangle the map's
// bounding box from (0, 0); x runs from the first pinned vertex (x ~ 0) towards the second one
// (docs/flatten.md "Disk bands"). The map does not wrap in y (every corner offset 0).
#include <vector>

#include "band_faces.h"
#include "flatten_internal.h"

namespace cf::flat_detail {

// Two boundary vertices of `s` far apart (3D): the boundary vertex farthest from the first vertex of
// the first boundary loop, and the one farthest from it. {-1, -1} when s has no boundary.
std::array<int, 2> far_boundary_pair(const Surface& s, const Edges& E);

// The LSCM positions (mm, not yet scaled) of s's vertices, `pins` at (0, 0) and (|p1 - p0|, 0);
// degenerate faces (`degenerate`) add no energy; `clamp`: each half cotangent weight clamped to
// [0.01, 100] (no negative weight: fewer folded faces on a real surface's obtuse triangles). Empty when
// the solve fails. Pre: s is a connected disk (one boundary loop), pins distinct boundary vertices.
std::vector<V2> lscm_positions(const Surface& s, const Edges& E, const std::vector<char>& degenerate,
                               const std::array<int, 2>& pins, bool clamp = false);

// True when the map `emb` of s has no face of negative area (degenerate faces aside) and its boundary
// edges cross nowhere but at shared vertices (a locally injective map of a disk with a simple boundary
// is injective).
bool injective_disk_map(const Surface& s, const Edges& E, const Embedding& emb, const std::vector<char>& degenerate);

// What disk_band did (COLONFLAT_FLATTEN_DEBUG prints it).
struct DiskMapResult {
  bool ok = false;            // the band holds an injective disk map
  const char* why = "";       // why not
  int corrected_iterations = 0;
  std::size_t balanced_vertices = 0;
};

// Maps band w (w.ann a disk; p: prepare_faces() of it, which set w.seg.area_3d; its `fixed` vertices,
// the rim, are held while the conformal map's folds are untangled) as above: sets w.emb (corner
// offsets 0, period = the box's height), w.along (= x, mm), w.seg.length and period (the box), map
// "disk" and its correction figures. On failure w.emb is unspecified.
DiskMapResult disk_band(SegmentWork& w, const Prepared& p, const FlattenOptions& o);

// A disk piece as one band: disk_band on `disk` (its faces prepared as a band's), measured; the band a
// branch's (`branch`, no branches or patches of its own). Empty when the map is refused
// (COLONFLAT_FLATTEN_DEBUG: a line saying why).
std::vector<SegmentWork> flatten_disk(const Surface& disk, int component, double lumen_sign, const FlattenOptions& o);

}  // namespace cf::flat_detail
