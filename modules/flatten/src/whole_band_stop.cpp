// The faces the whole-band area pass holds (see whole_band_stop.h).
#include "whole_band_stop.h"

#include <algorithm>

#include "face_blocks.h"

namespace cf::flat_detail {

double band_areas(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate, std::vector<double>& area3,
                  std::vector<double>& area2) {
  area3.resize(s.t.size()), area2.resize(s.t.size());
  for_each_block(s.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) area3[f] = face_area_3d(s, int(f)), area2[f] = emb.area2(s, int(f));
  });
  double a2 = 0, a3 = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f]) a2 += std::max(area2[f], 0.0), a3 += area3[f];
  return a2 > 0 ? a3 / a2 : 1.0;
}

std::vector<char> whole_band_held(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate,
                                  double below) {
  std::vector<double> area3, area2;
  const double scale = band_areas(s, emb, degenerate, area3, area2);
  std::vector<char> held(s.p.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && area2[f] > 0 && crushed_in_band(scale, area2[f], area3[f], below))
      for (int v : s.t[f]) held[v] = 1;
  return held;
}

}  // namespace cf::flat_detail
