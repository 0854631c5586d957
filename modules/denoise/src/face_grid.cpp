#include "colonflat/denoise/face_grid.h"

#include <vtkTriangle.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <unordered_set>

#include "colonflat/core/vertex_stamps.h"

namespace cf {

FaceGrid::FaceGrid(const Mesh& mesh, double cell_size) : cell_(cell_size) { build_static(mesh, mesh.faces()); }

FaceGrid::FaceGrid(const Mesh& mesh, double cell_size, const std::vector<Mesh::FaceHandle>& faces) : cell_(cell_size) {
  build_static(mesh, faces);
}

FaceGrid::Key FaceGrid::key(const Vec3& p) const {
  return {static_cast<long long>(std::floor(p[0] / cell_)), static_cast<long long>(std::floor(p[1] / cell_)),
          static_cast<long long>(std::floor(p[2] / cell_))};
}

namespace {
// Faces the thread's current query tested (a face lies in every cell its box meets, and a query
// walking cells would test it once per cell); one array per thread: the restricted caps query from two.
VertexStamps& tested_faces(const Mesh& mesh) {
  thread_local VertexStamps stamps;
  stamps.start(mesh.n_faces());
  return stamps;
}

bool first_visit(VertexStamps& seen, int f) {  // true the first time face f comes in the query
  if (seen.marked(f)) return false;
  seen.mark(f);
  return true;
}

void face_box(const Mesh& mesh, Mesh::FaceHandle f, Vec3& lo, Vec3& hi, std::array<int, 3>& ids,
              std::array<Vec3, 3>& pts) {
  // The face's halfedge cycle read directly (the order of fv_range): this runs for every
  // candidate face of every grid query, and the circulator's bookkeeping was most of its cost.
  auto h = mesh.halfedge_handle(f);
  for (int k = 0; k < 3; ++k, h = mesh.next_halfedge_handle(h)) {
    const auto v = mesh.to_vertex_handle(h);
    ids[k] = v.idx();
    pts[k] = mesh.point(v);
  }
  lo = hi = pts[0];
  for (int i = 1; i < 3; ++i)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], pts[i][a]);
      hi[a] = std::max(hi[a], pts[i][a]);
    }
}
}  // namespace

std::vector<int> FaceGrid::candidates(const Vec3& lo, const Vec3& hi) const {
  const Key a = key(lo), b = key(hi);
  std::vector<int> cand(big_.begin(), big_.end());
  auto add_row = [&](std::uint32_t row) {
    for (const int* f = static_.begin(row); f != static_.end(row); ++f)
      if (!erased(*f)) cand.push_back(*f);
  };
  const double box_cells = double(b.x - a.x + 1) * double(b.y - a.y + 1) * double(b.z - a.z + 1);
  if (box_cells > double(cells_.size() + static_.rows())) {
    for (std::uint32_t row = 0; row < static_.rows(); ++row) add_row(row);  // a query box with more cells than the grid
    for (const auto& [k, v] : cells_) {
      (void)k;
      cand.insert(cand.end(), v.begin(), v.end());
    }
  } else {
    for (long long x = a.x; x <= b.x; ++x)
      for (long long y = a.y; y <= b.y; ++y)
        for (long long z = a.z; z <= b.z; ++z) cell_faces(Key{x, y, z}, [&](int f) { return cand.push_back(f), false; });
  }
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  return cand;
}

namespace {
// Whether the rectangle [u0, u1] x [v0, v1] of axes (u, v) lies wholly beyond one edge of triangle
// p's projection on them (nd: p's normal along the third axis, nonzero; its sign is the
// projection's orientation), so that the two do not meet.
bool beyond_an_edge(const std::array<Vec3, 3>& p, int u, int v, double nd, double u0, double u1, double v0, double v1) {
  for (int e = 0; e < 3; ++e) {
    const Vec3 &a = p[e], &b = p[(e + 1) % 3];
    auto inside = [&](double x, double y) {  // on p's side of edge (a, b), or on it
      return ((b[u] - a[u]) * (y - a[v]) - (b[v] - a[v]) * (x - a[u])) * nd >= 0;
    };
    if (!inside(u0, v0) && !inside(u1, v0) && !inside(u0, v1) && !inside(u1, v1)) return true;
  }
  return false;
}
}  // namespace

// Calls visit(cell) for the cells that the plane of triangle p crosses inside the triangle's
// bounding box (every cell the triangle meets is one of them) until visit returns true; returns
// whether it did. Per column of cells along the plane's dominant normal axis, the plane spans a
// short range of that axis: a cap triangle of a long loop (tens of mm) has 10^4-10^5 cells in its
// bounding box, and most of the surface's faces near the loop in them, but its plane crosses
// only a sheet of cells one or two thick. Columns whose rectangle (grown by a tenth of a cell)
// lies beyond an edge of the triangle's projection are skipped: about half the box's columns for
// a cap triangle, none of the triangle's own. A degenerate triangle visits its whole box.
template <class Visit>
bool FaceGrid::triangle_cells(const std::array<Vec3, 3>& p, Visit&& visit) const {
  Vec3 lo = p[0], hi = p[0];
  for (int i = 1; i < 3; ++i) {
    lo.minimize(p[i]);
    hi.maximize(p[i]);
  }
  const Vec3 n = OpenMesh::cross(p[1] - p[0], p[2] - p[0]);
  int d = 0;
  for (int a = 1; a < 3; ++a)
    if (std::fabs(n[a]) > std::fabs(n[d])) d = a;
  const int u = (d + 1) % 3, v = (d + 2) % 3;
  const double c = OpenMesh::dot(n, p[0]), slack = 1e-9 * cell_;
  const Key ka = key(lo), kb = key(hi);
  const long long la[3] = {ka.x, ka.y, ka.z}, lb[3] = {kb.x, kb.y, kb.z};
  long long k[3];
  for (k[u] = la[u]; k[u] <= lb[u]; ++k[u])
    for (k[v] = la[v]; k[v] <= lb[v]; ++k[v]) {
      long long d0 = la[d], d1 = lb[d];
      if (n[d] != 0) {  // the plane's range of axis d over the column's rectangle clamped to the box
        const double u0 = std::max(k[u] * cell_, lo[u]), u1 = std::min((k[u] + 1) * cell_, hi[u]);
        const double v0 = std::max(k[v] * cell_, lo[v]), v1 = std::min((k[v] + 1) * cell_, hi[v]);
        const double grow = 0.1 * cell_;
        if (beyond_an_edge(p, u, v, n[d], u0 - grow, u1 + grow, v0 - grow, v1 + grow)) continue;
        double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin;
        for (double uu : {u0, u1})
          for (double vv : {v0, v1}) {
            const double x = (c - n[u] * uu - n[v] * vv) / n[d];
            dmin = std::min(dmin, x);
            dmax = std::max(dmax, x);
          }
        d0 = std::max(d0, static_cast<long long>(std::floor((std::max(dmin, lo[d]) - slack) / cell_)));
        d1 = std::min(d1, static_cast<long long>(std::floor((std::min(dmax, hi[d]) + slack) / cell_)));
      }
      for (k[d] = d0; k[d] <= d1; ++k[d])
        if (visit(Key{k[0], k[1], k[2]})) return true;
    }
  return false;
}

// Calls visit(cell) for the cells segment pq passes through, in order (a 3D DDA walk), until
// visit returns true; returns whether it did. A face the segment meets lies in the cell of the
// meeting point (faces are hashed by bounding box), so these cells hold every face it can hit.
template <class Visit>
bool FaceGrid::segment_cells(const Vec3& p, const Vec3& q, Visit&& visit) const {
  const Key a = key(p), b = key(q);
  long long k[3] = {a.x, a.y, a.z};
  const long long last[3] = {b.x, b.y, b.z};
  const Vec3 d = q - p;
  long long step[3];
  double next[3], delta[3];
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    step[i] = d[i] > 0 ? 1 : (d[i] < 0 ? -1 : 0);
    const double boundary = (k[i] + (step[i] > 0 ? 1 : 0)) * cell_;
    next[i] = step[i] != 0 ? (boundary - p[i]) / d[i] : kInf;
    delta[i] = step[i] != 0 ? cell_ / std::fabs(d[i]) : kInf;
  }
  const long long cells = std::llabs(b.x - a.x) + std::llabs(b.y - a.y) + std::llabs(b.z - a.z) + 1;
  for (long long n = 0; n < cells; ++n) {
    if (visit(Key{k[0], k[1], k[2]})) return true;
    if (k[0] == last[0] && k[1] == last[1] && k[2] == last[2]) break;
    int i = 0;
    if (next[1] < next[i]) i = 1;
    if (next[2] < next[i]) i = 2;
    k[i] += step[i];
    next[i] += delta[i];
  }
  return false;
}

// Calls visit(face id) for the grid faces of cell k (a face may come again from another cell)
// until visit returns true; returns whether it did.
template <class Visit>
bool FaceGrid::cell_faces(const Key& k, Visit&& visit) const {
  const std::uint64_t code = StaticCells::code(k);
  const std::uint32_t row = code == StaticCells::kEmpty ? StaticCells::kNoRow : static_.find(code);
  if (row != StaticCells::kNoRow)
    for (const int* f = static_.begin(row); f != static_.end(row); ++f)
      if (!erased(*f) && visit(*f)) return true;
  if (cells_.empty()) return false;
  const auto it = cells_.find(k);
  if (it != cells_.end())
    for (int f : it->second)
      if (visit(f)) return true;
  return false;
}

// ---- the constructor's faces in compressed rows per cell (the build's part: face_grid_cells.cpp) ----

std::uint64_t FaceGrid::StaticCells::code(const Key& k) {
  constexpr long long kHalf = 1LL << 20;
  auto out = [&](long long c) { return c < -kHalf || c >= kHalf; };
  if (out(k.x) || out(k.y) || out(k.z)) return kEmpty;
  return (std::uint64_t(k.x + kHalf) << 42) | (std::uint64_t(k.y + kHalf) << 21) | std::uint64_t(k.z + kHalf);
}

std::uint32_t FaceGrid::StaticCells::find(std::uint64_t code) const {
  if (slot_code_.empty()) return kNoRow;
  const std::size_t mask = slot_code_.size() - 1;
  for (std::size_t s = slot(code, mask);; s = (s + 1) & mask) {
    if (slot_code_[s] == code) return slot_row_[s];
    if (slot_code_[s] == kEmpty) return kNoRow;
  }
}

// One pass over the faces counts each cell's faces and lists (row, face) to fill the rows from; faces
// spanning over kMaxCellsPerFace cells go to big_, faces beyond the codes' range to the dynamic cells.
template <class Faces>
void FaceGrid::build_static(const Mesh& mesh, const Faces& faces) {
  erased_.assign(mesh.n_faces(), 0);
  std::vector<std::pair<std::uint32_t, int>> entries;  // (row, face); most faces lie in 1-2 cells
  entries.reserve(2 * mesh.n_faces());
  std::uint64_t last = StaticCells::kEmpty;
  std::uint32_t last_row = StaticCells::kNoRow;
  for (auto f : faces) {
    Key a, b;
    if (!cell_range(mesh, f, a, b)) {
      if (big_set_.insert(f.idx()).second) big_.push_back(f.idx());
      continue;
    }
    if (StaticCells::code(a) == StaticCells::kEmpty || StaticCells::code(b) == StaticCells::kEmpty) {
      insert_dynamic(mesh, f);
      continue;
    }
    for (long long x = a.x; x <= b.x; ++x)
      for (long long y = a.y; y <= b.y; ++y)
        for (long long z = a.z; z <= b.z; ++z) {
          const std::uint64_t c = StaticCells::code(Key{x, y, z});
          if (c != last) last = c, last_row = static_.find_or_add(c);
          static_.count(last_row);
          entries.emplace_back(last_row, f.idx());
        }
  }
  static_.finish_counts();
  for (const auto& [row, face] : entries) static_.fill(row, face);
  static_.end_fill();
}

bool FaceGrid::cell_range(const Mesh& mesh, Mesh::FaceHandle f, Key& a, Key& b) const {
  Vec3 lo, hi;
  std::array<int, 3> ids;
  std::array<Vec3, 3> pts;
  face_box(mesh, f, lo, hi, ids, pts);
  a = key(lo);
  b = key(hi);
  return (b.x - a.x + 1) * (b.y - a.y + 1) * (b.z - a.z + 1) <= kMaxCellsPerFace;
}

template <class Visit>
bool FaceGrid::visit_cells(const Mesh& mesh, Mesh::FaceHandle f, Visit&& visit) const {
  Key a, b;
  if (!cell_range(mesh, f, a, b)) return false;
  for (long long x = a.x; x <= b.x; ++x)
    for (long long y = a.y; y <= b.y; ++y)
      for (long long z = a.z; z <= b.z; ++z) visit(Key{x, y, z});
  return true;
}

void FaceGrid::insert(const Mesh& mesh, Mesh::FaceHandle f) {
  if (f.idx() < static_cast<int>(erased_.size())) erased_[f.idx()] = 0;
  insert_dynamic(mesh, f);
}

void FaceGrid::insert_dynamic(const Mesh& mesh, Mesh::FaceHandle f) {
  const bool small = visit_cells(mesh, f, [&](const Key& k) {
    auto& v = cells_[k];
    if (std::find(v.begin(), v.end(), f.idx()) == v.end()) v.push_back(f.idx());
  });
  if (!small && big_set_.insert(f.idx()).second) big_.push_back(f.idx());  // checked by every query instead
}

void FaceGrid::forget_faces_from(int first) {
  for (auto& [k, faces] : cells_) {
    (void)k;
    faces.erase(std::remove_if(faces.begin(), faces.end(), [first](int f) { return f >= first; }), faces.end());
  }
  big_.erase(std::remove_if(big_.begin(), big_.end(), [first](int f) { return f >= first; }), big_.end());
  for (auto it = big_set_.begin(); it != big_set_.end();) it = *it >= first ? big_set_.erase(it) : std::next(it);
}

void FaceGrid::erase(const Mesh& mesh, Mesh::FaceHandle f) {
  const bool small = visit_cells(mesh, f, [&](const Key& k) {
    auto it = cells_.find(k);
    if (it != cells_.end()) it->second.erase(std::remove(it->second.begin(), it->second.end(), f.idx()), it->second.end());
  });
  if (!small && big_set_.erase(f.idx())) big_.erase(std::find(big_.begin(), big_.end(), f.idx()));
  if (small && f.idx() < static_cast<int>(erased_.size())) erased_[f.idx()] = 1;  // hides its static entries
}

namespace {
// Parameter t > 1e-9 at which the ray p + t d meets triangle (a, b, c), or infinity (Moller-Trumbore).
double ray_triangle(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  // The near-parallel test (three square roots) last: it only turns a hit into kNever, and with
  // det = 0 the quotients are infinite or NaN, which every test below refuses.
  const Vec3 e1 = b - a, e2 = c - a, h = OpenMesh::cross(d, e2);
  const double det = OpenMesh::dot(e1, h);
  const Vec3 s = p - a;
  const double u = OpenMesh::dot(s, h) / det;
  if (u < 0 || u > 1) return kNever;
  const Vec3 qv = OpenMesh::cross(s, e1);
  const double v = OpenMesh::dot(d, qv) / det;
  if (v < 0 || u + v > 1) return kNever;
  const double t = OpenMesh::dot(e2, qv) / det;
  if (!(t > 1e-9) || std::fabs(det) <= 1e-12 * e1.norm() * e2.norm() * d.norm()) return kNever;
  return t;
}

// Segment [p, q] against triangle (a, b, c), excluding the segment's first 1e-9.
bool segment_hits_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  return ray_triangle(p, q - p, a, b, c) <= 1.0;
}

}  // namespace

// Disjoint triangles by VTK's triangle test; sharing one vertex v: an edge of one pierces the
// other away from v; sharing an edge: the two fold flat onto each other.
bool triangles_intersect_improperly(const std::array<int, 3>& ids, const std::array<Vec3, 3>& p,
                                    const std::array<int, 3>& gids, const std::array<Vec3, 3>& q) {
  int shared = 0, ia = -1, ib = -1;
  for (int i1 = 0; i1 < 3; ++i1)
    for (int i2 = 0; i2 < 3; ++i2)
      if (ids[i1] == gids[i2]) {
        ++shared;
        ia = i1;
        ib = i2;
      }
  if (shared == 0)
    return vtkTriangle::TrianglesIntersect(p[0].data(), p[1].data(), p[2].data(), q[0].data(), q[1].data(),
                                           q[2].data()) != 0;
  if (shared == 3) return false;
  if (shared == 1) {
    const Vec3& v = p[ia];
    const Vec3 &a1 = p[(ia + 1) % 3], &a2 = p[(ia + 2) % 3], &b1 = q[(ib + 1) % 3], &b2 = q[(ib + 2) % 3];
    return segment_hits_triangle(a1, a2, v, b1, b2) || segment_hits_triangle(b1, b2, v, a1, a2) ||
           segment_hits_triangle(v, a1, v, b1, b2) || segment_hits_triangle(v, a2, v, b1, b2) ||
           segment_hits_triangle(v, b1, v, a1, a2) || segment_hits_triangle(v, b2, v, a1, a2);
  }
  const Vec3 na = OpenMesh::cross(p[1] - p[0], p[2] - p[0]), nb = OpenMesh::cross(q[1] - q[0], q[2] - q[0]);
  if (na.norm() == 0 || nb.norm() == 0) return false;
  return OpenMesh::dot(na, nb) / (na.norm() * nb.norm()) < -0.9999999;
}

bool FaceGrid::segment_hits(const Mesh& mesh, int a, int b) const {
  const Vec3 p = mesh.point(Mesh::VertexHandle(a)), q = mesh.point(Mesh::VertexHandle(b));
  VertexStamps& seen = tested_faces(mesh);
  auto pierces = [&](int gi) {
    if (!first_visit(seen, gi)) return false;
    Vec3 lo, hi;
    std::array<int, 3> ids;
    std::array<Vec3, 3> t;
    face_box(mesh, Mesh::FaceHandle(gi), lo, hi, ids, t);
    const bool at_a = ids[0] == a || ids[1] == a || ids[2] == a, at_b = ids[0] == b || ids[1] == b || ids[2] == b;
    if (at_a && at_b) return false;  // pq is that face's edge
    // from the shared end (the exclusion of a triangle's first 1e-9 is the one hits() applies)
    return at_b ? segment_hits_triangle(q, p, t[0], t[1], t[2]) : segment_hits_triangle(p, q, t[0], t[1], t[2]);
  };
  if (std::any_of(big_.begin(), big_.end(), pierces)) return true;
  return segment_cells(p, q, [&](const Key& k) { return cell_faces(k, pierces); });
}

double FaceGrid::free_distance(const Mesh& mesh, const Vec3& origin, const Vec3& dir, double max_dist,
                               int skip_vertex) const {
  double best = max_dist;
  VertexStamps& seen = tested_faces(mesh);
  auto meet = [&](int gi) {
    if (!first_visit(seen, gi)) return false;
    Vec3 lo, hi;
    std::array<int, 3> ids;
    std::array<Vec3, 3> q;
    face_box(mesh, Mesh::FaceHandle(gi), lo, hi, ids, q);
    if (ids[0] != skip_vertex && ids[1] != skip_vertex && ids[2] != skip_vertex)
      best = std::min(best, ray_triangle(origin, dir, q[0], q[1], q[2]));
    return false;
  };
  std::for_each(big_.begin(), big_.end(), meet);
  Vec3 lo = origin, hi = origin;
  lo.minimize(origin + max_dist * dir);
  hi.maximize(origin + max_dist * dir);
  const Key a = key(lo), b = key(hi);
  for (long long x = a.x; x <= b.x; ++x)
    for (long long y = a.y; y <= b.y; ++y)
      for (long long z = a.z; z <= b.z; ++z) cell_faces(Key{x, y, z}, meet);
  return best;
}

std::size_t FaceGrid::count_intersections(const Mesh& mesh, const std::vector<Mesh::FaceHandle>& faces,
                                          std::size_t stop_at, const PairFilter& skip) const {
  return intersecting_pairs(mesh, faces, stop_at, skip).size();
}

std::vector<std::pair<int, int>> FaceGrid::intersecting_pairs(const Mesh& mesh,
                                                              const std::vector<Mesh::FaceHandle>& faces,
                                                              std::size_t stop_at, const PairFilter& skip) const {
  std::vector<std::pair<int, int>> pairs;
  if (stop_at == 0) return pairs;
  std::unordered_set<int> in_set;
  for (auto f : faces) in_set.insert(f.idx());
  std::unordered_set<long long> seen;
  for (auto f : faces) {
    Vec3 lo, hi;
    std::array<int, 3> ids;
    std::array<Vec3, 3> p;
    face_box(mesh, f, lo, hi, ids, p);
    // Candidates: faces in the cells (the caller inserts moved faces at their current place;
    // stale cells only cost time, the test below uses current geometry).
    const std::vector<int> cand = candidates(lo, hi);
    for (int gi : cand) {
      if (gi == f.idx()) continue;
      const auto g = Mesh::FaceHandle(gi);
      if (in_set.count(gi)) {
        const long long lo_id = std::min(f.idx(), gi), hi_id = std::max(f.idx(), gi);
        if (!seen.insert(lo_id * 4000000000LL + hi_id).second) continue;
      }
      Vec3 glo, ghi;
      std::array<int, 3> gids;
      std::array<Vec3, 3> q;
      face_box(mesh, g, glo, ghi, gids, q);
      if (glo[0] > hi[0] || glo[1] > hi[1] || glo[2] > hi[2] || ghi[0] < lo[0] || ghi[1] < lo[1] || ghi[2] < lo[2])
        continue;
      if (triangles_intersect_improperly(ids, p, gids, q) && !(skip && skip(f.idx(), gi))) {
        pairs.emplace_back(f.idx(), gi);
        if (pairs.size() >= stop_at) return pairs;
      }
    }
  }
  return pairs;
}

// With first_only, each cell's faces are tested as the cells come (a face in several cells may be
// tested again; the first hit ends the query): a cap triangle that crosses a wall is refused
// after a few cells. Otherwise every face once (sorted, unique), for an exact count.
std::size_t FaceGrid::grid_hits(const Mesh& mesh, const std::array<int, 3>& ids, const std::array<Vec3, 3>& p,
                                bool first_only) const {
  Vec3 lo = p[0], hi = p[0];
  for (int i = 1; i < 3; ++i) {
    lo.minimize(p[i]);
    hi.maximize(p[i]);
  }
  auto hit = [&](int gi) {
    Vec3 glo, ghi;
    std::array<int, 3> gids;
    std::array<Vec3, 3> q;
    face_box(mesh, Mesh::FaceHandle(gi), glo, ghi, gids, q);
    if (glo[0] > hi[0] || glo[1] > hi[1] || glo[2] > hi[2] || ghi[0] < lo[0] || ghi[1] < lo[1] || ghi[2] < lo[2])
      return false;
    return triangles_intersect_improperly(ids, p, gids, q);
  };
  if (first_only) {
    VertexStamps& seen = tested_faces(mesh);
    auto first_hit = [&](int gi) { return first_visit(seen, gi) && hit(gi); };
    if (std::any_of(big_.begin(), big_.end(), first_hit)) return 1;
    return triangle_cells(p, [&](const Key& k) { return cell_faces(k, first_hit); }) ? 1 : 0;
  }
  std::vector<int> cand(big_.begin(), big_.end());
  triangle_cells(p, [&](const Key& k) { return cell_faces(k, [&](int f) { return cand.push_back(f), false; }); });
  std::sort(cand.begin(), cand.end());
  cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
  return static_cast<std::size_t>(std::count_if(cand.begin(), cand.end(), hit));
}

std::size_t FaceGrid::count_triangles(const Mesh& mesh, const std::vector<std::array<int, 3>>& tris) const {
  std::size_t count = 0;
  std::vector<std::array<Vec3, 3>> pts(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int i = 0; i < 3; ++i) pts[t][i] = mesh.point(Mesh::VertexHandle(tris[t][i]));
  for (std::size_t t = 0; t < tris.size(); ++t) {
    count += grid_hits(mesh, tris[t], pts[t], false);
    for (std::size_t u = t + 1; u < tris.size(); ++u)
      if (triangles_intersect_improperly(tris[t], pts[t], tris[u], pts[u])) ++count;
  }
  return count;
}

bool FaceGrid::hits(const Mesh& mesh, const std::array<int, 3>& tri,
                    const std::vector<std::array<int, 3>>& others) const {
  std::array<Vec3, 3> p;
  for (int i = 0; i < 3; ++i) p[i] = mesh.point(Mesh::VertexHandle(tri[i]));
  for (const auto& o : others) {
    std::array<Vec3, 3> q;
    for (int i = 0; i < 3; ++i) q[i] = mesh.point(Mesh::VertexHandle(o[i]));
    bool apart = false;  // bounding boxes disjoint
    for (int a = 0; a < 3 && !apart; ++a)
      apart = std::min({q[0][a], q[1][a], q[2][a]}) > std::max({p[0][a], p[1][a], p[2][a]}) ||
              std::max({q[0][a], q[1][a], q[2][a]}) < std::min({p[0][a], p[1][a], p[2][a]});
    if (!apart && triangles_intersect_improperly(tri, p, o, q)) return true;
  }
  return grid_hits(mesh, tri, p, true) > 0;
}

}  // namespace cf
