// The rims of cut-off branches on a band's flat map: found, judged, and checked for crossings
// (cut_rims.h).
#include "cut_rims.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace cf::flat_detail {

namespace {

struct RimSegment {  // a rim edge in the map: its vertices and corners (in its face's frame)
  int a, b;
  V2 p, q;
};
std::vector<RimSegment> rim_segments(const SegmentWork& w, const std::vector<std::array<int, 2>>& rims) {
  std::vector<RimSegment> seg;
  for (const auto& [f, k] : rims) {
    const auto c = w.emb.corners(w.ann, f);
    seg.push_back({w.ann.t[f][k], w.ann.t[f][(k + 1) % 3], c[k], c[(k + 1) % 3]});
  }
  return seg;
}

// `t` shifted by the period in y to lie nearest `s`.
RimSegment nearest_copy(const RimSegment& s, RimSegment t, double period) {
  const V2 shift(0, period > 0 ? period * std::round(((s.p + s.q) - (t.p + t.q)).y() / (2 * period)) : 0.0);
  t.p += shift, t.q += shift;
  return t;
}

// (held_in_local_passes) the share of a rim's faces crushed, how round its hole, how much room.
constexpr double kRoundHole = 0.8, kCrushedRim = 0.5, kHoleRoom = 0.25;
// The rims as loops of rim_segments() indices, each edge's copy placed next to the one before.
std::vector<std::pair<std::vector<std::size_t>, std::vector<RimSegment>>> rim_loops(const std::vector<RimSegment>& seg,
                                                                                          double period) {
  std::unordered_map<int, std::size_t> from;  // the rim edge leaving each rim vertex
  for (std::size_t i = 0; i < seg.size(); ++i) from[seg[i].a] = i;
  std::vector<char> seen(seg.size(), 0);
  std::vector<std::pair<std::vector<std::size_t>, std::vector<RimSegment>>> loops;
  for (std::size_t i = 0; i < seg.size(); ++i) {
    if (seen[i]) continue;
    auto& [loop, placed] = loops.emplace_back();
    for (std::size_t k = i; !seen[k];) {
      seen[k] = 1, loop.push_back(k);
      placed.push_back(placed.empty() ? seg[k] : nearest_copy(placed.back(), seg[k], period));
      const auto next = from.find(seg[k].b);
      if (next == from.end()) break;
      k = next->second;
    }
  }
  return loops;
}

}  // namespace

std::vector<std::array<int, 2>> rim_edges(const Surface& s, const std::vector<char>& fixed,
                                                 const std::vector<char>& ends) {
  std::unordered_map<std::uint64_t, char> half;  // the half-edges between boundary vertices
  const auto key = [&](int a, int b) { return std::uint64_t(a) * s.p.size() + std::uint64_t(b); };
  for (const Tri& t : s.t)
    for (int k = 0; k < 3; ++k)
      if (fixed[t[k]] && fixed[t[(k + 1) % 3]]) half[key(t[k], t[(k + 1) % 3])] = 1;
  std::vector<std::array<int, 2>> out;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = s.t[f][k], b = s.t[f][(k + 1) % 3];
      if (fixed[a] && fixed[b] && !(ends[a] && ends[b]) && !half.count(key(b, a))) out.push_back({int(f), k});
    }
  return out;
}

std::size_t rim_crossings(const SegmentWork& w, const std::vector<std::array<int, 2>>& rims) {
  const std::vector<RimSegment> seg = rim_segments(w, rims);
  const auto side = [](const V2& a, const V2& b, const V2& c) {
    const double x = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    return (x > 0) - (x < 0); };
  std::size_t n = 0;
  for (std::size_t i = 0; i < seg.size(); ++i)
    for (std::size_t j = i + 1; j < seg.size(); ++j) {
      const RimSegment& s = seg[i];
      if (s.a == seg[j].a || s.a == seg[j].b || s.b == seg[j].a || s.b == seg[j].b) continue;
      const RimSegment t = nearest_copy(s, seg[j], w.emb.period);
      n += side(s.p, s.q, t.p) * side(s.p, s.q, t.q) < 0 && side(t.p, t.q, s.p) * side(t.p, t.q, s.q) < 0;
    }
  return n;
}

// (cut_rims.h) The constants, measured: freed without them, on the colon-like U (contact 60 mm) a
// 43 x 15 mm hole (0.68 round) had its tip dragged 4 mm along it and crossed its other side, and on
// the real CT colon band small crushed holes (map area 0.05-0.12 of their 3D circle's) crossed 22
// times (the passes then ran twice). The U's rim that keeps a strip crushed: 0.98 round, room 0.31.
std::vector<char> held_in_local_passes(const SegmentWork& w, const std::vector<std::array<int, 2>>& rims,
                                              const std::vector<char>& ends, double min_ratio) {
  double a2 = 0, a3 = 0;  // the band's area scale
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) a2 += std::max(w.emb.area2(w.ann, int(f)), 0.0), a3 += face_area_3d(w.ann, int(f));
  const double scale = a2 > 0 ? a3 / a2 : 1.0;
  std::vector<char> held = ends;
  const auto seg = rim_segments(w, rims);
  for (const auto& [loop, placed] : rim_loops(seg, w.emb.period)) {
    double area = 0, length = 0, length3 = 0;  // shoelace over the edges (either orientation); 3D length
    for (const RimSegment& e : placed) area += 0.5 * (e.p.x() * e.q.y() - e.q.x() * e.p.y()), length += (e.q - e.p).norm();
    for (std::size_t k : loop) length3 += (w.ann.p[seg[k].a] - w.ann.p[seg[k].b]).norm();
    const bool wraps = (placed.back().q - placed.front().p).norm() > 0.5 * w.emb.period;  // around the band
    const auto crushed = std::count_if(loop.begin(), loop.end(), [&](std::size_t k) {
      return scale * w.emb.area2(w.ann, rims[k][0]) < min_ratio * face_area_3d(w.ann, rims[k][0]); });
    const bool round = std::abs(area) >= kRoundHole * length * length / (4 * M_PI) && !wraps;
    const bool room = std::abs(area) >= kHoleRoom * length3 * length3 / (4 * M_PI);
    if (!round || !room || double(crushed) < kCrushedRim * double(loop.size()))
      for (std::size_t k : loop) held[std::size_t(seg[k].a)] = held[std::size_t(seg[k].b)] = 1;
  }
  return held;
}

}  // namespace cf::flat_detail
