#pragma once
// Face sets grown by vertex rings (flatten, internal): the local area correction's regions and
// spots (area_correct.cpp) and the hidden patches (hidden_patches.cpp) grow theirs the same way.
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// Grows a face set by `rings` vertex rings (vf: vertex_faces). `ring` holds the set's newest faces;
// each step adds the faces that share a vertex with the previous step's and that `take(g)` accepts
// (take marks g as in the set). On return `ring` holds the last step's faces; `added` (optional)
// gets every added face in the order added.
template <class Take>
void grow_face_rings(const Surface& s, const std::vector<std::vector<int>>& vf, int rings, std::vector<int>& ring,
                     Take&& take, std::vector<int>* added = nullptr) {
  for (int k = 0; k < rings; ++k) {
    std::vector<int> next;
    for (int f : ring)
      for (int v : s.t[std::size_t(f)])
        for (int g : vf[std::size_t(v)])
          if (take(g)) next.push_back(g);
    if (added) added->insert(added->end(), next.begin(), next.end());
    ring.swap(next);
  }
}

}  // namespace cf::flat_detail
