#include "self_intersections.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <iterator>
#include <vector>

namespace cf::testing {

std::size_t count_self_intersections(const Mesh& mesh) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using SM = CGAL::Surface_mesh<K::Point_3>;
  SM sm;
  std::vector<SM::Vertex_index> vid(mesh.n_vertices());
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    vid[v.idx()] = sm.add_vertex(K::Point_3(p[0], p[1], p[2]));
  }
  for (auto f : mesh.faces()) {
    std::vector<SM::Vertex_index> t;
    for (auto v : mesh.fv_range(f)) t.push_back(vid[v.idx()]);
    sm.add_face(t[0], t[1], t[2]);
  }
  std::vector<std::pair<SM::Face_index, SM::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  return pairs.size();
}

}  // namespace cf::testing
