#pragma once
// The rims of cut-off branches on a band's flat map (band_axis.cpp's local passes): a cut branch
// leaves a hole in its band whose rim the whole-band map holds; where the conformal map made a
// limb-sized branch's round rim much shorter than in 3D, the strip of wall along it is crushed and
// only the rim moving opens it (issue 26, docs/flatten.md session 25).
#include <array>
#include <cstddef>
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// The edges of the band's boundary that lie on no end (the rims of cut-off branches), each as
// (face, corner k): the half-edge t[k] -> t[k + 1] of that face, whose reverse no face holds.
// `fixed`, `ends`: per vertex of s, on the boundary / on one of the band's two end loops.
// Order: face order, then k.
std::vector<std::array<int, 2>> rim_edges(const Surface& s, const std::vector<char>& fixed, const std::vector<char>& ends);

// Pairs of rim edges (rim_edges() of w.ann) that cross in the map w.emb (a rim folded over itself
// or another rim through the hole it bounds: a fold no face's orientation shows). Edges sharing a
// vertex are not judged; an edge is compared with the other's copy nearest it across the period.
std::size_t rim_crossings(const SegmentWork& w, const std::vector<std::array<int, 2>>& rims);

// The vertices held in the local passes (per vertex of w.ann): the band's `ends` and every rim but
// those that can open a crushed strip by moving into their hole: at least half of the rim's faces
// below `min_ratio` (area ratio at the band's area scale), a round hole (map area >= 0.8 x that of
// the circle of the rim's map length; not around the band) with room (map area >= 0.25 x that of
// the circle of the rim's 3D length).
std::vector<char> held_in_local_passes(const SegmentWork& w, const std::vector<std::array<int, 2>>& rims,
                                       const std::vector<char>& ends, double min_ratio);

}  // namespace cf::flat_detail
