#pragma once
// Wall that a finished band's map still hides, cut out of the band as patches and flattened as bands
// of their own (flatten, internal; issue 26, docs/history/flatten.md session 30 "grown").
//
// A band (colon band, side branch or pouch) whose area-balanced map leaves more than
// kHiddenWallTolerance of its wall below the coverage ratio has its hidden clusters of at least
// `--branch-min-area` mm^2 (faces out of the map included), grown by kPatchRings vertex rings of shown
// wall and closed over enclosed islands, cut out. The band keeps its map (its other faces do not move:
// no re-solve); each patch (a disk, or an annulus where it holds one of the band's own boundary loops)
// is flattened like a side branch, recursively up to the branches' depth, and hangs from the band at
// its rim. Whatever the patch's own map shows of that wall is shown; nothing the band showed is lost
// except the ring faces, which the patch shows again.
#include <vector>

#include "branch_bands.h"

namespace cf::flat_detail {

// Vertex rings of the wall around a hidden cluster taken into its patch (the patch's rim then runs
// through wall the band showed, not along the crushed faces).
constexpr int kPatchRings = 3;

// The patches of band w (its annulus w.ann, map w.emb, edges E, vertex -> faces vf): per patch its
// faces of w.ann, ascending; none when the band hides at most kHiddenWallTolerance of its wall. A
// face is hidden as measure() counts it: not degenerate and out of the map, or shown below
// `min_ratio` at the band's area scale. Only clusters (edge-connected hidden faces) of at least
// `min_area_mm2` seed a patch; a patch that is neither a disk nor an annulus is dropped.
std::vector<std::vector<int>> hidden_patches(const SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                                             const std::vector<char>& degenerate, double min_ratio, double min_area_mm2);

// The patches cut out of a band: the pieces to flatten (surface, open ends, neck vertices in the band
// after the cut, rim length) and each old vertex's id in the band after the cut (-1: gone).
struct PatchCut {
  std::vector<BranchPiece> pieces;
  std::vector<int> new_of_old;
  double area_mm2 = 0;  // the pieces' wall, summed in piece order
};

// Cuts `patches` (from hidden_patches) out of w: w.ann, w.emb (positions and corner offsets), w.along,
// w.seg.area_3d, E and degenerate keep the other faces, whose map is unchanged. Empty patches: nothing.
PatchCut cut_patches(SegmentWork& w, Edges& E, std::vector<char>& degenerate, const std::vector<std::vector<int>>& patches);

// The direct branches' (parent -1) necks renumbered after patches were cut out of their band
// (`new_of_old`: cut_patches'; empty: nothing cut, nothing done), then the patches' works appended,
// their parents shifted to the joined list.
void join_patches(std::vector<SegmentWork>& branches, const std::vector<int>& new_of_old, std::vector<SegmentWork>& patches);

}  // namespace cf::flat_detail
