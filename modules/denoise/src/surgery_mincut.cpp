// Minimum-cut caps (step 7f of the Surgery, surgery_steps.h; issue 26, session 31).
//
// A loop whose disk has to weave round walls (the raw CT mask's sieve loop: its two halves on two
// walls, a tissue plate across its disk) has no cap that is a height field over a plane or a
// relaxed minimal surface. Its disk is found in free space instead: with both rings where the loop
// was, the surface's faces in a box around the loop are told apart by the ring they are reached
// from first (a breadth-first flood over the cut surface, inside the box), and the free cells
// next to the left side's faces are separated from those next to the right side's by a minimum
// cut (free_space_cut.h). The piece of the cut that is a disk with its boundary along the loop
// becomes both caps: its vertices moved a fraction of a cell to each ring's side (along their
// normals, towards the right side for the right cap), each joined to its ring by a strip.
// Both caps are checked on the guard grid and against each other before anything is added (as
// the front caps are): a failure leaves nothing behind, and the concentric caps follow.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <unordered_map>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/face_grid.h"
#include "colonflat/denoise/free_space_cut.h"
#include "denoise_debug.h"
#include "free_space_disks.h"
#include "surgery_steps.h"
#include "triangle_hash.h"

namespace cf::detail {

namespace {
// mm of free space around the loop's bounding box: room for a disk that bulges off the loop's
// plane to pass round a plate or through a gap beside it.
constexpr double kBoxMargin = 1.5;
// Cells of the box at most (about 40 bytes of graph per cell): beyond, the cells are made larger.
constexpr double kMaxCells = 4.0e6;
// A disk's boundary must stay this close to the loop: 2 cells (the free cells next to the faces
// at the loop) plus 2 mean loop edges (how far the staircase walls there can lie from the loop).
constexpr double kGapCells = 2.0, kGapEdges = 2.0;
// Rounds of taking the squares a strip crosses off the disk (mincut_caps()), over all placements
// of one loop: on the real CT surface, with these caps tried in a loop's first cut (not kept), a
// loop whose strips never came clean ran 16 rounds in each of the 36 placements (90 s, load 10).
constexpr int kPeelRounds = 16;
// Wall widening at a disk's holes (surgery_mincut_widen.cpp): rounds of moves and cuts, and the
// moves tried in a round (fractions of SurgeryOptions::mincut_widen), largest first.
constexpr int kWidenRounds = 3;
constexpr double kWidenShifts[] = {1.0, 2.0 / 3.0, 1.0 / 3.0};
// Crossing pairs among the caps' triangles gathered per round (their squares are peeled).
constexpr std::size_t kMaxPairs = 64;
// The placements tried, in order: ring pull, right cap's offset and left cap's (cells, along the
// normals), rim smoothing passes. The first passed the stepped-gap washer (test), the later ones
// the folds seen on the raw CT mask's loop 91 (a smoothed concave rim corner folding over a square,
// a left cap offset into a wall).
struct MincutPlacement {
  double pull, right, left;
  int rim;
};
std::vector<MincutPlacement> mincut_placements(double ring_pull) {
  std::vector<MincutPlacement> out;
  for (double pull : {ring_pull, 0.4})
    for (int rim : {3, 1, 0})
      for (double shift : {0.25, 0.125, 0.45})
        for (double left : {-shift, 0.0}) out.push_back({pull, shift, left, rim});
  return out;
}

struct Bounds {
  Vec3 lo, hi;
  bool meets(const Bounds& o) const {
    for (int a = 0; a < 3; ++a)
      if (o.lo[a] > hi[a] || o.hi[a] < lo[a]) return false;
    return true;
  }
};

Bounds bounds(const std::array<Vec3, 3>& p) {
  Bounds b{p[0], p[0]};
  for (int i = 1; i < 3; ++i) b.lo.minimize(p[i]), b.hi.maximize(p[i]);
  return b;
}

// Up to `most` pairs of `tris` (mesh vertex ids, not in the mesh) that intersect improperly (one
// per later triangle; hash cells of `cell` mm).
std::vector<std::pair<int, int>> crossings(const Mesh& mesh, const std::vector<std::array<int, 3>>& tris, double cell,
                                           std::size_t most) {
  TriangleHash hash(mesh, cell);
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : tris) {
    const int u = hash.crossing(t);
    if (u >= 0) pairs.emplace_back(u, static_cast<int>(hash.size()));
    if (pairs.size() >= most) break;
    hash.insert(t);
  }
  return pairs;
}
}  // namespace

// The box: the loop's bounding box grown by kBoxMargin, in cells of opts_.mincut_cell (larger
// when there would be more than kMaxCells).
FreeSpaceBox Surgery::mincut_box() const {
  Vec3 lo = original_[0], hi = original_[0];
  for (const auto& p : original_) lo.minimize(p), hi.maximize(p);
  const Vec3 margin(kBoxMargin, kBoxMargin, kBoxMargin);
  lo -= margin;
  hi += margin;
  const Vec3 size = hi - lo;
  FreeSpaceBox box;
  box.lo = lo;
  box.cell = std::max(opts_.mincut_cell, std::cbrt(size[0] * size[1] * size[2] / kMaxCells));
  for (int a = 0; a < 3; ++a) box.n[a] = std::max(1, static_cast<int>(std::ceil(size[a] / box.cell)));
  return box;
}

// The faces whose bounding boxes meet the box, each with the side it is reached from first by a
// breadth-first flood over faces inside the box: 2 from the right ring, 1 from the left (0: not
// reached). Both rings must be where the loop was. *ids (when given) receives each one's mesh face id.
std::vector<SidedTriangle> Surgery::sided_faces(const FreeSpaceBox& box, std::vector<int>* ids) const {
  const Bounds region{box.lo, box.lo + box.cell * Vec3(box.n[0], box.n[1], box.n[2])};
  std::vector<int> local(mesh_.n_faces(), -1);
  std::vector<SidedTriangle> out;
  if (ids) ids->clear();
  for (auto f : mesh_.faces()) {
    std::array<Vec3, 3> p;
    int i = 0;
    for (auto v : mesh_.fv_range(f)) p[i++] = mesh_.point(v);
    if (!bounds(p).meets(region)) continue;
    local[f.idx()] = static_cast<int>(out.size());
    out.push_back({p, 0});
    if (ids) ids->push_back(f.idx());
  }
  std::deque<Mesh::FaceHandle> queue;
  for (const auto& [ring, side] : {std::pair{&result_.right_ring, 2}, std::pair{&result_.left_ring, 1}})
    for (auto v : *ring)
      for (auto f : mesh_.vf_range(v))
        if (local[f.idx()] >= 0 && out[local[f.idx()]].side == 0) {
          out[local[f.idx()]].side = side;
          queue.push_back(f);
        }
  flood_sides(local, &queue, &out);
  // Faces the rings' flood did not reach (other components, or walls joined to the rings only
  // outside the box): one obstacle per group of faces joined inside the box (sides 3, 4, ...).
  int obstacle = 3;
  for (auto f : mesh_.faces())
    if (local[f.idx()] >= 0 && out[local[f.idx()]].side == 0) {
      out[local[f.idx()]].side = obstacle++;
      queue.push_back(f);
      flood_sides(local, &queue, &out);
    }
  return out;
}

// Spreads the sides of the faces in `queue` to the unsided faces they border inside the box
// (`local`: a face's index in *out, -1 outside the box), breadth first.
void Surgery::flood_sides(const std::vector<int>& local, std::deque<Mesh::FaceHandle>* queue,
                          std::vector<SidedTriangle>* out) const {
  while (!queue->empty()) {
    const auto f = queue->front();
    queue->pop_front();
    for (auto g : mesh_.ff_range(f))
      if (local[g.idx()] >= 0 && (*out)[local[g.idx()]].side == 0) {
        (*out)[local[g.idx()]].side = (*out)[local[f.idx()]].side;
        queue->push_back(g);
      }
  }
}

// The disk whose boundary stays near the loop (kGapCells, kGapEdges), the smallest one when
// several do; null when none does.
const CutDisk* Surgery::ring_disk(const std::vector<CutDisk>& disks, double cell) const {
  double radius = 0, edge = 0;
  loop_radius_and_edge(original_, &radius, &edge);
  const double limit = kGapCells * cell + kGapEdges * edge;
  const CutDisk* best = nullptr;
  for (const auto& d : disks) {
    double gap = 0;
    Vec3 far(0, 0, 0);
    for (int v : d.boundary) {
      double near = 1e300;
      for (const auto& p : original_) near = std::min(near, (d.points[v] - p).norm());
      if (near > gap) gap = near, far = d.points[v];
    }
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: mincut k=%zu: disk of %zu squares, %zu holes, boundary %zu vertices up to %.2f mm off the loop "
                   "(at %.2f, %.2f, %.2f)\n", k_, d.quads.size(), d.holes.size(), d.boundary.size(), gap, far[0], far[1], far[2]);
    if (gap <= limit && (!best || d.quads.size() < best->quads.size())) best = &d;
  }
  return best;
}

// True when the disk's boundary runs round the loop in the loop's direction (the nearest loop
// vertex's index mostly increases along it).
bool Surgery::disk_runs_with_loop(const CutDisk& disk) const {
  std::vector<long> nearest;
  for (int v : disk.boundary) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < k_; ++i)
      if ((disk.points[v] - original_[i]).sqrnorm() < (disk.points[v] - original_[best]).sqrnorm()) best = i;
    nearest.push_back(static_cast<long>(best));
  }
  long turn = 0;
  const long k = static_cast<long>(k_);
  for (std::size_t j = 0; j < nearest.size(); ++j) {
    long step = (nearest[(j + 1) % nearest.size()] - nearest[j] + k) % k;
    if (step > k / 2) step -= k;
    turn += step;
  }
  return turn > 0;
}

// The disk's points with its boundary's staircase smoothed (`passes` passes of a (1, 2, 1) / 4
// average along the boundary; inner points unchanged): the strips then join a rim without the
// lattice's one-cell bays, over which a strip would pass the other cap's squares.
static std::vector<Vec3> smoothed_rim(const CutDisk& disk, int passes) {
  std::vector<Vec3> p = disk.points;
  const std::size_t m = disk.boundary.size();
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<Vec3> q = p;
    for (std::size_t j = 0; j < m; ++j)
      q[disk.boundary[j]] = (p[disk.boundary[(j + m - 1) % m]] + 2.0 * p[disk.boundary[j]] + p[disk.boundary[(j + 1) % m]]) / 4.0;
    p.swap(q);
  }
  return p;
}

// The right cap's disk: its points moved `shift` mm along their normals and added to the mesh
// (inner[i]: point i), the squares as two triangles each, oriented like the ring's hole, then the
// holes' fills (the strip to the ring is added by join_mincut_rims()).
Surgery::FrontCap Surgery::mincut_cap(const CutDisk& disk, double shift, int rim_passes, bool flip) {
  FrontCap cap;
  std::vector<int> id(disk.points.size());
  const std::vector<Vec3> points = smoothed_rim(disk, rim_passes);
  for (std::size_t i = 0; i < disk.points.size(); ++i) {
    cap.inner.push_back(mesh_.add_vertex(points[i] + shift * disk.normals[i]));
    id[i] = cap.inner.back().idx();
  }
  for (const auto& q : disk.quads)
    for (std::array<int, 3> t : {std::array<int, 3>{id[q[0]], id[q[1]], id[q[2]]}, std::array<int, 3>{id[q[0]], id[q[2]], id[q[3]]}}) {
      if (flip) std::swap(t[1], t[2]);
      cap.tris.push_back(t);
    }
  return cap;
}

// The left cap's disk as the right one's mirror (the same squares on copies of the disk's points
// moved `shift` mm along their normals, reversed), so the two disks run side by side; its holes
// are closed on its own points (a mirrored fill met the surface where the right one did not).
// Empty when a hole has no clean fill.
Surgery::FrontCap Surgery::mincut_mirror(const CutDisk& disk, const FrontCap& right, double shift, int rim_passes,
                                         bool flip) {
  FrontCap cap;
  const std::vector<Vec3> points = smoothed_rim(disk, rim_passes);
  std::unordered_map<int, int> mirror;
  std::vector<int> id(disk.points.size());
  for (std::size_t i = 0; i < right.inner.size(); ++i) {
    cap.inner.push_back(mesh_.add_vertex(points[i] + shift * disk.normals[i]));
    mirror[right.inner[i].idx()] = id[i] = cap.inner.back().idx();
  }
  for (std::size_t t = 0; t < 2 * disk.quads.size(); ++t)
    cap.tris.push_back({mirror.at(right.tris[t][0]), mirror.at(right.tris[t][2]), mirror.at(right.tris[t][1])});
  return cap;
}

// Puts each ring's strip (mincut_strips()) in front of its cap's disk triangles; false when no
// strip pair is clean.
bool Surgery::join_mincut_rims(const CutDisk& disk, bool flip, double cell, FrontCap* right, FrontCap* left,
                               std::vector<int>* disk_hits) const {
  std::unordered_map<int, int> mirror;
  for (std::size_t i = 0; i < k_; ++i) mirror[result_.right_ring[i].idx()] = result_.left_ring[i].idx();
  for (std::size_t i = 0; i < right->inner.size(); ++i) mirror[right->inner[i].idx()] = left->inner[i].idx();
  std::vector<int> inner;
  for (int v : disk.boundary) inner.push_back(right->inner[v].idx());
  if (flip) std::reverse(inner.begin(), inner.end());
  TriangleHash disks(mesh_, 2 * cell);
  for (const auto* cap : {right, left})
    for (const auto& t : cap->tris) disks.insert(t);
  std::vector<std::array<int, 3>> right_strip, left_strip;
  if (!mincut_strips(inner, mirror, disks, cell, &right_strip, &left_strip, disk_hits)) return false;
  right->tris.insert(right->tris.begin(), right_strip.begin(), right_strip.end());
  left->tris.insert(left->tris.begin(), left_strip.begin(), left_strip.end());
  return true;
}

// The triangles that close the disk's holes (a triangulation of a hole's rim has two fewer).
static std::size_t fill_count(const CutDisk& disk) {
  std::size_t n = 0;
  for (const auto& rim : disk.holes) n += rim.size() - 2;
  return n;
}

// The disk without the squares `hits` names (indices in the right cap's triangles then the left's,
// `right_tris` of them the right's: squares first, two triangles each), as the largest disk its
// other squares form; false when they form none.
static bool peeled(const CutDisk& disk, const std::vector<int>& hits, std::size_t right_tris, CutDisk* out) {
  std::vector<char> drop(disk.quads.size(), 0);
  for (int u : hits) {
    const std::size_t t = std::size_t(u) < right_tris ? std::size_t(u) : std::size_t(u) - right_tris;
    if (t < 2 * disk.quads.size()) drop[t / 2] = 1;
  }
  std::vector<std::array<long long, 4>> squares;
  for (std::size_t q = 0; q < disk.quads.size(); ++q)
    if (!drop[q]) squares.push_back({disk.quads[q][0], disk.quads[q][1], disk.quads[q][2], disk.quads[q][3]});
  if (squares.size() == disk.quads.size()) return false;
  std::size_t pieces = 0;
  std::vector<CutDisk> disks = cut_disks(squares, [&disk](long long v) { return disk.points[v]; }, &pieces);
  if (disks.empty()) return false;
  *out = *std::max_element(disks.begin(), disks.end(), [](const CutDisk& a, const CutDisk& b) { return a.quads.size() < b.quads.size(); });
  return true;
}

// Both caps (mincut_caps_once()); where a strip or a hole's fill crosses a square of the disk, the
// disk loses those squares (near the rim: its rim lay beyond a ring, which is then on the other
// cap's side) and the caps are made again, while the loop's peel_rounds_left_ last.
bool Surgery::mincut_caps(const CutDisk& disk, double shift, double left_shift, int rim_passes, double cell) {
  CutDisk d = disk;
  for (;;) {
    std::vector<int> hits;
    if (mincut_caps_once(d, shift, left_shift, rim_passes, cell, &hits)) return true;
    if (hits.empty() || peel_rounds_left_ <= 0) return false;
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: mincut k=%zu: peel (%d left): %zu squares, %zu crossed\n", k_, peel_rounds_left_,
                   d.quads.size(), hits.size());
    --peel_rounds_left_;
    CutDisk next;
    if (!peeled(d, hits, 2 * d.quads.size() + fill_count(d), &next)) return false;
    d = std::move(next);
  }
}

// Both caps `shift` mm off the cut (the right one towards the right side); kept when neither
// meets a grid face nor the other cap nor itself, otherwise the vertices they added are removed.
bool Surgery::mincut_caps_once(const CutDisk& disk, double shift, double left_shift, int rim_passes, double cell,
                               std::vector<int>* disk_hits) {
  const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
  const bool flip = !disk_runs_with_loop(disk);
  FrontCap right = mincut_cap(disk, shift, rim_passes, flip);
  FrontCap left = mincut_mirror(disk, right, left_shift, rim_passes, flip);
  if (!close_mincut_holes(disk, flip, cell, &right, &left)) {
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f mm: a hole has no clean fill\n", k_, shift);
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  const std::size_t right_disk = right.tris.size();
  if (!join_mincut_rims(disk, flip, cell, &right, &left, disk_hits)) {
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f / %.3f mm, rim %d: no clean strip\n", k_, shift, left_shift, rim_passes);
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  std::vector<std::array<int, 3>> all = right.tris;
  all.insert(all.end(), left.tris.begin(), left.tris.end());
  bool clean = true;
  std::size_t t = 0;
  for (; t < all.size() && clean; ++t) clean = !opts_.guard->hits(mesh_, all[t]);
  const auto pairs = clean ? crossings(mesh_, all, 2 * cell, kMaxPairs) : std::vector<std::pair<int, int>>{};
  if (denoise_debug() && (!clean || !pairs.empty()))
    std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f / %.3f mm, rim %d: %s (triangle %zu, %zu pairs, first %d %d of %zu + %zu)\n",
                 k_, shift, left_shift, rim_passes, clean ? "the caps cross" : "a cap triangle hits the surface", t - 1, pairs.size(),
                 pairs.empty() ? -1 : pairs[0].first, pairs.empty() ? -1 : pairs[0].second, right.tris.size(), left.tris.size());
  if (denoise_debug() && !clean) {
    Vec3 c(0, 0, 0);
    for (int v : all[t - 1]) c += mesh_.point(Mesh::VertexHandle(v)) / 3.0;
    std::fprintf(stderr, "denoise debug: mincut k=%zu: the triangle hitting the surface is at (%.2f, %.2f, %.2f)\n", k_, c[0], c[1], c[2]);
  }
  const std::size_t strip = right.tris.size() - right_disk;
  for (const auto& [a, b] : pairs)
    for (int x : {a, b}) {  // the squares among the crossing triangles, as peeled() counts them
      const long i = x - long(strip), j = x - long(right.tris.size() + strip);
      if (i >= 0 && i < long(2 * disk.quads.size())) disk_hits->push_back(int(i));
      if (j >= 0 && j < long(2 * disk.quads.size())) disk_hits->push_back(int(right_disk + j));
    }
  clean = clean && pairs.empty();
  if (!clean) {
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  add_ordered(right.tris);
  add_ordered(left.tris);
  finish_caps_with_interior(right.inner, left.inner);
  return true;
}

// Adds a cap's triangles (strip first, then the disk from its boundary inwards) to the mesh and
// the guard; a triangle OpenMesh refuses at its turn (it would touch the patch at a vertex only)
// is retried after the others.
void Surgery::add_ordered(const std::vector<std::array<int, 3>>& tris) {
  std::vector<std::array<int, 3>> pending = tris, later;
  while (!pending.empty()) {
    later.clear();
    for (const auto& t : pending) {
      const auto f = mesh_.add_face(Mesh::VertexHandle(t[0]), Mesh::VertexHandle(t[1]), Mesh::VertexHandle(t[2]));
      if (f.is_valid()) opts_.guard->insert(mesh_, f);
      else later.push_back(t);
    }
    if (later.size() == pending.size()) throw Error("surgery (mincut): could not add a cap triangle");
    pending.swap(later);
  }
}

// 7f. Minimum-cut caps (opts_.mincut, with a guard): the free-space cut with the rings where the
//     loop was, then both caps at a quarter and an eighth of a cell off it, rings in their first
//     placement. True when they were added (cap kind "mincut").
bool Surgery::try_mincut_caps() {
  if (!opts_.mincut || !opts_.guard || opts_.trial) return false;
  Stopwatch sw;
  place_rings(0.0, target_left_, target_right_);
  const FreeSpaceBox box = mincut_box();
  FreeSpaceCutStats st;
  std::vector<int> ids;
  std::vector<SidedTriangle> sided = sided_faces(box, &ids);
  const std::vector<CutDisk> disks = free_space_cut(box, sided, &st);
  const CutDisk* disk = ring_disk(disks, box.cell);
  const double t_cut = sw.seconds();
  double used = 0;
  bool hole_free = false;  // widening gave a disk without holes (its placements were tried)
  if (disk && !disk->holes.empty() && opts_.mincut_widen > 0) used = widened_mincut_caps(*disk, box, sided, ids, &hole_free);
  if (used == 0 && disk && !hole_free) used = place_mincut_caps(*disk, box);
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: mincut k=%zu: %d x %d x %d cells of %.3f mm, %zu free (%zu source, %zu sink), flow %lld, "
                 "%zu squares in %zu pieces, %zu disks: %s (offset %.3f cell); cut %.2f s, caps %.2f s\n", k_, box.n[0], box.n[1],
                 box.n[2], box.cell, st.free, st.sources, st.sinks, st.flow, st.squares, st.pieces, st.disks,
                 used > 0 ? "clean" : disk ? "failed" : "no disk", used, t_cut, sw.seconds() - t_cut);
  if (used > 0) cap_kind_ = "mincut";
  return used > 0;
}

// The placements (mincut_placements) of caps from `disk`, in order, until one is clean; the right
// cap's offset (cells) of the one kept, 0 when none was.
double Surgery::place_mincut_caps(const CutDisk& disk, const FreeSpaceBox& box) {
  double placed_pull = -1;
  peel_rounds_left_ = kPeelRounds;
  for (const MincutPlacement& pl : mincut_placements(opts_.ring_pull)) {
    if (pl.pull != placed_pull) {
      place_rings(pl.pull, target_left_, target_right_);
      placed_pull = pl.pull;
      const std::vector<Mesh::FaceHandle> around = faces_around_rings();
      for (auto f : around) opts_.guard->insert(mesh_, f);
      if (new_pairs(around, 1) > 0) continue;
    }
    if (mincut_caps(disk, pl.right * box.cell, pl.left * box.cell, pl.rim, box.cell)) return pl.right;
  }
  return 0;
}

// A disk with holes: the walls moved apart at its holes (surgery_mincut_widen.cpp) by the first of
// kWidenShifts that moves them cleanly, the cut made again, up to kWidenRounds times while the
// disk keeps holes; then, when it has none (*hole_free), its placements. Without clean caps every
// move is put back (0 returned); the caller then tries the first disk only when no hole-free one
// was tried (on the raw CT mask's loop 91 both fail, and trying both doubled the caps' time).
double Surgery::widened_mincut_caps(const CutDisk& first, const FreeSpaceBox& box, std::vector<SidedTriangle> sided,
                                    std::vector<int> ids, bool* hole_free) {
  std::vector<std::pair<Mesh::VertexHandle, Vec3>> before;
  double largest = 0;
  std::vector<CutDisk> disks{first};
  const CutDisk* disk = &disks[0];
  for (int round = 0; round < kWidenRounds && disk && !disk->holes.empty(); ++round) {
    bool moved = false;
    for (double shift : kWidenShifts)
      if (!moved) moved = widen_at_holes(*disk, sided, ids, shift * opts_.mincut_widen * box.cell, &before, &largest);
    if (!moved) break;
    FreeSpaceCutStats st;
    sided = sided_faces(box, &ids);
    disks = free_space_cut(box, sided, &st);
    disk = ring_disk(disks, box.cell);
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: mincut k=%zu: walls moved apart at the holes (%zu vertices, up to %.3f mm): flow %lld, "
                   "%s with %zu holes\n", k_, before.size(), largest, st.flow, disk ? "a disk" : "no disk",
                   disk ? disk->holes.size() : std::size_t{0});
  }
  *hole_free = disk && disk->holes.empty();
  const double used = *hole_free ? place_mincut_caps(*disk, box) : 0;
  if (used == 0) {
    set_points(before);
    return 0;
  }
  result_.widened = largest;
  result_.undo.positions.insert(result_.undo.positions.end(), before.begin(), before.end());
  return used;
}

}  // namespace cf::detail
