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
#include "surgery_steps.h"

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

std::array<Vec3, 3> triangle_points(const Mesh& mesh, const std::array<int, 3>& t) {
  return {mesh.point(Mesh::VertexHandle(t[0])), mesh.point(Mesh::VertexHandle(t[1])), mesh.point(Mesh::VertexHandle(t[2]))};
}

// True when two of `tris` (mesh vertex ids, not in the mesh) intersect improperly: a hash of
// their bounding boxes in cells of `cell` mm, each pair tested once.
bool any_crossing(const Mesh& mesh, const std::vector<std::array<int, 3>>& tris, double cell, std::pair<int, int>* pair) {
  std::unordered_map<long long, std::vector<int>> grid;
  std::vector<int> stamp(tris.size(), -1);
  auto key = [cell](const Vec3& p, int a) { return static_cast<long long>(std::floor(p[a] / cell)); };
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const auto p = triangle_points(mesh, tris[t]);
    const Bounds b = bounds(p);
    for (long long z = key(b.lo, 2); z <= key(b.hi, 2); ++z)
      for (long long y = key(b.lo, 1); y <= key(b.hi, 1); ++y)
        for (long long x = key(b.lo, 0); x <= key(b.hi, 0); ++x) {
          auto& cellfaces = grid[(x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL)];
          for (int u : cellfaces) {
            if (stamp[u] == int(t)) continue;
            stamp[u] = int(t);
            const auto q = triangle_points(mesh, tris[u]);
            if (bounds(q).meets(b) && triangles_intersect_improperly(tris[t], p, tris[u], q)) {
              *pair = {u, int(t)};
              return true;
            }
          }
          cellfaces.push_back(int(t));
        }
  }
  return false;
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
// reached). Both rings must be where the loop was.
std::vector<SidedTriangle> Surgery::sided_faces(const FreeSpaceBox& box) const {
  const Bounds region{box.lo, box.lo + box.cell * Vec3(box.n[0], box.n[1], box.n[2])};
  std::vector<int> local(mesh_.n_faces(), -1);
  std::vector<SidedTriangle> out;
  for (auto f : mesh_.faces()) {
    std::array<Vec3, 3> p;
    int i = 0;
    for (auto v : mesh_.fv_range(f)) p[i++] = mesh_.point(v);
    if (!bounds(p).meets(region)) continue;
    local[f.idx()] = static_cast<int>(out.size());
    out.push_back({p, 0});
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
    for (int v : d.boundary) {
      double near = 1e300;
      for (const auto& p : original_) near = std::min(near, (d.points[v] - p).norm());
      gap = std::max(gap, near);
    }
    if (denoise_debug())
      std::fprintf(stderr, "denoise debug: mincut k=%zu: disk of %zu squares, boundary %zu vertices up to %.2f mm off the loop\n",
                   k_, d.quads.size(), d.boundary.size(), gap);
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

// The strip between `ring` (mesh vertices, loop order) and `inner` (the disk's boundary, loop
// direction), oriented like the ring: the least-area one that joins ring[0] to the inner vertex
// nearest it and advances along one side per triangle (contour tiling by dynamic programming; a
// greedy shorter-diagonal rule folded where the lattice boundary zigzags).
void Surgery::mincut_strip(const std::vector<Mesh::VertexHandle>& ring, const std::vector<int>& inner,
                           std::vector<std::array<int, 3>>* tris) const {
  const std::size_t k = ring.size(), m = inner.size();
  auto at = [this](int v) { return mesh_.point(Mesh::VertexHandle(v)); };
  std::size_t j0 = 0;
  for (std::size_t j = 1; j < m; ++j)
    if ((at(inner[j]) - mesh_.point(ring[0])).sqrnorm() < (at(inner[j0]) - mesh_.point(ring[0])).sqrnorm()) j0 = j;
  auto r = [&](std::size_t i) { return ring[i % k].idx(); };
  auto b = [&](std::size_t j) { return inner[(j0 + j) % m]; };
  auto area = [&](int x, int y, int z) { return OpenMesh::cross(at(y) - at(x), at(z) - at(x)).norm(); };
  const std::size_t w = m + 1;
  std::vector<double> cost((k + 1) * w, 1e300);
  std::vector<char> along_ring((k + 1) * w, 0);
  cost[0] = 0;
  for (std::size_t i = 0; i <= k; ++i)
    for (std::size_t j = 0; j <= m; ++j) {
      double& c = cost[i * w + j];
      if (i > 0 && cost[(i - 1) * w + j] + area(r(i - 1), r(i), b(j)) < c) {
        c = cost[(i - 1) * w + j] + area(r(i - 1), r(i), b(j));
        along_ring[i * w + j] = 1;
      }
      if (j > 0 && cost[i * w + j - 1] + area(r(i), b(j), b(j - 1)) < c) {
        c = cost[i * w + j - 1] + area(r(i), b(j), b(j - 1));
        along_ring[i * w + j] = 0;
      }
    }
  std::vector<std::array<int, 3>> back;
  for (std::size_t i = k, j = m; i > 0 || j > 0;) {
    if (along_ring[i * w + j]) back.push_back({r(i - 1), r(i), b(j)}), --i;
    else back.push_back({r(i), b(j), b(j - 1)}), --j;
  }
  tris->insert(tris->end(), back.rbegin(), back.rend());
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

// The right cap from the disk: its points moved `shift` mm along their normals and added to the
// mesh, the strip to the right ring, then the disk's squares as two triangles each, oriented like
// the ring's hole.
Surgery::FrontCap Surgery::mincut_cap(const CutDisk& disk, double shift, int rim_passes, bool flip) {
  FrontCap cap;
  std::vector<int> id(disk.points.size());
  const std::vector<Vec3> points = smoothed_rim(disk, rim_passes);
  for (std::size_t i = 0; i < disk.points.size(); ++i) {
    cap.inner.push_back(mesh_.add_vertex(points[i] + shift * disk.normals[i]));
    id[i] = cap.inner.back().idx();
  }
  std::vector<int> inner;
  for (int v : disk.boundary) inner.push_back(id[v]);
  if (flip) std::reverse(inner.begin(), inner.end());
  mincut_strip(result_.right_ring, inner, &cap.tris);
  for (const auto& q : disk.quads)
    for (std::array<int, 3> t : {std::array<int, 3>{id[q[0]], id[q[1]], id[q[2]]}, std::array<int, 3>{id[q[0]], id[q[2]], id[q[3]]}}) {
      if (flip) std::swap(t[1], t[2]);
      cap.tris.push_back(t);
    }
  for (const auto& rim : disk.holes)
    if (!close_hole(rim, id, flip, &cap.tris)) return FrontCap{};
  return cap;
}

// Closes a hole of the disk (rim: disk point ids in the squares' direction; id: their mesh ids)
// with the least-area triangulation of its rim whose triangles meet no grid face (cap_triangulation.h);
// false when there is none.
bool Surgery::close_hole(const std::vector<int>& rim, const std::vector<int>& id, bool flip,
                         std::vector<std::array<int, 3>>* tris) const {
  std::vector<Mesh::VertexHandle> ring;  // the hole's boundary as the fill sees it: against the squares
  for (auto it = rim.rbegin(); it != rim.rend(); ++it) ring.push_back(Mesh::VertexHandle(id[*it]));
  if (flip) std::reverse(ring.begin(), ring.end());
  auto none = [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; };
  const std::vector<std::array<int, 3>> fill = triangulate_ring(mesh_, ring, none, opts_.guard);
  tris->insert(tris->end(), fill.begin(), fill.end());
  return !fill.empty();
}

// The left cap as the right one's mirror (the same strip and squares on the left ring and on
// copies of the disk's points moved `shift` mm along their normals, reversed), so the two strips
// and disks run side by side; its holes are closed on its own points (a mirrored fill met the
// surface where the right one did not). Empty when a hole has no clean fill.
Surgery::FrontCap Surgery::mincut_mirror(const CutDisk& disk, const FrontCap& right, double shift, int rim_passes,
                                         bool flip) {
  FrontCap cap;
  const std::vector<Vec3> points = smoothed_rim(disk, rim_passes);
  std::unordered_map<int, int> mirror;
  std::vector<int> id(disk.points.size());
  for (std::size_t i = 0; i < k_; ++i) mirror[result_.right_ring[i].idx()] = result_.left_ring[i].idx();
  for (std::size_t i = 0; i < right.inner.size(); ++i) {
    cap.inner.push_back(mesh_.add_vertex(points[i] + shift * disk.normals[i]));
    mirror[right.inner[i].idx()] = id[i] = cap.inner.back().idx();
  }
  std::size_t fills = 0;
  for (const auto& rim : disk.holes) fills += rim.size() - 2;
  for (std::size_t t = 0; t + fills < right.tris.size(); ++t)
    cap.tris.push_back({mirror.at(right.tris[t][0]), mirror.at(right.tris[t][2]), mirror.at(right.tris[t][1])});
  for (const auto& rim : disk.holes)
    if (!close_hole(rim, id, !flip, &cap.tris)) return FrontCap{};
  return cap;
}

// Both caps `shift` mm off the cut (the right one towards the right side); kept when neither
// meets a grid face nor the other cap nor itself, otherwise the vertices they added are removed.
bool Surgery::mincut_caps(const CutDisk& disk, double shift, double left_shift, int rim_passes, double cell) {
  const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
  const bool flip = !disk_runs_with_loop(disk);
  const FrontCap right = mincut_cap(disk, shift, rim_passes, flip);
  if (right.tris.empty()) {  // a hole without a clean fill
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f mm: a hole has no clean fill\n", k_, shift);
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  const FrontCap left = mincut_mirror(disk, right, left_shift, rim_passes, flip);
  if (left.tris.empty()) {
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f mm: a left hole has no clean fill\n", k_, shift);
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  std::vector<std::array<int, 3>> all = right.tris;
  all.insert(all.end(), left.tris.begin(), left.tris.end());
  bool clean = true;
  std::size_t t = 0;
  for (; t < all.size() && clean; ++t) clean = !opts_.guard->hits(mesh_, all[t]);
  std::pair<int, int> pair{-1, -1};
  const bool crossing = clean && any_crossing(mesh_, all, 2 * cell, &pair);
  if (denoise_debug() && (!clean || crossing))
    std::fprintf(stderr, "denoise debug: mincut k=%zu: offset %.3f / %.3f mm, rim %d: %s (triangle %zu, pair %d %d of %zu + %zu)\n",
                 k_, shift, left_shift, rim_passes, crossing ? "the caps cross" : "a cap triangle hits the surface", t - 1,
                 pair.first, pair.second, right.tris.size(), left.tris.size());
  clean = clean && !crossing;
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
  const std::vector<CutDisk> disks = free_space_cut(box, sided_faces(box), &st);
  const CutDisk* disk = ring_disk(disks, box.cell);
  const double t_cut = sw.seconds();
  double used = 0;
  double placed_pull = -1;
  for (const MincutPlacement& pl : mincut_placements(opts_.ring_pull)) {
    if (!disk || used > 0) break;
    if (pl.pull != placed_pull) {
      place_rings(pl.pull, target_left_, target_right_);
      placed_pull = pl.pull;
      const std::vector<Mesh::FaceHandle> around = faces_around_rings();
      for (auto f : around) opts_.guard->insert(mesh_, f);
      if (new_pairs(around, 1) > 0) continue;
    }
    if (mincut_caps(*disk, pl.right * box.cell, pl.left * box.cell, pl.rim, box.cell)) used = pl.right;
  }
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: mincut k=%zu: %d x %d x %d cells of %.3f mm, %zu free (%zu source, %zu sink), flow %lld, "
                 "%zu squares in %zu pieces, %zu disks: %s (offset %.3f cell); cut %.2f s, caps %.2f s\n", k_, box.n[0], box.n[1],
                 box.n[2], box.cell, st.free, st.sources, st.sinks, st.flow, st.squares, st.pieces, st.disks,
                 used > 0 ? "clean" : disk ? "failed" : "no disk", used, t_cut, sw.seconds() - t_cut);
  if (used > 0) cap_kind_ = "mincut";
  return used > 0;
}

}  // namespace cf::detail
