#pragma once
// The faces a band keeps when its side branches are cut off, its end loops whole (branches.cpp).
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {
// The faces of s the band keeps once `cuts` are taken out (per face 1 = kept: the cuts' faces out,
// then clean_selection). Precondition: `loops` are the band's ends (vertices of s). Postcondition:
// every vertex of every loop is a corner of a kept face. A cut whose removal would take a loop
// vertex with it (its faces, or the clean-up beside them, reach the band's end: a notch in the end,
// not a side branch) is dropped from `cuts`, with every other cut of the removed region that
// reaches that vertex, and the faces are taken again; when no cut is left, `cuts` is empty and the
// returned faces are all 1.
std::vector<char> band_faces_after_cuts(const Surface& s, const Edges& E, const std::vector<std::vector<int>>& loops,
                                        std::vector<BranchCut>& cuts);

}  // namespace cf::flat_detail
