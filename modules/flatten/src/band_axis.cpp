// The x axis of a segment's band and the area-balanced map built on it (see flatten.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>

#include <unordered_map>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/union_find.h"
#include "cut_rims.h"
#include "face_blocks.h"
#include "flatten_internal.h"
#include "whole_band_stop.h"

namespace cf::flat_detail {

std::vector<FaceDistortion> band_distortion(const SegmentWork& w, const std::vector<char>& degenerate,
                                            const std::vector<FaceFrame>* frames) {
  std::vector<FaceDistortion> fd;
  band_distortion(w, degenerate, frames, fd);
  return fd;
}

void band_distortion(const SegmentWork& w, const std::vector<char>& degenerate, const std::vector<FaceFrame>* frames,
                     std::vector<FaceDistortion>& fd) {
  fd.resize(w.ann.t.size());
  for_each_block(fd.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const Tri& t = w.ann.t[f];
      const auto c = w.emb.corners(w.ann, int(f));
      fd[f] = frames ? face_distortion((*frames)[f], c[0], c[1], c[2])
                     : face_distortion(w.ann.p[t[0]], w.ann.p[t[1]], w.ann.p[t[2]], c[0], c[1], c[2]);
      fd[f].degenerate = degenerate[f];
    }
  });
}

std::vector<FaceFrame> band_frames(const SegmentWork& w) {
  std::vector<FaceFrame> frames(w.ann.t.size());
  for_each_block(frames.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f) {
      const Tri& t = w.ann.t[f];
      frames[f] = face_frame(w.ann.p[t[0]], w.ann.p[t[1]], w.ann.p[t[2]]);
    }
  });
  return frames;
}

// COLONFLAT_FLATTEN_DEBUG=1: distortion after each step on stderr.
void debug_stats(const char* step, const SegmentWork& w, const std::vector<char>& degenerate) {
  if (!std::getenv("COLONFLAT_FLATTEN_DEBUG")) return;
  const std::vector<FaceDistortion> fd = band_distortion(w, degenerate);
  const DistortionStats st = stats_of(fd);
  std::size_t crowded = 0;
  for (const FaceDistortion& d : fd) crowded += !d.degenerate && too_small_in_map(d.area2, d.area3);
  std::fprintf(stderr, "flatten debug %s: crowded %zu, flipped %zu qc mean %.3f p95 %.3f max %.3g area p05 %.4f p50 %.3f p95 %.3f\n",
               step, crowded, st.flipped, st.qc_mean, st.qc_p95, st.qc_max, st.area_p05, st.area_median, st.area_p95);
}

double band_area_scale(const SegmentWork& w, const std::vector<char>* degenerate) {
  double a2 = 0, a3 = 0;
  for (std::size_t f = 0; f < w.ann.t.size(); ++f)
    if (!degenerate || !(*degenerate)[f]) a2 += std::max(w.emb.area2(w.ann, int(f)), 0.0), a3 += face_area_3d(w.ann, int(f));
  return a2 > 0 ? a3 / a2 : 1.0;
}

// COLONFLAT_FLATTEN_DEBUG=1: the faces shown below 0.1 (at the band's area scale) by decade of
// their area ratio, and their largest vertex-connected pockets (faces, mm2, smallest ratio, LPS,
// the band x they span, how many of their vertices are fixed: an end loop or a cut branch's rim).
void debug_pockets(const char* step, const SegmentWork& w, const std::vector<char>& degenerate,
                   const std::vector<char>& fixed) {
  if (!std::getenv("COLONFLAT_FLATTEN_DEBUG")) return;
  const Surface& s = w.ann;
  std::vector<double> ratio(s.t.size(), 1.0);
  const double scale = band_area_scale(w, &degenerate);
  UnionFind sets(s.p.size());
  std::array<double, 9> decade_area{};
  std::array<std::size_t, 9> decade_faces{};
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (degenerate[f]) continue;
    ratio[f] = scale * w.emb.area2(s, int(f)) / std::max(face_area_3d(s, int(f)), 1e-300);
    if (!(ratio[f] < 0.1)) continue;
    const int d = ratio[f] <= 0 ? 8 : std::clamp(int(-std::log10(ratio[f])), 1, 8);
    decade_area[d] += face_area_3d(s, int(f)), ++decade_faces[d];
    for (int k = 1; k < 3; ++k) sets.unite(std::uint32_t(s.t[f][0]), std::uint32_t(s.t[f][k]));
  }
  for (int d = 1; d <= 8; ++d)
    std::fprintf(stderr, "flatten debug pockets %s: ratio in [1e-%d, 1e-%d): %zu faces, %.0f mm2\n", step, d + 1, d,
                 decade_faces[d], decade_area[d]);
  struct Pocket {
    std::size_t faces = 0, below3 = 0, fixed = 0;
    double area = 0, min_ratio = 1, x0 = 1e300, x1 = -1e300, rim3 = 0, rim2 = 0;
    V3 c = V3::Zero();
  };
  std::unordered_map<std::uint32_t, Pocket> pockets;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (degenerate[f] || !(ratio[f] < 0.1)) continue;
    Pocket& p = pockets[sets.find(std::uint32_t(s.t[f][0]))];
    const double a = face_area_3d(s, int(f));
    ++p.faces, p.area += a, p.min_ratio = std::min(p.min_ratio, ratio[f]), p.below3 += ratio[f] < 1e-3;
    p.c += a * (s.p[s.t[f][0]] + s.p[s.t[f][1]] + s.p[s.t[f][2]]) / 3;
    const auto c = w.emb.corners(s, int(f));
    for (int k = 0; k < 3; ++k) {
      const int v = s.t[f][k], u = s.t[f][(k + 1) % 3];
      p.x0 = std::min(p.x0, w.emb.pos[v].x()), p.x1 = std::max(p.x1, w.emb.pos[v].x());
      p.fixed += fixed[v] != 0;  // counted once per face corner
      if (fixed[v] && fixed[u])  // an edge on the boundary: its 3D and 2D (area-preserving scale) lengths
        p.rim3 += (s.p[v] - s.p[u]).norm(), p.rim2 += std::sqrt(scale) * (c[k] - c[(k + 1) % 3]).norm();
    }
  }
  std::vector<Pocket> list;
  for (auto& [root, p] : pockets) list.push_back(p);
  std::sort(list.begin(), list.end(), [](const Pocket& a, const Pocket& b) { return a.area > b.area; });
  for (std::size_t i = 0; i < std::min<std::size_t>(list.size(), 25); ++i) {
    const Pocket& p = list[i];
    const V3 c = p.c / std::max(p.area, 1e-300);
    std::fprintf(stderr, "flatten debug pocket %s: %zu faces (%zu below 1e-3), %.1f mm2, min ratio %.2g, LPS %.1f %.1f %.1f, "
                 "x %.1f..%.1f, %zu fixed corners, boundary edges %.1f mm long in 3D, %.1f mm in the map\n",
                 step, p.faces, p.below3, p.area, p.min_ratio, c.x(), c.y(), c.z(), p.x0, p.x1, p.fixed, p.rim3, p.rim2);
  }
}


namespace {

// Bounds of the axis choice (targets: 0.2, 5): wide, because the area correction that follows
// brings the faces out of [area_ratio_low, area_ratio_high] back in; within them the axis that
// distorts angles least is taken.
constexpr double kAxisAreaLow = 0.15, kAxisAreaHigh = 3.5;

// Distortion of the band for one axis (x = L axis(u), y scaled by yscale), on a sample of faces,
// those out of the map left out.
DistortionStats axis_distortion(const SegmentWork& w, const std::vector<double>& axis, double length, double yscale,
                                const std::vector<char>& degenerate) {
  const Surface& s = w.ann;
  const std::size_t stride = std::max<std::size_t>(1, s.t.size() / 200000);
  std::vector<FaceDistortion> fd;
  for (std::size_t f = 0; f < s.t.size(); f += stride) {
    if (degenerate[f]) continue;
    const Tri& t = s.t[f];
    auto c = w.emb.corners(s, int(f));
    for (auto& q : c) q = V2(length * interpolate_axis(axis, q.x() / w.seg.length), q.y() * yscale);
    const FaceDistortion d = face_distortion(s.p[t[0]], s.p[t[1]], s.p[t[2]], c[0], c[1], c[2]);
    if (!too_small_in_map(d.area2, d.area3)) fd.push_back(d);  // as measure(): a stump's crushed faces
  }                                                             // would swamp the qc mean (1e11)
  return stats_of(fd);
}

// The band's x axis: among x(u) = B F_beta(u) (B the band length) (beta = 0: conformal spacing; 1: each slice as wide
// as its wall area), the one with the smallest angle distortion whose area ratios stay in bounds
// (5th percentile >= 0.3, 95th <= 3.5); when none is, the least distorting of those whose 5th
// percentile is within 10 % of the best. The 11 axes are measured side by side (parallel_tasks:
// each on its own, read in beta order, so the choice is the same for any thread count).
std::vector<double> choose_axis(SegmentWork& w, const Centreline& cl, double band, double yscale,
                                const std::vector<char>& degenerate) {
  w.seg.balance_strength = 1.0;
  constexpr int kSteps = 10;
  std::vector<DistortionStats> measured(kSteps + 1);
  std::vector<std::function<void()>> tasks;
  for (int step = 0; step <= kSteps; ++step)
    tasks.emplace_back([&, step] { measured[step] = axis_distortion(w, cl.blended_axis(0.1 * step), band, yscale, degenerate); });
  parallel_tasks(tasks);
  std::vector<std::pair<double, DistortionStats>> tried;
  for (int step = 0; step <= kSteps; ++step) {
    const double beta = 0.1 * step;
    const DistortionStats& st = measured[std::size_t(step)];
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug axis beta %.1f (conformal length %.0f, band %.0f mm): qc mean %.3f area p05 %.3f p95 %.3f\n",
                   beta, w.seg.length, band, st.qc_mean, st.area_p05, st.area_p95);
    tried.emplace_back(beta, st);
  }
  double best_p05 = 0;
  bool any_within = false;
  for (const auto& [beta, st] : tried) {
    best_p05 = std::max(best_p05, st.area_p05);
    any_within = any_within || (st.area_p05 >= kAxisAreaLow && st.area_p95 <= kAxisAreaHigh);
  }
  // Candidates: within bounds; when none is, within 10 % of the best 5th percentile.
  double best_qc = 1e300;
  for (const auto& [beta, st] : tried) {
    const bool ok = any_within ? st.area_p05 >= kAxisAreaLow && st.area_p95 <= kAxisAreaHigh : st.area_p05 >= 0.9 * best_p05;
    if (ok && st.qc_mean < best_qc) best_qc = st.qc_mean, w.seg.balance_strength = beta;
  }
  return cl.blended_axis(w.seg.balance_strength);
}

}  // namespace

// Which area corrections a band needs: on the whole band when its area ratio 5th percentile is
// below 0.25, its 95th above 4 or its quasi-conformal mean above 1.45; on pockets (local) when
// more than 0.25 % of its wall is shown below coverage_min_ratio (margins under the targets 0.2,
// 5, 1.5 and 99.5 %). A band within all of them is left as it is: on a large colon a whole-band
// correction costs several times the conformal solve. The whole-band pass holds crushed pockets
// (area_correct.cpp), so pockets left after it are opened by a local pass.
// (kWholeBandAreaLow, kWholeBandAreaHigh, kWholeBandQcMean: whole_band_stop.h)
struct CorrectionNeed {
  bool global = false, local = false;
  BoundStats all;      // over the faces in the map
  double hidden = 0;   // fraction of the wall shown below coverage_min_ratio
};
struct NeedScratch {  // a caller's vectors kept across needs_correction() calls
  std::vector<FaceDistortion> fd;
  std::vector<double> ratio;
};
static CorrectionNeed needs_correction(const SegmentWork& w, const std::vector<char>& degenerate, const FlattenOptions& o,
                                       const std::vector<FaceFrame>* frames = nullptr, NeedScratch* scratch = nullptr) {
  NeedScratch own;
  NeedScratch& use = scratch ? *scratch : own;
  std::vector<FaceDistortion>& fd = use.fd;
  band_distortion(w, degenerate, frames, fd);
  double a2 = 0, a3 = 0;
  for (const FaceDistortion& d : fd)
    if (!d.degenerate) a2 += std::max(d.area2, 0.0), a3 += d.area3;
  double hidden = 0;
  for (const FaceDistortion& d : fd)
    if (!d.degenerate && d.area2 * a3 < o.coverage_min_ratio * d.area3 * a2) hidden += d.area3;
  // the faces out of the map are left out, as measure() does
  const BoundStats st = bound_stats_in_map(fd, &use.ratio);
  const bool area = st.area_p05 < kWholeBandAreaLow || st.area_p95 > kWholeBandAreaHigh;
  return {area || st.qc_mean > kWholeBandQcMean, hidden > kHiddenWallTolerance * a3, st, a3 > 0 ? hidden / a3 : 0.0};
}

// When the whole-band pass has done its job, asked after each of its steps: WholeBandStop
// (whole_band_stop.h) on the trigger's own statistics, over all faces and then, when those say go on,
// over the faces the pass moves (none of their corners held: the pass holds the corners of the faces
// crushed when it starts, whole_band_held()). Each step costs a solve on the whole band (0.9 M
// unknowns on the real CT colon band); past that point the steps only trade angle against area
// distortion in wall that is already readable, and the pockets are the local pass's job. The faces'
// 3D frames are computed once for the pass (the check's numbers are the same bits).
// COLONFLAT_FLATTEN_DEBUG: one line per check.
std::function<bool()> whole_band_done(const SegmentWork& w, const std::vector<char>& degenerate, const FlattenOptions& o) {
  auto frames = std::make_shared<const std::vector<FaceFrame>>(band_frames(w));
  auto scratch = std::make_shared<NeedScratch>();  // the checks' vectors, kept from step to step
  auto moved = std::make_shared<std::vector<char>>(degenerate.size(), 0);  // faces with no corner held
  const std::vector<char> held = whole_band_held(w.ann, w.emb, degenerate, o.coverage_min_ratio);
  for (std::size_t f = 0; f < moved->size(); ++f) {
    const Tri& t = w.ann.t[f];
    (*moved)[f] = !degenerate[f] && !held[t[0]] && !held[t[1]] && !held[t[2]];
  }
  const std::size_t moved_faces = std::size_t(std::count(moved->begin(), moved->end(), 1));
  const bool debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
  auto all = std::make_shared<AllFacesCheck>(w.ann, *frames, degenerate);  // rule (a), after every step
  return [&w, &degenerate, &o, frames, scratch, moved, moved_faces, debug, all, rule = WholeBandStop(), step = 0]() mutable {
    if (all->all_done(w.emb)) return true;
    if (!WholeBandStop::judges_free(++step)) return false;
    std::vector<FaceDistortion>& fd = scratch->fd;  // the held faces left out, as degenerate ones are
    band_distortion(w, degenerate, frames.get(), fd);
    for (std::size_t f = 0; f < fd.size(); ++f) fd[f].degenerate = !(*moved)[f];
    const BoundStats free = bound_stats_in_map(fd, &scratch->ratio);
    if (debug) {
      const CorrectionNeed now = needs_correction(w, degenerate, o, frames.get());
      std::fprintf(stderr, "flatten debug whole-band check %d: all p05 %.4f p95 %.4f qc %.4f hidden %.6f; "
                   "free (%zu of %zu faces) p05 %.4f p95 %.4f qc %.4f\n", step, now.all.area_p05, now.all.area_p95,
                   now.all.qc_mean, now.hidden, moved_faces, fd.size(), free.area_p05, free.area_p95, free.qc_mean);
    }
    return rule.free_done(free);
  };
}

// Runs one area correction pass (COLONFLAT_FLATTEN_DEBUG: what it did).
static int correct_pass(SegmentWork& w, const std::vector<std::vector<int>>& vf, const std::vector<char>& fixed,
                        const std::vector<char>& degenerate, const FlattenOptions& o, bool local, bool grow = false,
                        const std::function<bool()>& enough = {}, const std::vector<int>* vertex_order = nullptr) {
  const Stopwatch sw;
  const bool debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
  CorrectionTimes times;
  const AreaCorrection corr =
      correct_area(w.ann, vf, w.emb, fixed, degenerate, local, o, grow, enough, vertex_order, debug ? &times : nullptr);
  if (debug) {
    std::fprintf(stderr, "flatten debug area correction (%s): %zu faces, %d iterations, energy %.6g -> %.6g (%s), %.2f s\n",
                 local ? "local" : "whole band", corr.faces, corr.iterations, corr.energy_before, corr.energy_after,
                 corr.stop, sw.seconds());
    const StepTimes& t = times.steps;
    std::fprintf(stderr, "flatten debug area correction (%s) parts: %s %zu faces, %d steps, %.2f s: system %.2f s, "
                 "gradients %.2f, solves %.2f, step limit %.2f, line search %.2f (%d energies), check %.2f; "
                 "%zu pieces, %.2f s summed, the longest started %zu-th\n",
                 local ? "local" : "whole band", local ? "longest piece" : "band", times.longest_faces, times.longest_steps,
                 times.longest_s, times.build_s, t.gradient, t.solve, t.step_limit, t.line_search, t.energy_evals, t.check,
                 times.pieces, times.pieces_s, times.longest_place + 1);
    const Stopwatch measures;  // debug only, inside the pass's debug clock stretch (mostly one thread)
    debug_stats(local ? "local area correction" : "area correction", w, degenerate);
    debug_pockets(local ? "local area correction" : "area correction", w, degenerate, fixed);
    std::fprintf(stderr, "flatten debug area correction (%s) measures (debug only): %.2f s wall\n",
                 local ? "local" : "whole band", measures.seconds());
  }
  return corr.iterations;
}

// The local passes once, with the vertices `held` fixed: pockets; then, grown until they have room,
// those left (when the band still needs it, or `second`). Returns whether the second pass ran.
static bool run_local_passes(SegmentWork& w, const std::vector<std::vector<int>>& vf, const std::vector<char>& held,
                             const std::vector<char>& degenerate, const FlattenOptions& o, bool branch,
                             bool second = false) {
  for (bool grow : {false, true}) {
    w.seg.corrected_iterations = std::max(w.seg.corrected_iterations, correct_pass(w, vf, held, degenerate, o, true, grow));
    if (!branch) debug_clock(grow ? "local pass 2" : "local pass 1");
    if (grow || second) continue;
    const bool need = needs_correction(w, degenerate, o).local;
    if (!branch) debug_clock("correction need after local pass 1");
    if (!need) return false;
  }
  return true;
}

// The freed rims (`freed`) that cross more often than at the start (`start`: rim_crossings() before
// the passes); COLONFLAT_FLATTEN_DEBUG: the round's counts.
static std::vector<char> rims_that_crossed(const SegmentWork& w, const CutRims& rims, const std::vector<char>& freed,
                                           const std::vector<std::size_t>& start, int round) {
  const std::vector<std::size_t> now = rim_crossings(w, rims);
  std::vector<char> crossed(now.size(), 0);
  std::size_t free_edges = 0, added = 0;
  for (std::size_t r = 0; r < now.size(); ++r) {
    crossed[r] = freed[r] && now[r] > start[r];
    free_edges += freed[r] ? rims.loops[r].size() : 0, added += crossed[r];
  }
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug local passes, rims free (round %d): %zu rims (%zu edges), %zu freed (%zu edges), "
                 "%zu of them crossed\n", round, rims.loops.size(), rims.edges.size(),
                 std::size_t(std::count(freed.begin(), freed.end(), 1)), free_edges, added);
  return crossed;
}

// (cut_rims.h) A rim held where the conformal map put it (a round hole whose length in the map can
// be half its 3D length where a limb-sized branch was cut off) leaves the strip of wall along it
// crushed; only the rim giving way opens it (issue 26, docs/flatten.md session 25). A band whose
// rims all stay held (most bands) runs the passes once, without the crossing checks. A rim that
// crosses costs the passes of its own pieces again; the rims that did not keep what they opened.
void local_area_passes(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                       const std::vector<char>& fixed, const std::vector<char>& ends,
                       const std::vector<char>& degenerate, const FlattenOptions& o, bool branch, bool pockets) {
  const CutRims rims = cut_rims(w.ann, E, ends);
  const std::vector<char> freed = free_rims(w, rims, o);
  const std::vector<char> widened = widen_short_rims(w, rims, freed, ends, o);  // (held from then on)
  if (!pockets && std::count(widened.begin(), widened.end(), 1) == 0) return;
  if (std::count(freed.begin(), freed.end(), 1) == 0) {
    run_local_passes(w, vf, fixed, degenerate, o, branch);
    return;
  }
  local_passes_freeing(w, rims, freed, vf, ends, degenerate, o, branch);
}

void local_passes_freeing(SegmentWork& w, const CutRims& rims, std::vector<char> freed,
                          const std::vector<std::vector<int>>& vf, const std::vector<char>& ends,
                          const std::vector<char>& degenerate, const FlattenOptions& o, bool branch) {
  const std::vector<std::size_t> start = rim_crossings(w, rims);
  std::vector<char> kept(w.emb.pos.size(), 0);  // moved by pieces that keep their result
  bool second = false;  // the restored pieces get the passes the first round ran
  for (int round = 1;; ++round) {
    std::vector<char> held = held_vertices(w, rims, freed, ends);
    for (std::size_t v = 0; v < held.size(); ++v) held[v] |= kept[v];
    const std::vector<V2> before = w.emb.pos;
    second = run_local_passes(w, vf, held, degenerate, o, branch, second);
    const std::vector<char> crossed = rims_that_crossed(w, rims, freed, start, round);
    if (std::count(crossed.begin(), crossed.end(), 1) == 0) return;
    std::vector<char> others(crossed.size());  // the crossed rims are held from now on
    for (std::size_t r = 0; r < crossed.size(); ++r) others[r] = !crossed[r], freed[r] = freed[r] && !crossed[r];
    const std::size_t back =
        restore_touched_pieces(w, before, held_vertices(w, rims, others, std::vector<char>(held.size(), 0)), kept);
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug local passes: %zu vertices restored, %zu kept\n", back,
                   std::size_t(std::count(kept.begin(), kept.end(), 1)));
  }
}

// Band length: the centreline length L, moved towards the conformal length by at most 8 % (the
// wall of a folded colon is longer than its centreline; within the 10 % the band may differ from
// L this removes part of the angle distortion a rectangle of length L would impose everywhere).
// A side branch's band takes its conformal length (a pouch's centreline is short and ill-defined;
// its ticks still give centreline mm from the neck).
constexpr double kBandLengthSlack = 0.08;

// Area-balanced map: x = B F(u) (the axis chosen above; B the band length), y scaled so that the
// band's area is the wall area, fold-overs untangled, then the regions still out of bounds
// balanced (symmetric Dirichlet). centreline_x keeps the true centreline mm of each band x.
void area_balanced_step(SegmentWork& w, const Centreline& cl, const std::vector<std::vector<int>>& ends, const Edges& E,
                        const std::vector<std::vector<int>>& vf,
                        const std::vector<char>& fixed, const std::vector<char>& degenerate,
                        const FlattenOptions& o, bool branch) {
  Embedding& emb = w.emb;
  const double conformal_length = w.seg.length;
  const double slack = branch ? 1e9 : kBandLengthSlack;
  const double band = std::clamp(conformal_length, (1 - std::min(slack, 0.5)) * cl.length, (1 + slack) * cl.length);
  const double period = w.seg.area_3d / band;
  const double yscale = period / emb.period;
  // A branch keeps the conformal spacing (beta 0: x linear in u, so no fold from the axis; its
  // x is not a centreline position anyway); the area correction balances it.
  const std::vector<double> axis = branch ? cl.blended_axis(w.seg.balance_strength = 0.0)
                                          : choose_axis(w, cl, band, yscale, degenerate);
  parallel_for(emb.pos.size(), [&](std::size_t b, std::size_t e) {  // each vertex on its own
    for (std::size_t v = b; v < e; ++v)
      emb.pos[v] = V2(band * interpolate_axis(axis, emb.pos[v].x() / conformal_length), emb.pos[v].y() * yscale);
  });
  for (std::size_t i = 0; i < cl.knot_u.size(); ++i)
    w.seg.centreline_x.push_back({cl.knot_s[i], band * interpolate_axis(axis, cl.knot_u[i])});
  for (auto& d : emb.dy)
    for (double& x : d) x *= yscale;
  emb.period = period;
  w.seg.length = band;
  w.seg.period = period;
  if (!branch) debug_clock("axis chosen, band reparametrised");
  w.seg.untangled_vertices += untangle(w.ann, vf, emb, fixed, degenerate);
  if (!branch) debug_clock("untangled");
  debug_stats("reparametrised", w, degenerate);
  debug_pockets("reparametrised", w, degenerate, fixed);
  CorrectionNeed need = needs_correction(w, degenerate, o);
  if (!branch) debug_clock("debug stats, correction need");
  const std::vector<int> order = w.band_order();  // a large band's nested dissection order, for its systems
  const std::vector<int>* band_order = order.empty() ? nullptr : &order;
  std::vector<char> on_end(fixed.size(), 0);
  for (const std::vector<int>& l : ends)
    for (int v : l) on_end[std::size_t(v)] = 1;
  if (need.global) {
    w.seg.corrected_iterations =
        correct_pass(w, vf, fixed, degenerate, o, false, false, whole_band_done(w, degenerate, o), band_order);
    if (!branch) debug_clock("whole-band pass");
    need.local = needs_correction(w, degenerate, o).local;
    if (!branch) debug_clock("correction need after the whole band");
  }
  local_area_passes(w, E, vf, fixed, on_end, degenerate, o, branch, need.local);
  const Stopwatch sw;
  const BalanceResult bal = balance_area(w.ann, vf, emb, fixed, degenerate, o, band_order);
  w.seg.balanced_vertices = bal.vertices;
  if (!branch) debug_clock("balance");
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug balance: %zu faces, %zu iterations, %zu systems factorised, %.2f s\n", bal.faces,
                 bal.iterations, bal.systems_built, sw.seconds());
}

}  // namespace cf::flat_detail
