#include "self_intersections.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <iterator>
#include <vector>

namespace cf::testing {

namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;

SM to_surface_mesh(const Mesh& mesh, std::vector<SM::Face_index>* face_of = nullptr) {
  SM sm;
  if (face_of) face_of->assign(mesh.n_faces(), SM::null_face());
  std::vector<SM::Vertex_index> vid(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    vid[v.idx()] = sm.add_vertex(K::Point_3(p[0], p[1], p[2]));
  }
  for (auto f : mesh.faces()) {
    std::vector<SM::Vertex_index> t;
    for (auto v : mesh.fv_range(f)) t.push_back(vid[v.idx()]);
    const auto g = sm.add_face(t[0], t[1], t[2]);
    if (face_of) (*face_of)[f.idx()] = g;
  }
  return sm;
}
}  // namespace

std::vector<std::pair<int, int>> self_intersecting_pairs(const Mesh& mesh) {
  std::vector<SM::Face_index> face_of;
  const SM sm = to_surface_mesh(mesh, &face_of);
  std::vector<int> id_of(sm.number_of_faces(), -1);
  for (std::size_t f = 0; f < face_of.size(); ++f) id_of[std::size_t(face_of[f])] = static_cast<int>(f);
  std::vector<std::pair<SM::Face_index, SM::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  std::vector<std::pair<int, int>> out;
  for (const auto& [a, b] : pairs)
    out.emplace_back(std::min(id_of[std::size_t(a)], id_of[std::size_t(b)]), std::max(id_of[std::size_t(a)], id_of[std::size_t(b)]));
  return out;
}

std::size_t count_self_intersections(const Mesh& mesh) { return self_intersecting_pairs(mesh).size(); }

std::size_t count_self_intersections_in(const Mesh& mesh, const std::vector<std::array<Vec3, 2>>& boxes) {
  std::vector<SM::Face_index> face_of;
  const SM sm = to_surface_mesh(mesh, &face_of);
  std::vector<SM::Face_index> inside;
  for (auto f : mesh.faces()) {
    Vec3 lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
    for (auto v : mesh.fv_range(f)) {
      lo.minimize(mesh.point(v));
      hi.maximize(mesh.point(v));
    }
    for (const auto& b : boxes)
      if (lo[0] <= b[1][0] && hi[0] >= b[0][0] && lo[1] <= b[1][1] && hi[1] >= b[0][1] && lo[2] <= b[1][2] &&
          hi[2] >= b[0][2]) {
        if (face_of[f.idx()] != SM::null_face()) inside.push_back(face_of[f.idx()]);
        break;
      }
  }
  std::vector<std::pair<SM::Face_index, SM::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(inside, sm, std::back_inserter(pairs));
  return pairs.size();
}

}  // namespace cf::testing
