// Relaxed closings of front caps (step 7c of the Surgery, surgery_steps.h, surgery_front.cpp).
//
// A front is closed by its minimum-area triangulation, a disk of its chords. On a long loop
// whose chords cross the surface the restricted triangulations (step 7d) then search long and
// often find nothing (issue 26: the real CT surface's last handle, a 236-238-vertex loop: 10-20 s
// of grid queries in 7 placements), while a disk with interior vertices that bends with the
// loop is clean at once: concentric rings about one front edge apart, relaxed to a discrete
// minimal surface with the front fixed (uniform Laplacian), the disk the concentric caps of
// step 8 use, but checked on the guard grid before anything is added and mirrored like the
// front caps, so a failure leaves nothing behind and the later steps still run.
#include <algorithm>
#include <cmath>

#include "colonflat/denoise/face_grid.h"
#include "surgery_steps.h"

namespace cf::detail {

namespace {
// Concentric rings at most (ring spacing about one front edge up to this many).
constexpr int kMaxRelaxedRings = 16;
}  // namespace

// The disk of `rows` over `front`: its vertices added to the mesh and to right->inner, its
// triangles (strips ring by ring, then the fan at the centre: ear order) appended to right->tris.
void Surgery::add_relaxed_disk(const std::vector<Mesh::VertexHandle>& front,
                               const std::vector<std::vector<Vec3>>& rows, FrontCap* right) {
  const std::size_t n = front.size();
  const int m = static_cast<int>(rows.size()) - 1;
  std::vector<std::vector<int>> id(m + 1);
  for (auto v : front) id[0].push_back(v.idx());
  for (int j = 1; j <= m; ++j)
    for (const auto& q : rows[j]) {
      const auto v = mesh_.add_vertex(q);
      right->inner.push_back(v);
      id[j].push_back(v.idx());
    }
  for (int j = 0; j + 1 < m; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t a = (i + 1) % n;
      right->tris.push_back({id[j][i], id[j][a], id[j + 1][a]});
      right->tris.push_back({id[j][i], id[j + 1][a], id[j + 1][i]});
    }
  for (std::size_t i = 0; i < n; ++i) right->tris.push_back({id[m - 1][i], id[m - 1][(i + 1) % n], id[m][0]});
}

// Closes the right cap with the relaxed disk over `front` and mirrors it (left_front_cap() at 1,
// 1/2 and 1/4 of the rings' separation); true when both are clean. Otherwise everything it added
// is removed.
bool Surgery::close_front_relaxed(const std::vector<Mesh::VertexHandle>& front, FrontCap* right, FrontCap* left) {
  std::vector<Vec3> p(front.size());
  for (std::size_t i = 0; i < front.size(); ++i) p[i] = mesh_.point(front[i]);
  double radius = 0, edge = 0;
  loop_radius_and_edge(p, &radius, &edge);
  if (edge <= 0) return false;
  const int m = std::clamp(static_cast<int>(std::lround(radius / edge)), 2, kMaxRelaxedRings);
  const std::size_t n_vertices = mesh_.n_vertices(), n_edges = mesh_.n_edges(), n_faces = mesh_.n_faces();
  const std::size_t tris_before = right->tris.size(), inner_before = right->inner.size();
  add_relaxed_disk(front, concentric_disk_rows(p, m), right);
  if (clean_from(right->tris, tris_before, {}))
    for (double fraction : {1.0, 0.5, 0.25}) {
      const std::size_t with_right = mesh_.n_vertices();
      if (left_front_cap(*right, fraction, left)) return true;
      mesh_.resize(with_right, n_edges, n_faces);
    }
  right->tris.resize(tris_before);
  right->inner.resize(inner_before);
  mesh_.resize(n_vertices, n_edges, n_faces);
  return false;
}

}  // namespace cf::detail
