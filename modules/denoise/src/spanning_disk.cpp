#include "colonflat/denoise/spanning_disk.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include "colonflat/denoise/cap_triangulation.h"

namespace cf {

namespace {
// Refinement rounds (each halves the longest interior edges: chords of a 2000-vertex ring are
// at most ~640 ring edges long, 2^10 > 640) and umbrella steps per round / at the end.
constexpr int kRounds = 12;
constexpr int kSmoothPerRound = 4;
constexpr int kSmoothFinal = 40;

class DiskBuilder {
 public:
  DiskBuilder(const std::vector<Vec3>& ring, double edge) : k_(static_cast<int>(ring.size())), edge_(edge), ring_(ring) {}
  SpanningDisk build();

 private:
  bool seed();
  bool ring_vertex(Mesh::VertexHandle v) const { return v.idx() < k_; }
  int split_edges(bool chords_only);
  void flip_edges();
  void smooth(int steps);
  SpanningDisk output() const;

  const int k_;
  const double edge_;
  const std::vector<Vec3>& ring_;
  Mesh d_;
};

bool DiskBuilder::seed() {
  const std::vector<std::array<int, 3>> tris = min_area_triangulation(ring_);
  if (tris.empty()) return false;
  for (const auto& p : ring_) d_.add_vertex(p);
  for (const auto& t : tris)
    if (!d_.add_face(Mesh::VertexHandle(t[0]), Mesh::VertexHandle(t[1]), Mesh::VertexHandle(t[2])).is_valid()) return false;
  return true;
}

// Splits interior edges at their midpoints: with chords_only every edge between two ring
// vertices, else every edge longer than 4/3 of the target length. Returns how many.
int DiskBuilder::split_edges(bool chords_only) {
  std::vector<Mesh::EdgeHandle> todo;
  const double limit = 4.0 / 3.0 * edge_;
  for (auto e : d_.edges()) {
    if (d_.is_boundary(e)) continue;
    const auto h = d_.halfedge_handle(e, 0);
    const auto a = d_.from_vertex_handle(h), b = d_.to_vertex_handle(h);
    const bool chord = ring_vertex(a) && ring_vertex(b);
    if (chords_only ? chord : (d_.point(a) - d_.point(b)).norm() > limit) todo.push_back(e);
  }
  for (auto e : todo) {
    const auto h = d_.halfedge_handle(e, 0);
    d_.split(e, 0.5 * (d_.point(d_.from_vertex_handle(h)) + d_.point(d_.to_vertex_handle(h))));
  }
  return static_cast<int>(todo.size());
}

// Delaunay flips of interior edges (the two opposite angles summing to more than pi), never
// creating an edge between two ring vertices.
void DiskBuilder::flip_edges() {
  for (int pass = 0; pass < 4; ++pass) {
    int flips = 0;
    for (auto e : d_.edges()) {
      if (d_.is_boundary(e) || !d_.is_flip_ok(e)) continue;
      const auto h0 = d_.halfedge_handle(e, 0), h1 = d_.halfedge_handle(e, 1);
      const auto a = d_.from_vertex_handle(h0), b = d_.to_vertex_handle(h0);
      const auto c = d_.to_vertex_handle(d_.next_halfedge_handle(h0));
      const auto o = d_.to_vertex_handle(d_.next_halfedge_handle(h1));
      if (ring_vertex(c) && ring_vertex(o)) continue;
      auto angle = [&](Mesh::VertexHandle apex) {
        const Vec3 u = d_.point(a) - d_.point(apex), w = d_.point(b) - d_.point(apex);
        return std::atan2(OpenMesh::cross(u, w).norm(), OpenMesh::dot(u, w));
      };
      if (angle(c) + angle(o) > M_PI + 1e-9) {
        d_.flip(e);
        ++flips;
      }
    }
    if (flips == 0) break;
  }
}

// Gauss-Seidel umbrella steps: each interior vertex to the centroid of its neighbours.
void DiskBuilder::smooth(int steps) {
  for (int s = 0; s < steps; ++s)
    for (auto v : d_.vertices()) {
      if (ring_vertex(v)) continue;
      Vec3 c(0, 0, 0);
      int n = 0;
      for (auto w : d_.vv_range(v)) c += d_.point(w), ++n;
      if (n) d_.set_point(v, c / double(n));
    }
}

// Points, normals, and the faces in breadth-first order from the ring (each one shares an edge
// with the ring or an earlier face).
SpanningDisk DiskBuilder::output() const {
  SpanningDisk out;
  out.normals.assign(d_.n_vertices(), Vec3(0, 0, 0));
  for (auto v : d_.vertices()) out.points.push_back(d_.point(v));
  std::vector<std::uint8_t> seen(d_.n_faces(), 0);
  std::deque<Mesh::FaceHandle> queue;
  for (int i = 0; i < k_; ++i) {
    const auto h = d_.find_halfedge(Mesh::VertexHandle(i), Mesh::VertexHandle((i + 1) % k_));
    const auto f = d_.face_handle(h);
    if (f.is_valid() && !seen[f.idx()]) seen[f.idx()] = 1, queue.push_back(f);
  }
  while (!queue.empty()) {
    const auto f = queue.front();
    queue.pop_front();
    std::array<int, 3> t;
    int i = 0;
    for (auto v : d_.fv_range(f)) t[i++] = v.idx();
    out.triangles.push_back(t);
    const Vec3 n = OpenMesh::cross(out.points[t[1]] - out.points[t[0]], out.points[t[2]] - out.points[t[0]]);
    for (int c : t) out.normals[c] += n;
    for (auto g : d_.ff_range(f))
      if (!seen[g.idx()]) seen[g.idx()] = 1, queue.push_back(g);
  }
  for (auto& n : out.normals)
    if (n.norm() > 0) n /= n.norm();
  return out;
}

SpanningDisk DiskBuilder::build() {
  if (k_ < 3 || !(edge_ > 0) || !seed()) return {};
  split_edges(true);
  for (int r = 0; r < kRounds; ++r) {
    const int split = split_edges(false);
    flip_edges();
    smooth(kSmoothPerRound);
    if (split == 0) break;
  }
  split_edges(true);  // flips never make chords; smoothing cannot either: a safeguard
  smooth(kSmoothFinal);
  return output();
}
}  // namespace

SpanningDisk spanning_disk(const std::vector<Vec3>& ring, double edge) { return DiskBuilder(ring, edge).build(); }

}  // namespace cf
