#pragma once
// A disk-shaped patch (hidden_patches.h) opened along a slit into an annulus before it is flattened
// (flatten, internal; issue 26, docs/history/flatten.md session 31 "grown").
//
// A disk is flattened as a band from its rim to a hole: a side branch's pouch opens a cap of <= 5 mm
// at its tip (the point farthest from the rim) and counts it as wall not shown. The wall a band hides
// is mostly a strip (along a cut-off branch's rim, between two rims), not a pouch: from one tip the
// harmonic u of a strip falls off exponentially along it, and the strip's far parts are crushed
// (a 33 532-face patch of the grown CT-mask row: over half of its faces at area ratio 0.000). Here
// the disk is instead cut open along its ridge: the shortest path, through the vertices at least
// kSlitRidge of the largest distance from the rim, between the two ridge vertices farthest apart.
// Its inner vertices are doubled (one copy for the faces on either side), so the slit becomes the
// annulus' second boundary loop, and u runs from the rim across the strip to its middle line along
// its whole length. The slit's two ends are rounded (session 32 "grown"): the faces around each end
// vertex are dropped (wall not shown, a few mm^2), since a slit's end is a corner of angle 2 pi that
// the map opens to pi (on the grown real mask a 987-face slit patch had qc mean 1.0e5, 314 with its
// ends rounded: docs/history/flatten.md session 32). A slit, rounded or not, is only cut where the
// band's boundary clean-up leaves an annulus: a slit one face from the rim is unzipped into it
// (faces with three corners on the boundary dropped one after the other), the band is no tube, and
// the whole patch was lost.
#include "flatten_internal.h"

namespace cf::flat_detail {

// Ridge vertices: those at least this fraction of the largest distance (along edges) from the rim.
constexpr double kSlitRidge = 0.5;

// `disk` (one boundary loop, Euler characteristic 1) cut open along its ridge: an annulus (two
// loops, Euler characteristic 0) with the disk's faces in their order less the faces around the
// slit's two end vertices (kept where the rounded slit would not stay an annulus), the slit's inner
// vertices copied (same position and src) for the faces on the slit's right side, vertices without
// a face dropped. Empty (no faces) when no slit of at least two edges
// exists or the cut is not an annulus that stays one after the clean-up (clean_face_set).
Surface slit_disk(const Surface& disk);

}  // namespace cf::flat_detail
