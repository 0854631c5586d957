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
// A rim vertex whose faces' angles at it sum above one turn (the rim folded over at that vertex)
// counts once for its rim.
std::vector<std::size_t> rim_crossings(const SegmentWork& w, const CutRims& rims);

// Per rim: free to move in the local passes (1) or held (0): a rim that can open a crushed strip by
// moving into its hole: at least half of the rim's faces below o.coverage_min_ratio (area ratio at
// the band's area scale), a round hole (map area >= 0.8 x that of the circle of the rim's map length;
// not around the band) with room (map area >= 0.25 x that of the circle of the rim's 3D length).
// COLONFLAT_FLATTEN_DEBUG=1: one line per rim with these figures.
std::vector<char> free_rims(const SegmentWork& w, const CutRims& rims, const FlattenOptions& o);

// Rims much shorter in the map than in 3D widened, each as one curve (issue 26, docs/flatten.md
// session 27 "rim"): the conformal map shrinks the wall beside a rim of map / 3D length l about
// isotropically by l, so that wall sits at area ratio ~ l^2 and no pass that holds the rim opens
// it. A rim at least 0.5 x the band's period long in 3D (a limb-sized branch's neck), not around the
// band, with l^2 < o.area_ratio_low: its hole scaled about its centroid by sqrt(area_ratio_low) / l
// (the rim's shape kept), the rings of wall around it (2 mm wide, out to 0.45 x the period or 1 mm
// short of an end) each given the area factor that brings its mean ratio up to area_ratio_low, paid
// by the rings above it (down to 0.6 x their area): a radial map increasing in the radius, so the
// band stays embedded and the rim cannot cross itself. Rims `freed` (free_rims(): the passes move
// them) are left alone; `ends`: per vertex of w.ann, on an end loop. Not done (the rim as it was)
// when the disc lacks the room or a face would fold. Returns per rim whether it was widened (then
// hold it).
std::vector<char> widen_short_rims(SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                   const std::vector<char>& ends, const FlattenOptions& o);

// The vertices held in the local passes (per vertex of w.ann): `ends` and the rims not `freed`.
std::vector<char> held_vertices(const SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                const std::vector<char>& ends);

// After passes that moved w.emb.pos from `before`: the moved vertices in pieces (the faces with a
// moved corner, joined through shared vertices). The pieces holding a vertex `touched` go back to
// `before` (each of their faces then is as before, so no face folds); the other moved vertices are
// marked in `kept`. Returns how many vertices went back.
std::size_t restore_touched_pieces(SegmentWork& w, const std::vector<V2>& before, const std::vector<char>& touched,
                                   std::vector<char>& kept);

// The local area correction passes of area_balanced_step (band_axis.cpp: pockets, then grown
// pockets) on a band whose boundary vertices are `fixed` (per vertex), `ends` (per vertex) those on
// its two end loops, `E` its edges: the ends stay; a rim of a cut-off branch moves where
// free_rims() lets it; a freed rim that crossed itself or another rim in the passes is held, the
// pieces it moved in are restored (restore_touched_pieces) and the passes run again with every
// vertex the other pieces moved held, until no freed rim adds a crossing. Post: positive faces stay
// so; no freed rim crosses more than before; the same map for any thread count. The rims are judged
// first; then the held ones widen_short_rims() widens (held still); the passes run when `pockets`
// (the band needs them) or a rim was widened.
void local_area_passes(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                       const std::vector<char>& fixed, const std::vector<char>& ends,
                       const std::vector<char>& degenerate, const FlattenOptions& o, bool branch, bool pockets);

// local_area_passes once its rims are found and judged: `freed` per rim (cut_rims(), free_rims()).
void local_passes_freeing(SegmentWork& w, const CutRims& rims, std::vector<char> freed,
                          const std::vector<std::vector<int>>& vf, const std::vector<char>& ends,
                          const std::vector<char>& degenerate, const FlattenOptions& o, bool branch);

}  // namespace cf::flat_detail
