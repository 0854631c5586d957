// Layout of the flattened segments and the output FlatMap.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <unordered_map>

#include "colonflat/core/run_stats.h"
#include "flatten_internal.h"

namespace cf::flat_detail {
namespace {

void reverse_segment(SegmentWork& w) {
  const double L = w.seg.length, P = w.seg.period, C = w.seg.centreline_length;
  for (auto& q : w.emb.pos) q = V2(L - q.x(), P - q.y());
  for (auto& d : w.emb.dy)
    for (double& x : d) x = -x;
  for (double& a : w.along) a = C - a;
  std::reverse(w.seg.centreline.begin(), w.seg.centreline.end());
  for (auto& q : w.seg.centreline_x) q = {C - q[0], L - q[1]};
  std::reverse(w.seg.centreline_x.begin(), w.seg.centreline_x.end());
}

// The flat vertex id of each (annulus vertex, sheet) pair met so far, keyed as
// v * 64 + (sheet + 32) (a sheet: how many periods a face's corner lies above its vertex). A
// vertex's first key lives in two arrays, a second one (a vertex on the period's seam: two sheets)
// in a hash map: the same ids as one hash map of every key (which, on the real CT's 1.06 M flat
// vertices, made emitting take 0.40 s against 0.23 s now).
class SheetIds {
 public:
  explicit SheetIds(std::size_t vertices) : id_(vertices, -1), low_(vertices, 0) {}
  // The id of `key`, or -1 when it is new (then `set` it).
  int& of(long long key) {
    const long long v = key >> 6;  // key = v * 64 + low, low in [0, 64): (v, low) <-> key
    const auto low = std::uint8_t(key & 63);
    if (v >= 0 && v < (long long)id_.size()) {
      int& id = id_[std::size_t(v)];
      if (id < 0) low_[std::size_t(v)] = low;
      if (id < 0 || low_[std::size_t(v)] == low) return id;
    }
    return more_.try_emplace(key, -1).first->second;
  }

 private:
  std::vector<int> id_;
  std::vector<std::uint8_t> low_;
  std::unordered_map<long long, int> more_;
};

void emit_one(const SegmentWork& w, FlatMap& out) {
  const Surface& ann = w.ann;
  const FlatSegment& seg = w.seg;
  std::vector<V3> nrm(ann.p.size(), V3::Zero());
  for (const Tri& t : ann.t) {
    const V3 n = (ann.p[t[1]] - ann.p[t[0]]).cross(ann.p[t[2]] - ann.p[t[0]]);
    for (int v : t) nrm[v] += n;
  }
  SheetIds vid(ann.p.size());
  const double P = seg.period;
  for (std::size_t f = 0; f < ann.t.size(); ++f) {
    if (!w.in_map[f]) continue;
    const auto c = w.emb.corners(ann, int(f));
    Tri ot;
    for (int k = 0; k < 3; ++k) {
      const int v = ann.t[f][k];
      const long long sheet = std::llround(w.emb.dy[f][k] / P);
      int& id = vid.of((long long)v * 64 + (sheet + 32));
      if (id < 0) {
        id = int(out.uv.size());
        out.uv.push_back({seg.x0 + c[k].x(), seg.y0 + c[k].y()});
        out.position.push_back({ann.p[v].x(), ann.p[v].y(), ann.p[v].z()});
        const V3 n = (w.lumen_sign * nrm[v]).normalized();
        out.normal.push_back({n.x(), n.y(), n.z()});
        out.segment.push_back(seg.id);
        out.source_vertex.push_back(ann.src[v]);
        out.centreline_mm.push_back(w.along[v]);
        const double a = std::fmod(c[k].y() / P, 1.0);
        out.angle_rad.push_back(2 * M_PI * (a < 0 ? a + 1 : a >= 1 ? 0 : a));
      }
      ot[k] = id;
    }
    out.triangles.push_back(ot);
  }
}

Coverage total_coverage(const std::vector<FlatSegment>& segs) {
  Coverage c;
  for (const auto& s : segs) {
    c.wall_area_mm2 += s.coverage.wall_area_mm2;
    c.shown_area_mm2 += s.coverage.shown_area_mm2;
    c.compressed_area_mm2 += s.coverage.compressed_area_mm2;
    c.missing_area_mm2 += s.coverage.missing_area_mm2;
    c.end_cap_area_mm2 += s.coverage.end_cap_area_mm2;
    c.not_shown.insert(c.not_shown.end(), s.coverage.not_shown.begin(), s.coverage.not_shown.end());
  }
  c.fraction = c.wall_area_mm2 > 0 ? c.shown_area_mm2 / c.wall_area_mm2 : 1.0;
  std::sort(c.not_shown.begin(), c.not_shown.end(), [](const auto& a, const auto& b) { return a.area_mm2 > b.area_mm2; });
  if (c.not_shown.size() > 20) c.not_shown.resize(20);
  return c;
}

}  // namespace

// Labels and orders the colon segments (rectum -> cecum); side branches follow, by the order of
// their parent and their neck's position on it, labelled "neck" -> "tip" ("rim" -> "tip" for a patch).
std::vector<char> label_and_order(std::vector<SegmentWork>& work, double midline_x) {
  std::vector<int> colon;
  std::vector<FlatSegment> segs;
  for (std::size_t i = 0; i < work.size(); ++i)
    if (work[i].parent < 0) colon.push_back(int(i)), segs.push_back(work[i].seg);
  std::vector<char> rev_colon, reversed(work.size(), 0);
  label_ends(segs, midline_x, rev_colon);
  for (std::size_t k = 0; k < colon.size(); ++k) work[colon[k]].seg = segs[k], reversed[colon[k]] = rev_colon[k];
  auto root_order = [&](int i) {
    while (work[i].parent >= 0) i = work[i].parent;
    return work[i].seg.order;
  };
  std::vector<int> branch;
  for (std::size_t i = 0; i < work.size(); ++i) {
    SegmentWork& b = work[i];
    if (b.parent < 0) continue;
    const SegmentWork& parent = work[b.parent];
    if (reversed[b.parent]) b.seg.attach_mm = parent.seg.centreline_length - b.seg.attach_mm;
    b.seg.kind = "branch";
    b.seg.x0_end = b.seg.holds == "wall" ? "rim" : "neck";  // a patch's x0 end is the rim it was cut along
    b.seg.x1_end = "tip";
    if (b.seg.map == "disk") b.seg.x0_end = b.seg.x1_end = "rim";  // a disk band: x between two rim points
    branch.push_back(int(i));
  }
  std::stable_sort(branch.begin(), branch.end(), [&](int a, int b) {
    return std::make_pair(root_order(a), work[a].seg.attach_mm) < std::make_pair(root_order(b), work[b].seg.attach_mm);
  });
  for (std::size_t k = 0; k < branch.size(); ++k) work[branch[k]].seg.order = int(colon.size() + k);
  return reversed;
}

void emit_segments(std::vector<SegmentWork>& work, const std::vector<char>& reversed, const FlattenOptions& o,
                   FlatMap& out) {
  std::vector<int> order(work.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return work[a].seg.order < work[b].seg.order; });
  std::vector<int> id_of_work(work.size());
  for (std::size_t k = 0; k < order.size(); ++k) id_of_work[order[k]] = int(k);
  double y_cursor = 0;
  double seconds[3] = {0, 0, 0};  // normalise, emit, statistics (COLONFLAT_FLATTEN_DEBUG)
  Stopwatch lap;
  for (std::size_t k = 0; k < order.size(); ++k) {
    SegmentWork& w = work[order[k]];
    if (reversed[order[k]]) reverse_segment(w);
    normalise_corner_offsets(w.ann, w.emb);
    seconds[0] += lap.lap();
    w.seg.id = int(k);
    w.seg.order = int(k);
    w.seg.parent = w.parent >= 0 ? id_of_work[w.parent] : -1;
    w.seg.x0 = 0;
    w.seg.y0 = y_cursor;
    y_cursor += w.seg.period + o.segment_gap;
    emit_one(w, out);
    out.segments.push_back(w.seg);
    seconds[1] += lap.lap();
  }
  out.stats = distortion_stats(out);
  out.coverage = total_coverage(out.segments);
  seconds[2] = lap.lap();
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug layout: %zu flat vertices, wall s: offsets normalised %.3f, emitted %.3f, statistics %.3f\n",
                 out.uv.size(), seconds[0], seconds[1], seconds[2]);
}

}  // namespace cf::flat_detail
