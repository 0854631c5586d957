#pragma once
// The rims of cut-off branches on a band's flat map (band_axis.cpp's local passes): a cut branch
// leaves a hole in its band whose rim the whole-band map holds; where the conformal map made a
// limb-sized branch's round rim much shorter than in 3D, the strip of wall along it is crushed and
// only the rim moving opens it (issue 26, docs/flatten.md sessions 25 and 26).
#include <array>
#include <cstddef>
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// The band's boundary edges that lie on no end (the rims of cut-off branches) and the rims they
// form. Edge i is (face, corner k): the half-edge t[k] -> t[k + 1] of that face, whose reverse no
// face holds; edges in face order, then k. A rim is a chain of edges followed from head to tail
// (loops[r]: its edge indices in chain order; loop_of[i]: the rim of edge i).
struct CutRims {
  std::vector<std::array<int, 2>> edges;
  std::vector<std::vector<std::size_t>> loops;
  std::vector<std::size_t> loop_of;
};
// `E`: build_edges(s.t); `ends`: per vertex of s, on one of the band's two end loops.
CutRims cut_rims(const Surface& s, const Edges& E, const std::vector<char>& ends);

// Per rim (rims of w.ann): how many pairs of rim edges with an edge on it cross in the map w.emb (a
// rim folded over itself or another rim through the hole it bounds: a fold no face's orientation
// shows). A pair on one rim counts once for it, a pair across two rims once for each. Edges sharing
// a vertex are not judged; an edge is compared with the other's copy nearest it across the period.
std::vector<std::size_t> rim_crossings(const SegmentWork& w, const CutRims& rims);

// Per rim: free to move in the local passes (1) or held (0): a rim that can open a crushed strip by
// moving into its hole: at least half of the rim's faces below `min_ratio` (area ratio at the band's
// area scale), a round hole (map area >= 0.8 x that of the circle of the rim's map length; not
// around the band) with room (map area >= 0.25 x that of the circle of the rim's 3D length).
std::vector<char> free_rims(const SegmentWork& w, const CutRims& rims, double min_ratio);

// The vertices held in the local passes (per vertex of w.ann): `ends` and the rims not `freed`.
std::vector<char> held_vertices(const SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                const std::vector<char>& ends);

// The local area correction passes of area_balanced_step (band_axis.cpp: pockets, then grown
// pockets) on a band whose boundary vertices are `fixed` (per vertex), `ends` (per vertex) those on
// its two end loops, `E` its edges: the ends stay; a rim of a cut-off branch moves where
// free_rims() lets it; if that made a rim cross itself or another, the passes are done again with
// every rim held. Post: positive faces stay so.
void local_area_passes(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                       const std::vector<char>& fixed, const std::vector<char>& ends,
                       const std::vector<char>& degenerate, const FlattenOptions& o, bool branch);

}  // namespace cf::flat_detail
