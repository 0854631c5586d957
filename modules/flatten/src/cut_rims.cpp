// The rims of cut-off branches on a band's flat map: found, judged, and checked for crossings
// (cut_rims.h).
#include "cut_rims.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "colonflat/core/union_find.h"

namespace cf::flat_detail {

namespace {

struct RimSegment {  // a rim edge in the map: its vertices and corners (in its face's frame)
  int a, b;
  V2 p, q;
};
std::vector<RimSegment> rim_segments(const SegmentWork& w, const CutRims& rims) {
  std::vector<RimSegment> seg;
  for (const auto& [f, k] : rims.edges) {
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

// (cut_rims) Chains of edges (i: the half-edge a -> b of rims.edges[i]), each followed from its
// first edge in edge order to the edge leaving its last head, until it closes or ends.
void chain_rims(const Surface& s, CutRims& rims) {
  std::unordered_map<int, std::size_t> from;  // the rim edge leaving each rim vertex
  const auto head = [&](std::size_t i) { return s.t[std::size_t(rims.edges[i][0])][rims.edges[i][1]]; };
  const auto tail = [&](std::size_t i) { return s.t[std::size_t(rims.edges[i][0])][(rims.edges[i][1] + 1) % 3]; };
  for (std::size_t i = 0; i < rims.edges.size(); ++i) from[head(i)] = i;
  const std::size_t none = rims.edges.size();
  rims.loop_of.assign(rims.edges.size(), none);
  for (std::size_t i = 0; i < rims.edges.size(); ++i) {
    if (rims.loop_of[i] != none) continue;
    std::vector<std::size_t>& loop = rims.loops.emplace_back();
    for (std::size_t k = i; rims.loop_of[k] == none;) {
      rims.loop_of[k] = rims.loops.size() - 1, loop.push_back(k);
      const auto next = from.find(tail(k));
      if (next == from.end()) break;
      k = next->second;
    }
  }
}

// (free_rims) the share of a rim's faces crushed, how round its hole, how much room.
constexpr double kRoundHole = 0.8, kCrushedRim = 0.5, kHoleRoom = 0.25;

}  // namespace

CutRims cut_rims(const Surface& s, const Edges& E, const std::vector<char>& ends) {
  CutRims rims;
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int a = E.ev[e][0], b = E.ev[e][1], f = E.ef[e][0];
    if (E.ef[e][1] >= 0 || (ends[std::size_t(a)] && ends[std::size_t(b)])) continue;
    const Tri& t = s.t[std::size_t(f)];
    for (int k = 0; k < 3; ++k)
      if ((t[k] == a || t[k] == b) && (t[(k + 1) % 3] == a || t[(k + 1) % 3] == b)) rims.edges.push_back({f, k});
  }
  std::sort(rims.edges.begin(), rims.edges.end());
  chain_rims(s, rims);
  return rims;
}

// Per rim vertex (the head of each rim edge), the angles of its faces at it summed in the map: above
// one turn, its fan of faces overlaps itself (the rim folded over at that vertex: its two sides
// swapped there, which no pair of rim edges shows, as they share the vertex).
std::vector<double> rim_fan_angles(const SegmentWork& w, const CutRims& rims) {
  std::vector<char> on_rim(w.ann.p.size(), 0);
  for (const auto& [f, k] : rims.edges) on_rim[std::size_t(w.ann.t[std::size_t(f)][k])] = 1;
  std::vector<double> angle(w.ann.p.size(), 0.0);
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
    const Tri& t = w.ann.t[f];
    if (!on_rim[std::size_t(t[0])] && !on_rim[std::size_t(t[1])] && !on_rim[std::size_t(t[2])]) continue;
    const auto c = w.emb.corners(w.ann, int(f));
    for (int k = 0; k < 3; ++k) {
      const V2 a = c[(k + 1) % 3] - c[k], b = c[(k + 2) % 3] - c[k];
      if (on_rim[std::size_t(t[k])]) angle[std::size_t(t[k])] += std::atan2(std::abs(a.x() * b.y() - a.y() * b.x()), a.dot(b));
    }
  }
  std::vector<double> out;
  for (const auto& [f, k] : rims.edges) out.push_back(angle[std::size_t(w.ann.t[std::size_t(f)][k])]);
  return out;
}

std::vector<std::size_t> rim_crossings(const SegmentWork& w, const CutRims& rims) {
  const std::vector<RimSegment> seg = rim_segments(w, rims);
  const std::vector<double> fan = rim_fan_angles(w, rims);
  const auto side = [](const V2& a, const V2& b, const V2& c) {
    const double x = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    return (x > 0) - (x < 0); };
  std::vector<std::size_t> n(rims.loops.size(), 0);
  for (std::size_t i = 0; i < seg.size(); ++i) n[rims.loop_of[i]] += fan[i] > 2 * M_PI * (1 + 1e-9);
  for (std::size_t i = 0; i < seg.size(); ++i)
    for (std::size_t j = i + 1; j < seg.size(); ++j) {
      const RimSegment& s = seg[i];
      if (s.a == seg[j].a || s.a == seg[j].b || s.b == seg[j].a || s.b == seg[j].b) continue;
      const RimSegment t = nearest_copy(s, seg[j], w.emb.period);
      if (side(s.p, s.q, t.p) * side(s.p, s.q, t.q) < 0 && side(t.p, t.q, s.p) * side(t.p, t.q, s.q) < 0) {
        ++n[rims.loop_of[i]];
        if (rims.loop_of[j] != rims.loop_of[i]) ++n[rims.loop_of[j]];
      }
    }
  return n;
}

// (cut_rims.h) The constants, measured: freed without them, on the colon-like U (contact 60 mm) a
// 43 x 15 mm hole (0.68 round) had its tip dragged 4 mm along it and crossed its other side, and on
// the real CT colon band small crushed holes (map area 0.05-0.12 of their 3D circle's) crossed 22
// times (the passes then ran twice). The U's rim that keeps a strip crushed: 0.98 round, room 0.31.
// kHoleRoom 0.15 (session 26, with a crossing rim held alone and folds at a rim vertex counted):
// U120's small hole (40 edges, room 0.157) then folds over at a vertex (its strip opened only so:
// session 25's p05 0.209 was that fold) and U180's two rims at 0.17 / 0.19 cross: both restored,
// nothing gained, 77 k / 13 k vertices corrected twice.
std::vector<char> free_rims(const SegmentWork& w, const CutRims& rims, const FlattenOptions& o) {
  const double min_ratio = o.coverage_min_ratio;
  const double scale = band_area_scale(w, nullptr);  // every face, degenerate ones too
  const auto seg = rim_segments(w, rims);
  std::vector<char> freed(rims.loops.size(), 0);
  for (std::size_t r = 0; r < rims.loops.size(); ++r) {
    const std::vector<std::size_t>& loop = rims.loops[r];
    double area = 0, length = 0, length3 = 0;  // shoelace over the edges (either orientation); 3D length
    const RimSegment first = seg[loop.front()];
    RimSegment last = first;
    for (std::size_t k : loop) {
      const RimSegment e = k == loop.front() ? first : nearest_copy(last, seg[k], w.emb.period);  // placed after the last
      area += 0.5 * (e.p.x() * e.q.y() - e.q.x() * e.p.y()), length += (e.q - e.p).norm();
      length3 += (w.ann.p[seg[k].a] - w.ann.p[seg[k].b]).norm();
      last = e;
    }
    const bool wraps = (last.q - first.p).norm() > 0.5 * w.emb.period;  // around the band
    const auto crushed = std::count_if(loop.begin(), loop.end(), [&](std::size_t k) {
      return scale * w.emb.area2(w.ann, rims.edges[k][0]) < min_ratio * face_area_3d(w.ann, rims.edges[k][0]); });
    const double roundness = std::abs(area) / (length * length / (4 * M_PI)), room = std::abs(area) / (length3 * length3 / (4 * M_PI));
    freed[r] = roundness >= kRoundHole && !wraps && room >= kHoleRoom && double(crushed) >= kCrushedRim * double(loop.size());
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug rim %zu: %zu edges, %.0f mm in 3D, crushed %.2f, round %.2f%s, room %.3f: %s\n", r,
                   loop.size(), length3, double(crushed) / double(loop.size()), roundness, wraps ? " (around the band)" : "",
                   room, freed[r] ? "freed" : "held");
  }
  return freed;
}

std::vector<char> held_vertices(const SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                const std::vector<char>& ends) {
  std::vector<char> held = ends;
  for (std::size_t r = 0; r < rims.loops.size(); ++r)
    if (!freed[r])
      for (std::size_t k : rims.loops[r]) {
        const auto& [f, c] = rims.edges[k];
        held[std::size_t(w.ann.t[std::size_t(f)][c])] = held[std::size_t(w.ann.t[std::size_t(f)][(c + 1) % 3])] = 1;
      }
  return held;
}

std::size_t restore_touched_pieces(SegmentWork& w, const std::vector<V2>& before, const std::vector<char>& touched,
                                   std::vector<char>& kept) {
  const std::vector<V2>& pos = w.emb.pos;
  UnionFind pieces(pos.size());
  for (const Tri& t : w.ann.t)
    if (pos[t[0]] != before[t[0]] || pos[t[1]] != before[t[1]] || pos[t[2]] != before[t[2]])
      pieces.unite(std::uint32_t(t[0]), std::uint32_t(t[1])), pieces.unite(std::uint32_t(t[0]), std::uint32_t(t[2]));
  std::vector<char> restore(pos.size(), 0);  // per piece root
  for (std::size_t v = 0; v < pos.size(); ++v)
    if (touched[v]) restore[pieces.find(std::uint32_t(v))] = 1;
  std::size_t back = 0;
  for (std::size_t v = 0; v < pos.size(); ++v) {
    if (pos[v] == before[v]) continue;
    if (restore[pieces.find(std::uint32_t(v))]) w.emb.pos[v] = before[v], ++back;
    else kept[v] = 1;
  }
  return back;
}

}  // namespace cf::flat_detail
