// The rims of cut-off branches on a band's flat map: found, judged, and checked for crossings
// (cut_rims.h).
#include "cut_rims.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
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

// (free_rims, widen_short_rims) A rim's hole in the map, its edges chained across the period.
struct RimShape {
  double area = 0, length = 0, length3 = 0;  // map area (signed, shoelace), map and 3D lengths
  V2 centre = V2::Zero();                      // the hole's area centroid (in the first edge's copy)
  double reach = 0;                            // largest map distance of a rim vertex from centre
  bool wraps = false;                          // the rim runs around the band
};
RimShape rim_shape(const SegmentWork& w, const std::vector<RimSegment>& seg, const std::vector<std::size_t>& loop) {
  RimShape h;
  std::vector<V2> at;  // the rim's vertices, placed one after the other
  RimSegment last = seg[loop.front()];
  for (std::size_t k : loop) {
    const RimSegment e = k == loop.front() ? last : nearest_copy(last, seg[k], w.emb.period);  // placed after the last
    const double cross = e.p.x() * e.q.y() - e.q.x() * e.p.y();
    h.area += 0.5 * cross, h.length += (e.q - e.p).norm(), h.centre += cross * (e.p + e.q) / 6;
    h.length3 += (w.ann.p[seg[k].a] - w.ann.p[seg[k].b]).norm();
    at.push_back(e.p), last = e;
  }
  h.wraps = (last.q - seg[loop.front()].p).norm() > 0.5 * w.emb.period;  // around the band
  h.centre = h.area != 0 ? V2(h.centre / h.area) : at.front();
  for (const V2& p : at) h.reach = std::max(h.reach, (p - h.centre).norm());
  return h;
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
    const RimShape h = rim_shape(w, seg, loop);
    const auto crushed = std::count_if(loop.begin(), loop.end(), [&](std::size_t k) {
      return scale * w.emb.area2(w.ann, rims.edges[k][0]) < min_ratio * face_area_3d(w.ann, rims.edges[k][0]); });
    const double roundness = std::abs(h.area) / (h.length * h.length / (4 * M_PI));
    const double room = std::abs(h.area) / (h.length3 * h.length3 / (4 * M_PI));
    freed[r] = roundness >= kRoundHole && !h.wraps && room >= kHoleRoom && double(crushed) >= kCrushedRim * double(loop.size());
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug rim %zu: %zu edges, %.0f mm in 3D, crushed %.2f, round %.2f%s, room %.3f: %s\n", r,
                   loop.size(), h.length3, double(crushed) / double(loop.size()), roundness, h.wraps ? " (around the band)" : "",
                   room, freed[r] ? "freed" : "held");
  }
  return freed;
}

namespace {

// (widen_short_rims) Which rims, and how far the wall around them gives way: a rim at least
// kLongRim x the band's period long in 3D (the neck of a limb-sized branch) whose map length is
// below sqrt(area_ratio_low) x its 3D length; the rings around it measured kRingWidth mm wide (map),
// out to kReachOfPeriod x the period (and 1 mm short of the nearest end vertex); the rings beyond
// the collar give up area down to kFarRing x their own.
constexpr double kLongRim = 0.5, kRingWidth = 2.0, kReachOfPeriod = 0.45, kFarRing = 0.6;

// The radial plan about a rim's hole: the hole (radius <= r0) scaled by s; ring i (radii
// r[i]..r[i+1]) takes area factor J[i] (h^2 affine in r^2 there); beyond r.back(), the identity.
struct RadialPlan {
  V2 centre;
  double s = 1;
  std::vector<double> r, J;
};

// The map x -> c + (x - c) h(|x - c|) / |x - c| of `plan` (each vertex's copy nearest c across the
// period moved, so the map commutes with the period): h increases with r (every J > 0), so it is a
// homeomorphism of the band when r.back() < half the period.
void apply_plan(Embedding& emb, const RadialPlan& plan) {
  const double r0 = plan.r.front(), r1 = plan.r.back();
  for (V2& p : emb.pos) {
    const double shift = emb.period * std::round((p.y() - plan.centre.y()) / emb.period);
    const V2 d = unshifted_corner(p, shift) - plan.centre;  // p - (0, shift) (shifted_corner.h: same bits)
    const double r = d.norm();
    if (!(r < r1)) continue;
    double h2 = plan.s * plan.s * std::min(r, r0) * std::min(r, r0);
    for (std::size_t i = 0; i + 1 < plan.r.size() && r > plan.r[i]; ++i)
      h2 += plan.J[i] * (std::min(r, plan.r[i + 1]) * std::min(r, plan.r[i + 1]) - plan.r[i] * plan.r[i]);
    p = shifted_corner(plan.centre, shift) + d * (r > 0 ? std::sqrt(h2) / r : plan.s);
  }
}

// Per ring of `plan.r` (by face centroid, nearest copy across the period): the wall's mean area
// ratio at the band's area scale (+infinity for a ring holding no wall).
std::vector<double> ring_ratios(const SegmentWork& w, const RadialPlan& plan, double scale) {
  const std::size_t n = plan.r.size() - 1;
  std::vector<double> a2(n, 0.0), a3(n, 0.0), q(n);
  const double width = (plan.r.back() - plan.r.front()) / double(n);
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
    const auto c = w.emb.corners(w.ann, int(f));
    V2 m = (c[0] + c[1] + c[2]) / 3 - plan.centre;
    m.y() -= w.emb.period * std::round(m.y() / w.emb.period);
    const double i = std::floor((m.norm() - plan.r.front()) / width);
    if (i < 0 || i >= double(n)) continue;
    a2[std::size_t(i)] += std::max(w.emb.area2(w.ann, int(f)), 0.0), a3[std::size_t(i)] += face_area_3d(w.ann, int(f));
  }
  for (std::size_t i = 0; i < n; ++i) q[i] = a2[i] > 0 ? scale * a2[i] / a3[i] : std::numeric_limits<double>::infinity();
  return q;
}

// The rings' factors for the collar's target ratio t: J[i] = max(kappa, t / q[i]) (a ring below t
// brought to t, the others giving up area, none below kappa x its own) with kappa such that the
// disc keeps its area (the hole's growth and the collar's paid by the far rings). False when that
// needs kappa below kFarRing.
bool fit_rings(RadialPlan& plan, const std::vector<double>& q, double t) {
  const double r0 = plan.r.front(), r1 = plan.r.back();
  const double room = r1 * r1 - plan.s * plan.s * r0 * r0;
  const auto need = [&](double kappa) {
    double sum = 0;
    for (std::size_t i = 0; i < q.size(); ++i)
      sum += std::max(kappa, t / q[i]) * (plan.r[i + 1] * plan.r[i + 1] - plan.r[i] * plan.r[i]);
    return sum;
  };
  if (room <= 0 || need(kFarRing) > room) return false;
  double lo = kFarRing, hi = 1;
  while (need(hi) < room) hi *= 2;
  for (int k = 0; k < 60; ++k) (need(0.5 * (lo + hi)) < room ? lo : hi) = 0.5 * (lo + hi);
  plan.J.clear();
  for (double qi : q) plan.J.push_back(std::max(lo, t / qi));
  return true;
}

// How far the band reaches about `c` before an end vertex (or half the period).
double room_about(const SegmentWork& w, const V2& c, const std::vector<char>& ends) {
  double room = kReachOfPeriod * w.emb.period;
  for (std::size_t v = 0; v < ends.size(); ++v) {
    if (!ends[v]) continue;
    V2 d = w.emb.pos[v] - c;
    d.y() -= w.emb.period * std::round(d.y() / w.emb.period);
    room = std::min(room, d.norm() - 1.0);
  }
  return room;
}

std::size_t count_not_positive(const SegmentWork& w) {
  std::size_t n = 0;
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) n += w.emb.area2(w.ann, int(f)) <= 0;
  return n;
}

// One rim widened by its plan, unless a face would fold (then nothing moves); `scale`: the band's
// area scale (band_area_scale, every face). Returns whether it moved.
bool widen_rim(SegmentWork& w, const RimShape& h, double ratio, double scale, const std::vector<char>& ends,
               const FlattenOptions& o) {
  RadialPlan plan{h.centre, std::sqrt(o.area_ratio_low) / ratio, {}, {}};
  const double r1 = room_about(w, h.centre, ends);
  if (!(r1 > plan.s * h.reach)) return false;
  const std::size_t n = std::size_t(std::ceil((r1 - h.reach) / kRingWidth));
  for (std::size_t i = 0; i <= n; ++i) plan.r.push_back(h.reach + (r1 - h.reach) * double(i) / double(n));
  if (!fit_rings(plan, ring_ratios(w, plan, scale), o.area_ratio_low)) return false;
  const std::vector<V2> before = w.emb.pos;
  const std::size_t folded = count_not_positive(w);
  apply_plan(w.emb, plan);
  if (count_not_positive(w) <= folded) return true;
  w.emb.pos = before;
  return false;
}

}  // namespace

std::vector<char> widen_short_rims(SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                   const std::vector<char>& ends, const FlattenOptions& o) {
  std::vector<char> widened(rims.loops.size(), 0);
  // The rims' map segments and the band's area scale, measured again only after a rim moved the map.
  std::vector<RimSegment> seg = rim_segments(w, rims);
  double scale = band_area_scale(w, nullptr);
  for (std::size_t r = 0; r < rims.loops.size(); ++r) {
    if (freed[r]) continue;  // the passes move it
    const RimShape h = rim_shape(w, seg, rims.loops[r]);
    const double ratio = std::sqrt(scale) * h.length / h.length3;  // map / 3D length
    if (h.wraps || h.length3 < kLongRim * w.emb.period || ratio * ratio >= o.area_ratio_low) continue;
    widened[r] = widen_rim(w, h, ratio, scale, ends, o);
    if (widened[r]) seg = rim_segments(w, rims), scale = band_area_scale(w, nullptr);
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug rim %zu widened: %.0f mm in 3D, %.0f in the map (x %.3f), centre %.1f %.1f, reach %.1f mm: %s\n",
                   r, h.length3, h.length, std::sqrt(o.area_ratio_low) / ratio, h.centre.x(), h.centre.y(), h.reach,
                   widened[r] ? "widened" : "no room (or a face would fold): as it was");
  }
  return widened;
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
