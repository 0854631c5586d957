#pragma once
// What the flatten steps need of a band's faces, prepared once per band (flatten.cpp; the disk map too).
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// What every step on a band needs: its edges (w.ann's), degenerate faces (3D area at most 1e-6 of the mean),
// fixed (boundary) vertices (the ends and the rims of cut-off branches) and vertex -> faces.
struct Prepared {
  Edges E;
  std::vector<char> degenerate, fixed;
  std::vector<std::vector<int>> vf;
};
// Fills p's degenerate, fixed and vf from w.ann and p.E (its edges) and sets w.seg.area_3d (flatten.cpp).
void prepare_faces(SegmentWork& w, Prepared& p);

}  // namespace cf::flat_detail
