// Front caps of cut_and_cap() (step 7c of the Surgery, surgery_steps.h).
//
// A cap without interior vertices lies along its ring's chords; where a loop runs over a wall in
// the wall's own tangent plane, that disk grazes the wall's relief next to the loop, and a collar
// (one lift, then a flat disk) still spans the relief when it is higher than the lift (issue 26).
// A front cap grows the disk from its ring inwards, layer by layer, and steers each layer away
// from the surface: every front vertex moves one mean ring edge (less where the surface is near)
// along the direction into the front's own minimum-area disk, turned about the front's tangent
// to the first of 0, +-15, ..., +-90 degrees whose ray (on the guard grid) is free for three steps;
// the first layer must rise above both rings' tangent planes on the side the disk lies on.
// Consecutive front vertices that come closer than half a step merge, so the front shrinks. A
// layer whose strip meets something is made again with the moves there halved (3 times at
// most). After each layer the front is closed by its minimum-area triangulation when that is
// clean and the left cap mirrored from the right one is clean too: its interior vertices are the
// right cap's moved by the rings' separation (or a half, a quarter of it) along the right cap's
// normal, towards the left side; else by a relaxed disk with interior vertices
// (surgery_relaxed.cpp). A front that stalls or meets anything fails (nothing is added).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_debug.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
// Fraction of the free distance along its direction a front vertex may move in one layer: the
// front stays at least twice as far from the surface ahead as it moved, and the left cap, offset
// from the right one by the rings' separation (about half an edge), stays off the surface too.
constexpr double kStepGap = 1.0 / 3.0;
// A vertex whose free distance allows less than this fraction of a step stops the front: a
// shorter step would leave a sliver strip triangle.
constexpr double kMinStep = 0.2;
// Consecutive front vertices closer than this many steps merge (the front shrinks as it advances).
constexpr double kMergeSteps = 0.5;
// Times a layer whose strip meets something is made again with the moves there halved (down to
// 1/8 of a step: below that the strip's triangles become slivers).
constexpr int kRetries = 3;
// Layers at most: a front advancing one mean ring edge per layer crosses a loop of radius 60
// edges; a longer way means it is stuck (its vertices stop where the surface is near).
constexpr int kMaxLayers = 60;
// Turns of the inward direction about the front's tangent, in 15 degree steps up to 90 degrees
// either way (0 first: the flat disk's own direction wins when it is free).
constexpr double kTurnStep = 0.2617993877991494;
constexpr int kTurns = 6;
// The first layer leaves the ring into the side of the surface its disk lies on: its directions
// rise at least this much (sine of 6 degrees) above the tangent planes of both rings. The cut has
// opened a gap between the two rings, so a ray from a ring vertex into the other side (into the
// solid for a handle loop), or along the wall's own tangent plane, can pass through the gap and
// meet nothing.
constexpr double kMinRise = 0.1;

// Rays start this many steps out of their vertex and see every face, those around a ring vertex
// too: a ray that leaves a ring vertex into its own faces (into the solid) meets them at once.
constexpr double kRayStart = 1e-3;

Vec3 unit(const Vec3& v) {
  const double n = v.norm();
  return n > 0 ? v / n : v;
}

// How far direction d rises above both sides' tangent planes at a cut ring vertex (sides: the
// two rings' unit normals, times the side the disk lies on).
double rise(const Vec3& d, const std::array<Vec3, 2>& sides) {
  return std::min(OpenMesh::dot(d, sides[0]), OpenMesh::dot(d, sides[1]));
}

std::vector<Vec3> positions(const Mesh& mesh, const std::vector<Mesh::VertexHandle>& f) {
  std::vector<Vec3> out;
  out.reserve(f.size());
  for (auto v : f) out.push_back(mesh.point(v));
  return out;
}
}  // namespace

// Direction into the front's minimum-area disk at each vertex (the mean way to the centroids of
// its triangles in `disk`, across the front's tangent); the way to the front's centroid for a
// vertex without a triangle.
std::vector<Vec3> Surgery::front_inward(const std::vector<Mesh::VertexHandle>& f,
                                        const std::vector<std::array<int, 3>>& disk) const {
  const std::size_t n = f.size();
  const std::vector<Vec3> p = positions(mesh_, f);
  std::unordered_map<int, std::size_t> index;
  for (std::size_t i = 0; i < n; ++i) index[f[i].idx()] = i;
  std::vector<Vec3> in(n, Vec3(0, 0, 0));
  for (const auto& t : disk) {
    const Vec3 c = (mesh_.point(Mesh::VertexHandle(t[0])) + mesh_.point(Mesh::VertexHandle(t[1])) +
                    mesh_.point(Mesh::VertexHandle(t[2]))) / 3.0;
    for (int a : t) in[index.at(a)] += unit(c - mesh_.point(Mesh::VertexHandle(a)));
  }
  Vec3 centre(0, 0, 0);
  for (const auto& q : p) centre += q;
  centre /= double(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 tangent = unit(p[(i + 1) % n] - p[(i + n - 1) % n]);
    if (in[i].norm() == 0) in[i] = centre - p[i];
    in[i] = unit(in[i] - OpenMesh::dot(in[i], tangent) * tangent);
  }
  return in;
}

// Free distance from p along the unit direction d, up to step / kStepGap (every face counts).
double Surgery::front_free(const Vec3& p, const Vec3& d, double step) const {
  const double start = kRayStart * step;
  return start + opts_.guard->free_distance(mesh_, p + start * d, d, step / kStepGap - start, -1);
}

// Each front vertex's direction: its inward direction turned about the front's tangent to the
// first of 0, +-15, ..., +-60 degrees whose ray is free for 3 steps (else the freest), then
// averaged with its neighbours' (twice), so that the front does not fold where its vertices chose
// different sides.
std::vector<Vec3> Surgery::front_directions(const std::vector<Mesh::VertexHandle>& f,
                                            const std::vector<std::array<int, 3>>& disk, double step,
                                            const std::vector<Sides>& side) const {
  const std::size_t n = f.size();
  const std::vector<Vec3> p = positions(mesh_, f), in = front_inward(f, disk);
  std::vector<Vec3> dir(n);
  const double reach = step / kStepGap;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 tangent = unit(p[(i + 1) % n] - p[(i + n - 1) % n]);
    double best = -1;
    for (int k = 0; k <= 2 * kTurns && best < reach; ++k) {
      const double a = kTurnStep * double((k + 1) / 2) * (k % 2 ? 1.0 : -1.0);
      const Vec3 d = std::cos(a) * in[i] + std::sin(a) * OpenMesh::cross(tangent, in[i]);
      if (!side.empty() && rise(d, side[i]) < kMinRise) continue;
      const double free = front_free(p[i], d, step);
      if (free > best) {
        best = free;
        dir[i] = d;
      }
    }
    if (best < 0) dir[i] = unit(side[i][0] + side[i][1]);  // no turn rises enough: straight up
  }
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Vec3> next(n);
    for (std::size_t i = 0; i < n; ++i) next[i] = unit(2.0 * dir[i] + dir[(i + 1) % n] + dir[(i + n - 1) % n]);
    dir.swap(next);
  }
  for (std::size_t i = 0; i < n && !side.empty(); ++i)  // smoothing must not take the first layer under
    for (int lift = 0; lift < 8 && rise(dir[i], side[i]) < kMinRise; ++lift)
      dir[i] = unit(dir[i] + 0.25 * unit(side[i][0] + side[i][1]));
  return dir;
}

// Groups of consecutive new front positions closer than kMergeSteps x step (at least 3 groups):
// group[i] of position i, non-decreasing, the last group joined to the first when they are close.
std::vector<int> Surgery::front_groups(const std::vector<Vec3>& g, double step) {
  const std::size_t n = g.size();
  std::vector<int> group(n, 0);
  int groups = 1;
  Vec3 anchor = g[0];
  for (std::size_t i = 1; i < n; ++i) {
    const bool merge = (g[i] - anchor).norm() < kMergeSteps * step;
    if (!merge) {
      ++groups;
      anchor = g[i];
    }
    group[i] = groups - 1;
  }
  if (groups > 3 && (g[n - 1] - g[0]).norm() < kMergeSteps * step) {
    for (std::size_t i = n; i-- > 0 && group[i] == groups - 1;) group[i] = 0;
    --groups;
  }
  if (groups < 3)
    for (std::size_t i = 0; i < n; ++i) group[i] = static_cast<int>(i);
  return group;
}

// One layer: every front vertex moves along its direction by scale x a step (less where the
// surface is near; an empty result when a vertex can move less than kMinStep of it); merged groups become
// one vertex at their mean. Appends the strip (F_i, F_i+1, G_g(i+1)), and (F_i, G_g(i+1), G_g(i))
// where the group changes, to *strip; the new vertices are added to the mesh.
std::vector<Mesh::VertexHandle> Surgery::advance_front(const std::vector<Mesh::VertexHandle>& f,
                                                       const std::vector<Vec3>& dir, const std::vector<double>& scale,
                                                       double step, std::vector<std::array<int, 3>>* strip) {
  const std::size_t n = f.size();
  std::vector<Vec3> g(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p = mesh_.point(f[i]);
    const double move = std::min(step, kStepGap * front_free(p, dir[i], step));
    if (move < kMinStep * step) return {};
    g[i] = p + scale[i] * move * dir[i];
  }
  const std::vector<int> group = front_groups(g, step);
  const int groups = *std::max_element(group.begin(), group.end()) + 1;
  std::vector<Vec3> sum(groups, Vec3(0, 0, 0));
  std::vector<int> count(groups, 0);
  for (std::size_t i = 0; i < n; ++i) {
    sum[group[i]] += g[i];
    ++count[group[i]];
  }
  std::vector<Mesh::VertexHandle> next(groups);
  for (int q = 0; q < groups; ++q) next[q] = mesh_.add_vertex(sum[q] / double(count[q]));
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    strip->push_back({f[i].idx(), f[j].idx(), next[group[j]].idx()});
    if (group[i] != group[j]) strip->push_back({f[i].idx(), next[group[j]].idx(), next[group[i]].idx()});
  }
  return next;
}

// True when the triangles of `tris` from `from` on meet neither the grid's faces nor an earlier
// triangle of `tris` (nor `others`); those before `from` were checked already.
bool Surgery::clean_from(const std::vector<std::array<int, 3>>& tris, std::size_t from,
                         const std::vector<std::array<int, 3>>& others) const {
  std::vector<std::array<int, 3>> done(tris.begin(), tris.begin() + static_cast<std::ptrdiff_t>(from));
  done.insert(done.end(), others.begin(), others.end());
  for (std::size_t t = from; t < tris.size(); ++t) {
    if (opts_.guard->hits(mesh_, tris[t], done)) return false;
    done.push_back(tris[t]);
  }
  return true;
}

// Both front caps: layers from the right ring inwards until the front's minimum-area disk is
// clean (after at least one layer), or its relaxed disk with interior vertices
// (close_front_relaxed(), from the ring itself on), and so is the left cap mirrored from it
// (left_front_cap(), its offset the rings' separation, then a half and a quarter of it); the
// right cap's triangles in ear order and its interior vertices, the left one's likewise.
bool Surgery::front_cap_pair(double sign, FrontCap* right, FrontCap* left) {
  std::vector<Sides> side(k_);
  for (std::size_t i = 0; i < k_; ++i) side[i] = {sign * normal_right_[i], sign * normal_left_[i]};
  double step = 0;
  for (std::size_t i = 0; i < k_; ++i) step += (original_[(i + 1) % k_] - original_[i]).norm();
  step /= double(k_);
  std::vector<Mesh::VertexHandle> front = result_.right_ring;
  auto none = [](Mesh::VertexHandle, Mesh::VertexHandle) { return false; };
  for (int layer = 0; layer <= kMaxLayers; ++layer) {
    const std::vector<std::array<int, 3>> disk = triangulate_ring(mesh_, front, none);
    if (layer > 0 && !disk.empty() && close_front(disk, right, left)) return true;
    if (close_front_relaxed(front, right, left)) return true;
    if (layer == kMaxLayers || front.size() <= 3) return false;
    front = clean_layer(front, front_directions(front, disk, step, layer == 0 ? side : std::vector<Sides>{}), step,
                        &right->tris);
    if (front.empty()) {
      if (denoise_debug()) std::fprintf(stderr, "denoise debug: front k=%zu: layer %d failed\n", k_, layer + 1);
      return false;
    }
    right->inner.insert(right->inner.end(), front.begin(), front.end());
  }
  return false;
}

// One clean layer (advance_front()): where strip triangles meet the surface or the cap so far,
// the moves of their front vertices and those vertices' neighbours are halved and the layer is
// made again, up to kRetries times. Empty when it stalls or stays unclean (nothing added then).
std::vector<Mesh::VertexHandle> Surgery::clean_layer(const std::vector<Mesh::VertexHandle>& f,
                                                     const std::vector<Vec3>& dir, double step,
                                                     std::vector<std::array<int, 3>>* tris) {
  const std::size_t n = f.size(), before = tris->size(), n_vertices = mesh_.n_vertices();
  std::unordered_map<int, std::size_t> index;
  for (std::size_t i = 0; i < n; ++i) index[f[i].idx()] = i;
  std::vector<double> scale(n, 1.0);
  for (int attempt = 0; attempt <= kRetries; ++attempt) {
    const std::vector<Mesh::VertexHandle> next = advance_front(f, dir, scale, step, tris);
    if (next.empty()) return {};
    std::vector<bool> shrink(n, false);
    std::vector<std::array<int, 3>> done(tris->begin(), tris->begin() + static_cast<std::ptrdiff_t>(before));
    for (std::size_t t = before; t < tris->size(); ++t) {
      if (opts_.guard->hits(mesh_, (*tris)[t], done))
        for (int a : (*tris)[t])
          if (auto it = index.find(a); it != index.end())
            for (std::size_t d : {n - 1, std::size_t(0), std::size_t(1)}) shrink[(it->second + d) % n] = true;
      done.push_back((*tris)[t]);
    }
    if (std::find(shrink.begin(), shrink.end(), true) == shrink.end()) return next;
    for (std::size_t i = 0; i < n; ++i) scale[i] *= shrink[i] ? 0.5 : 1.0;
    tris->resize(before);
    mesh_.resize(n_vertices, mesh_.n_edges(), mesh_.n_faces());
  }
  return {};
}

// Closes the right cap with `disk` and mirrors it (left_front_cap() at offsets of 1, 1/2 and 1/4
// of the rings' separation); true when both are clean. Otherwise the right cap is as before and
// the left one's vertices are removed.
bool Surgery::close_front(const std::vector<std::array<int, 3>>& disk, FrontCap* right, FrontCap* left) {
  const std::size_t before = right->tris.size();
  right->tris.insert(right->tris.end(), disk.begin(), disk.end());
  if (clean_from(right->tris, before, {})) {
    const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
    for (double fraction : {1.0, 0.5, 0.25}) {
      if (left_front_cap(*right, fraction, left)) return true;
      mesh_.resize(n_vertices, n_edges, n_faces);
    }
  }
  right->tris.resize(before);
  return false;
}

// The left cap as the right one's mirror: ring vertices mapped to the left ring, interior ones
// moved by `fraction` of the rings' mean separation along the right cap's unit normal, towards
// the left side; triangles reversed. True (with *left) when it meets neither the surface nor the
// right cap.
bool Surgery::left_front_cap(const FrontCap& right, double fraction, FrontCap* left) {
  std::unordered_map<int, int> mirror;
  double gap = 0, side = 0;
  for (std::size_t i = 0; i < k_; ++i) {
    mirror[result_.right_ring[i].idx()] = result_.left_ring[i].idx();
    gap += (mesh_.point(result_.right_ring[i]) - mesh_.point(result_.left_ring[i])).norm() / double(k_);
  }
  std::unordered_map<int, Vec3> normal;
  for (const auto& t : right.tris) {
    const Vec3 a = mesh_.point(Mesh::VertexHandle(t[0]));
    const Vec3 nrm = OpenMesh::cross(mesh_.point(Mesh::VertexHandle(t[1])) - a, mesh_.point(Mesh::VertexHandle(t[2])) - a);
    for (int v : t) normal.try_emplace(v, 0.0, 0.0, 0.0).first->second += nrm;
    if (mirror.count(t[0])) side += OpenMesh::dot(nrm, a - mesh_.point(Mesh::VertexHandle(mirror.at(t[0]))));
  }
  const double shift = (side > 0 ? -gap : gap) * fraction;
  *left = FrontCap{};
  for (auto v : right.inner) {
    left->inner.push_back(mesh_.add_vertex(mesh_.point(v) + shift * unit(normal[v.idx()])));
    mirror[v.idx()] = left->inner.back().idx();
  }
  for (const auto& t : right.tris) left->tris.push_back({mirror.at(t[0]), mirror.at(t[2]), mirror.at(t[1])});
  return clean_from(left->tris, 0, right.tris);
}

// 7c. Front caps in the current placement (after the collar caps), first into the side of the
//     surface where a disk of the loop lies first (disk_side()), then into the other: kept, added
//     to the mesh and the grid, when both caps meet nothing; otherwise every vertex they added is
//     removed.
bool Surgery::try_front_caps() {
  normal_right_ = unit_normals(result_.right_ring);
  normal_left_ = unit_normals(result_.left_ring);
  const double first = disk_side();
  for (double sign : {first, -first})
    if (front_caps(sign)) return true;
  return false;
}

// Front caps whose first layer leaves the right ring along sign x its side's normals.
bool Surgery::front_caps(double sign) {
  const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
  FrontCap right, left;
  const bool ok = front_cap_pair(sign, &right, &left);
  if (denoise_debug())
    std::fprintf(stderr, "denoise debug: front k=%zu sign %+.0f: %s, %zu interior vertices, %zu triangles per cap\n", k_,
                 sign, ok ? "clean" : "failed", right.inner.size(), right.tris.size());
  if (!ok) {
    mesh_.resize(n_vertices, n_edges, n_faces);
    return false;
  }
  add_cap(mesh_, right.tris, opts_.guard, "surgery (front)");
  add_cap(mesh_, left.tris, opts_.guard, "surgery (front)");
  finish_caps_with_interior(right.inner, left.inner);
  return true;
}

}  // namespace cf::detail
