// Area correction of the band: the map that is as conformal as possible while every face's area
// ratio stays within [lo, hi]. Minimises
//   E = sum_f sum_k w_fk |c_a - c_b|^2  +  lambda sum_f A3_f pen(log r_f),
// the first term the Dirichlet energy of the 2D corners with the (clamped) cotangent weights of
// the 3D triangles (its minimiser is the conformal map; it penalises angle distortion), the
// second a penalty on each face's log area ratio outside [log lo, log hi] (pen(l) = distance of
// l to the interval, squared; +infinity for a folded face). Newton steps on the quadratic part:
// direction = -A^-1 grad E with A the cotangent Laplacian, factorised once (the quadratic term's
// exact Hessian / 2, the "accelerated quadratic proxy" of Kovalsky et al. 2016), step cut so that
// no face folds and halved until E decreases (Armijo). The band's ends and the rims of cut-off
// branches are fixed, so the map stays bijective.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numeric>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/union_find.h"
#include "conformal_area_energy.h"
#include "face_blocks.h"
#include "face_rings.h"
#include "flatten_internal.h"
#include "proxy_descent.h"
#include "whole_band_stop.h"

namespace cf::flat_detail {
namespace {

// Whole-band pass: the vertices of the pockets not shown (area ratio below `below` =
// coverage_min_ratio at the band's scale: strand stumps, pouches behind narrow necks, wide stretches
// the conformal map shrank) are held, and faces whose corners are all held leave the energy. A
// face's penalty gradient grows as 1 / its 2D size, so with such faces free the Newton direction is
// a point source at each of them and the fold-free step (0.9 x the largest keeping every face
// positive) shrinks to nothing for the whole band: on the real CT colon's 1.88 M-face band 60 steps
// left area p05 at 0.153 (holding only faces below 1e-3: 0.155; holding the pockets: 0.325). The
// pockets are opened afterwards by the local pass, each with its own line search.
void hold_crushed(const Surface& s, const std::vector<double>& area2, const std::vector<double>& area3, double scale,
                  double below, std::vector<char>& free_vertex, std::vector<int>& faces) {
  for (int f : faces)
    if (crushed_in_band(scale, area2[f], area3[f], below))
      for (int v : s.t[f]) free_vertex[v] = 0;
  faces.erase(std::remove_if(faces.begin(), faces.end(),
                             [&](int f) {
                               const Tri& t = s.t[f];
                               return !free_vertex[t[0]] && !free_vertex[t[1]] && !free_vertex[t[2]];
                             }),
              faces.end());
}

// A region's rim stays: a free vertex with a face outside the region (`inside(g)` false) is fixed.
template <class Inside>
void fix_region_rim(const std::vector<std::vector<int>>& vf, Inside&& inside, std::vector<char>& free_vertex) {
  for (std::size_t v = 0; v < free_vertex.size(); ++v)
    if (free_vertex[v])
      for (int g : vf[v])
        if (!inside(g)) free_vertex[v] = 0;
}

// The local region: the pockets not shown (area ratio at `scale` below coverage_min_ratio) grown
// by kLocalRings vertex rings; a piece of it whose 2D area is still below kLocalRoom x its 3D area
// (a pouch left in the band, a wide stretch the conformal map shrank: the rings around it cannot
// give it room) grows by kLocalRings more, up to `growths` times (the balancing's region rule;
// kLocalGrowths in the second local pass, 0 in the first: grown regions merge pockets, and a merged
// piece gets fewer steps and shares its line search with the stumps in it).
constexpr int kLocalRings = 12, kLocalGrowths = 3;
constexpr double kLocalRoom = 0.6;
std::vector<char> local_region(const Surface& s, const std::vector<std::vector<int>>& vf, const std::vector<double>& area2,
                               const std::vector<double>& area3, double scale, double min_ratio, int growths) {
  std::vector<char> in(s.t.size(), 0);
  std::vector<int> ring;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (scale * area2[f] < min_ratio * std::max(area3[f], 1e-300)) in[f] = 1, ring.push_back(int(f));
  for (int growth = 0;; ++growth) {
    grow_face_rings(s, vf, kLocalRings, ring, [&](int g) {
      if (in[g]) return false;
      in[g] = 1;
      return true;
    });
    if (growth == growths || ring.empty()) return in;
    UnionFind sets(s.p.size());  // pieces of the region and their 2D / 3D areas
    for (std::size_t f = 0; f < s.t.size(); ++f)
      if (in[f]) sets.unite(std::uint32_t(s.t[f][0]), std::uint32_t(s.t[f][1])), sets.unite(std::uint32_t(s.t[f][0]), std::uint32_t(s.t[f][2]));
    std::vector<double> a2(s.p.size(), 0.0), a3(s.p.size(), 0.0);
    for (std::size_t f = 0; f < s.t.size(); ++f)
      if (in[f]) {
        const std::uint32_t root = sets.find(std::uint32_t(s.t[f][0]));
        a2[root] += scale * std::max(area2[f], 0.0), a3[root] += area3[f];
      }
    std::vector<int> starved;  // the frontier of pieces without room
    for (int f : ring) {
      const std::uint32_t root = sets.find(std::uint32_t(s.t[f][0]));
      if (a2[root] < kLocalRoom * a3[root]) starved.push_back(f);
    }
    if (starved.empty()) return in;
    ring.swap(starved);
  }
}

// The faces the correction works on: all of them (`local` false), or the local region above;
// free: their vertices that are not fixed and, when local, not on the region's rim. Folds left by
// untangle are not judged. area2 / area3: per face its signed map area / 3D area.
std::vector<int> correction_faces(const Surface& s, const std::vector<std::vector<int>>& vf, const std::vector<double>& area2,
                                  const std::vector<double>& area3, const std::vector<char>& fixed,
                                  const std::vector<char>& degenerate, double scale, const FlattenOptions& o,
                                  bool local, bool grow, std::vector<char>& free_vertex) {
  const std::vector<char> in = local ? local_region(s, vf, area2, area3, scale, o.coverage_min_ratio, grow ? kLocalGrowths : 0)
                                     : std::vector<char>(s.t.size(), 1);
  std::vector<int> faces;
  free_vertex.assign(s.p.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (in[f] && !degenerate[f] && area2[f] > 0) {
      faces.push_back(int(f));
      for (int v : s.t[f]) free_vertex[v] = !fixed[v];
    }
  if (local) fix_region_rim(vf, [&](int g) { return in[g] != 0; }, free_vertex);
  if (!local) hold_crushed(s, area2, area3, scale, o.coverage_min_ratio, free_vertex, faces);
  return faces;
}

// Steps allowed: `iterations` on a whole band; on local regions (pockets, a polyp head behind its
// stalk: ratios near 1e-3 that need hundreds of steps) up to kLocalStepFactor x as many, as long as
// the work (faces x steps) stays within kLocalWork. A strand stump's tip, crushed by the conformal
// map to 1e-19 of its area, opens by a bounded factor per fold-free step: with 10 x (600 steps) the
// real CT colon's stump piece (3100 faces) stopped on its step count with its energy still falling,
// and where it stopped depended on the rounding of the map before (shown 99.30 / 99.26 % with two
// equally exact elimination orders); with 60 x the work bound decides (3200 steps for 3100 faces).
constexpr double kLocalWork = 1e7, kLocalStepFactor = 60;
int iteration_budget(std::size_t faces, bool local, int iterations) {
  if (!local || faces == 0) return iterations;
  const double affordable = kLocalWork / double(faces);
  return int(std::clamp(affordable, double(iterations), kLocalStepFactor * iterations));
}

}  // namespace

// Exact (no rounding of the step count), so every piece whose budget the work bound sets has the
// same value, kLocalWork: faces x iteration_budget() truncates 1e7 / faces to whole steps and left
// such pieces ordered by the remainder (the real CT colon band's 76 k-face piece, 130 steps, the
// longest of its local pass, started 7-th of 12).
double piece_work_bound(std::size_t faces, int iterations) {
  const double f = double(faces), fewest = f * iterations, most = f * kLocalStepFactor * iterations;
  return fewest >= kLocalWork ? fewest : most <= kLocalWork ? most : kLocalWork;
}

// The pieces' indices, the most work first: the work bound (piece_work_bound()), then more faces.
// parallel_tasks starts tasks in the order given, so the piece that may take longest starts at
// once instead of after the pieces before it (the "longest processing time first" rule: with 2
// threads it ends at most 4/3 x the best schedule's length). Only the start order changes: each
// piece writes its own slot and vertices.
std::vector<std::size_t> most_work_first(const std::vector<std::vector<int>>& pieces, int iterations) {
  std::vector<std::size_t> order(pieces.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const double wa = piece_work_bound(pieces[a].size(), iterations), wb = piece_work_bound(pieces[b].size(), iterations);
    return wa != wb ? wa > wb : pieces[a].size() > pieces[b].size();
  });
  return order;
}

namespace {

// Faces split into vertex-connected pieces (local regions far apart are corrected independently:
// a stuck piece, such as a strand stump at zero area, does not hold back the line search of others).
std::vector<std::vector<int>> connected_pieces(const Surface& s, const std::vector<int>& faces) {
  UnionFind sets(s.p.size());
  for (int f : faces)
    for (int k = 1; k < 3; ++k) sets.unite(std::uint32_t(s.t[f][0]), std::uint32_t(s.t[f][k]));
  std::vector<int> piece_of_root(s.p.size(), -1);
  std::vector<std::vector<int>> pieces;
  for (int f : faces) {
    int& id = piece_of_root[sets.find(std::uint32_t(s.t[f][0]))];
    if (id < 0) id = int(pieces.size()), pieces.emplace_back();
    pieces[id].push_back(f);
  }
  return pieces;
}

// Wall area (3D) of `faces` whose map area ratio at `scale` is below `ratio`.
double area_below(const Surface& s, const Embedding& emb, const std::vector<double>& area3, double scale,
                  const std::vector<int>& faces, double ratio) {
  double a = 0;
  for (int f : faces) a += scale * emb.area2(s, f) < ratio * area3[f] ? area3[f] : 0.0;
  return a;
}

// The wall a local piece may leave hidden (shown below coverage_min_ratio): kHiddenWallTolerance of
// its wall, the second local pass's test of a piece with nothing to show.
double hidden_wall_tolerance(const std::vector<double>& area3, const std::vector<int>& piece) {
  double wall = 0;
  for (int f : piece) wall += area3[f];
  return kHiddenWallTolerance * wall;
}

// Newton steps on one set of faces (free vertices as given); accumulates into `res`; `times`
// (optional): where its wall time went. A whole band (not `local`) asks `enough` beside its next
// step's solve (proxy_descent.h); a local piece stops once its steps stall on the same faces' cut
// with no wall left hidden, or with `leave_stuck` once they stall far below the proxy's step showing
// nothing (held_steps.h). Returns the largest fold-free cut of a local piece's steps (1 for a whole
// band: not watched).
double minimise(const Surface& s, Embedding& emb, std::vector<int> faces, const std::vector<char>& free_vertex,
              const std::vector<double>& area3, double scale, const FlattenOptions& o, bool local,
              AreaCorrection& res, const std::function<bool()>& enough = {}, std::vector<V2>* scratch = nullptr,
              const std::vector<int>* vertex_order = nullptr, CorrectionTimes* times = nullptr,
              bool leave_stuck = false) {
  const std::size_t nfaces = faces.size();
  Stopwatch clock;
  const ConformalAreaEnergy energy(s, emb, std::move(faces), area3, o.area_ratio_low, o.area_ratio_high, o.area_weight,
                                   scale);
  RegionSystem sys;
  if (!sys.build(s, free_vertex, energy.faces(), energy.weights(), vertex_order)) return 1.0;
  if (!local) debug_clock("whole-band system built");
  const double build_s = clock.lap();
  const int max_steps = iteration_budget(nfaces, local, o.area_correction_iterations);
  StepTimes* step_times = times ? &times->steps : nullptr;
  const std::vector<int>& piece = energy.faces();
  HeldSteps held(s, emb, [&] { return area_below(s, emb, area3, scale, piece, o.coverage_min_ratio); },
                 local ? hidden_wall_tolerance(area3, piece) : 0.0, leave_stuck);
  const DescentResult d = proxy_descent(s, emb, energy, sys, energy.faces(), area3, max_steps, 1e-5, enough, scratch,
                                        step_times, !local, local ? &held : nullptr);
  if (times) {
    times->build_s = build_s, times->longest_s = build_s + clock.lap();
    times->longest_faces = nfaces, times->longest_steps = d.steps;
  }
  res.energy_before += d.energy_before;
  res.energy_after += d.energy_after;
  res.iterations = std::max(res.iterations, d.steps);
  res.stop = d.stop;
  return local ? held.largest_cut() : 1.0;
}

// The second (grown) local pass works only on the pieces that still hide wall: a piece whose wall
// shown below `min_ratio` (coverage_min_ratio) is at most kHiddenWallTolerance of its 3D wall is
// dropped. The pass runs because the band hides more than that fraction; the pieces dropped hide at
// most that fraction of their wall together, so they are not why, and their descent would only move
// area ratios of wall already shown, which the balancing after the local passes bounds (real CT
// colon band: 8 of the pass's 9 pieces hid 0.1-3.3 mm2 each and took 57 % of its summed time).
void keep_pieces_hiding_wall(const Surface& s, const Embedding& emb, const std::vector<double>& area3, double scale,
                             double min_ratio, std::vector<std::vector<int>>& pieces) {
  const auto shown = [&](const std::vector<int>& piece) {
    return !(area_below(s, emb, area3, scale, piece, min_ratio) > hidden_wall_tolerance(area3, piece));
  };
  pieces.erase(std::remove_if(pieces.begin(), pieces.end(), shown), pieces.end());
}

// A crushed spot of a local piece (issue 26, docs/flatten.md session 21): its faces at area ratio
// below kSpotRatio (at the band's scale; positive: folds are not judged), grown by kSpotRings vertex
// rings within the piece, corrected as a piece of its own. Such faces can bound every fold-free
// step of a whole piece (no face may lose more than half its area in a step; across a spot ~1e-4
// of its neighbours' size the piece's direction varies by far more than the spot's size), so a
// large piece gains < min_gain per step and stops with its pockets unopened; on the spot alone the
// same tiny steps are cheap, move only the spot, and gain until it has opened.
// A piece whose every step stayed below kStuckStep of the proxy's step was held by more than its
// faces below kSpotRatio: the CT mask's window piece (pass 2: 5e-9 .. 4e-8 at each of its 62 steps)
// holds 47 faces below 1e-4 and ~430 below 1e-3, and its re-run after the 47 went on at 1e-7 ..
// 2e-6, held by the next ones; its spots are then the faces below kStuckSpotRatio (issue 26,
// session 29 "tail"). Pieces that open step at 1e-5 .. 3e-2 once their ramp is over.
constexpr double kSpotRatio = 1e-4, kStuckSpotRatio = 1e-3;
constexpr int kSpotRings = 2;
struct SpotWork {
  std::size_t faces = 0;    // faces of the piece's spot regions
  int steps = 0;            // most steps a spot region took
  std::size_t regions = 0;  // spot regions (vertex-connected)
  long summed_steps = 0;    // steps of all regions
  double seconds = 0;       // wall time of the regions' descents
};
SpotWork open_crushed_spots(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                            const std::vector<int>& piece, const std::vector<char>& free_vertex,
                            const std::vector<double>& area3, double scale, const FlattenOptions& o,
                            double spot_ratio, std::vector<V2>* scratch) {
  SpotWork work;
  std::vector<int> ring;
  for (int f : piece)
    if (scale * emb.area2(s, f) < spot_ratio * area3[f]) ring.push_back(f);
  if (ring.empty()) return work;
  std::vector<char> mark(s.t.size(), 0);  // 1: in the piece, 2: in a spot region
  for (int f : piece) mark[f] = 1;
  for (int f : ring) mark[f] = 2;
  std::vector<int> faces = ring;
  const auto take = [&](int g) {
    if (mark[g] != 1) return false;
    mark[g] = 2;
    return true;
  };
  grow_face_rings(s, vf, kSpotRings, ring, take, &faces);
  std::sort(faces.begin(), faces.end());
  std::vector<char> spot_free(s.p.size(), 0);  // the piece's free vertices inside the spot regions
  for (int f : faces)
    for (int v : s.t[f]) spot_free[v] = free_vertex[v];
  fix_region_rim(vf, [&](int g) { return mark[g] == 2; }, spot_free);
  work.faces = faces.size();
  const Stopwatch clock;
  for (std::vector<int>& spot : connected_pieces(s, faces)) {
    AreaCorrection res;
    minimise(s, emb, std::move(spot), spot_free, area3, scale, o, true, res, {}, scratch);
    work.steps = std::max(work.steps, res.iterations), work.summed_steps += res.iterations, ++work.regions;
  }
  work.seconds = clock.seconds();
  return work;
}

// One local piece: its descent; when that left more than kFrozen of the piece's hidden wall hidden
// (a piece that opens its pockets leaves a few % at most: on the real CT colon band, every piece but
// the frozen one left <= 12 %) and the piece holds a crushed spot, the spot is opened on its own and
// the piece runs again; in the last local pass only (`last_pass`: the grown regions, where a piece
// has the most room; in the first pass a frozen piece is left to it). There a piece whose first
// descent is stuck (held_steps.h) stops it early and goes to its spots at once. Pieces that did their
// job are left as they are.
constexpr double kFrozen = 0.5;
SpotWork correct_piece(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                       const std::vector<int>& piece, const std::vector<char>& free_vertex,
                       const std::vector<double>& area3, double scale, const FlattenOptions& o, bool last_pass,
                       AreaCorrection& res, std::vector<V2>* scratch, CorrectionTimes* times) {
  const double hidden = area_below(s, emb, area3, scale, piece, o.coverage_min_ratio);
  const double largest_cut =
      minimise(s, emb, piece, free_vertex, area3, scale, o, true, res, {}, scratch, nullptr, times, last_pass);
  if (!last_pass || !(area_below(s, emb, area3, scale, piece, o.coverage_min_ratio) > kFrozen * hidden)) return {};
  Stopwatch clock;
  const double spot_ratio = largest_cut < HeldSteps::kStuckStep ? kStuckSpotRatio : kSpotRatio;
  const SpotWork spots = open_crushed_spots(s, vf, emb, piece, free_vertex, area3, scale, o, spot_ratio, scratch);
  if (spots.faces == 0) return spots;
  AreaCorrection again;
  CorrectionTimes again_times;
  minimise(s, emb, piece, free_vertex, area3, scale, o, true, again, {}, scratch, nullptr, &again_times);
  res.energy_after = again.energy_after, res.iterations += again.iterations, res.stop = again.stop;
  if (times) times->longest_s += clock.lap(), times->longest_steps = res.iterations;
  return spots;
}

// The local pieces' times combined (the piece that took longest, the sum); `place[i]`: piece i's
// place in the start order.
void combine_times(const std::vector<CorrectionTimes>& part, const std::vector<std::size_t>& place,
                   CorrectionTimes& out) {
  out.pieces = part.size();
  for (std::size_t i = 0; i < part.size(); ++i) {
    const CorrectionTimes& p = part[i];
    out.pieces_s += p.longest_s;
    if (p.longest_s > out.longest_s) {
      const double sum = out.pieces_s;
      out = p;
      out.pieces_s = sum, out.pieces = part.size(), out.longest_place = place[i];
    }
  }
}

// COLONFLAT_FLATTEN_DEBUG: one line per local piece (faces, steps of its budget, why it stopped,
// wall s, wall area shown below coverage_min_ratio before and after, below area_ratio_low after).
class PieceLog {
 public:
  PieceLog(const Surface& s, const Embedding& emb, const std::vector<double>& area3, double scale,
           const FlattenOptions& o, const std::vector<std::vector<int>>& pieces)
      : s_(s), emb_(emb), area3_(area3), scale_(scale), o_(o), pieces_(pieces) {
    for (const std::vector<int>& p : pieces_) {
      hidden_before_.push_back(area_below(p, o_.coverage_min_ratio));
      double a2 = 0, a3 = 0;
      for (int f : p) a2 += scale_ * std::max(emb_.area2(s_, f), 0.0), a3 += area3_[f];
      room_.push_back(a3 > 0 ? a2 / a3 : 1.0);
    }
  }
  void print(const std::vector<AreaCorrection>& part, const std::vector<CorrectionTimes>& times,
             const std::vector<std::size_t>& place, const std::vector<SpotWork>& spots) const {
    for (std::size_t i = 0; i < part.size(); ++i)
      std::fprintf(stderr, "flatten debug local piece %zu (started %zu-th): %zu faces, %d steps of %d, %s, %.3f s; "
                   "shown below %.2g: %.1f -> %.1f mm2; below %.2g: %.1f mm2; crushed spots first: %zu faces, %d steps (%zu regions, %ld steps summed, %.3f s); room %.3f\n",
                   i, place[i] + 1, pieces_[i].size(), part[i].iterations,
                   iteration_budget(pieces_[i].size(), true, o_.area_correction_iterations), part[i].stop,
                   times[i].longest_s, o_.coverage_min_ratio, hidden_before_[i], area_below(pieces_[i], o_.coverage_min_ratio),
                   o_.area_ratio_low, area_below(pieces_[i], o_.area_ratio_low), spots[i].faces, spots[i].steps, spots[i].regions, spots[i].summed_steps, spots[i].seconds, room_[i]);
  }

 private:
  double area_below(const std::vector<int>& faces, double ratio) const {
    return flat_detail::area_below(s_, emb_, area3_, scale_, faces, ratio);
  }
  const Surface& s_;
  const Embedding& emb_;
  const std::vector<double>& area3_;
  double scale_;
  const FlattenOptions& o_;
  std::vector<std::vector<int>> pieces_;  // a copy: the pieces are moved into their tasks
  std::vector<double> hidden_before_, room_;  // room: the piece's map area at the band's scale / its 3D area
};

}  // namespace

AreaCorrection correct_area(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                            const std::vector<char>& fixed, const std::vector<char>& degenerate, bool local,
                            const FlattenOptions& o, bool grow, const std::function<bool()>& enough,
                            const std::vector<int>* vertex_order, CorrectionTimes* times) {
  AreaCorrection res;
  if (o.area_correction_iterations <= 0 || s.t.empty()) return res;
  std::vector<double> area3, area2;
  const double scale = band_areas(s, emb, degenerate, area3, area2);
  std::vector<char> free_vertex;
  std::vector<int> faces = correction_faces(s, vf, area2, area3, fixed, degenerate, scale, o, local, grow, free_vertex);
  res.faces = faces.size();
  if (!local) {
    minimise(s, emb, std::move(faces), free_vertex, area3, scale, o, false, res, enough, nullptr, vertex_order, times);
    return res;
  }
  // The pieces side by side: each reads and moves only its own vertices (pieces share none), and
  // their results are combined in piece order, so the map is the same for any thread count.
  std::vector<std::vector<int>> pieces = connected_pieces(s, faces);
  if (grow) {
    keep_pieces_hiding_wall(s, emb, area3, scale, o.coverage_min_ratio, pieces);
    res.faces = 0;
    for (const std::vector<int>& p : pieces) res.faces += p.size();
  }
  std::vector<AreaCorrection> part(pieces.size());
  std::vector<SpotWork> spots(pieces.size());
  std::vector<CorrectionTimes> part_times(times ? pieces.size() : 0);
  std::unique_ptr<PieceLog> log = times ? std::make_unique<PieceLog>(s, emb, area3, scale, o, pieces) : nullptr;
  std::vector<V2> trial(emb.pos.size());  // one trial buffer for all pieces: each writes only its own vertices
  std::vector<std::function<void()>> tasks;
  const std::vector<std::size_t> order = most_work_first(pieces, o.area_correction_iterations);
  std::vector<std::size_t> place(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) place[order[k]] = k;
  for (std::size_t i : order)
    tasks.push_back([&, i] {
      spots[i] = correct_piece(s, vf, emb, pieces[i], free_vertex, area3, scale, o, grow, part[i], &trial,
                               times ? &part_times[i] : nullptr);
    });
  parallel_tasks(tasks);
  for (const AreaCorrection& p : part) {
    res.energy_before += p.energy_before, res.energy_after += p.energy_after;
    if (p.iterations >= res.iterations) res.iterations = p.iterations, res.stop = p.stop;
  }
  if (times) combine_times(part_times, place, *times);
  if (log) log->print(part, part_times, place, spots);
  return res;
}

}  // namespace cf::flat_detail
