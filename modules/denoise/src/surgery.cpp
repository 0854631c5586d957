#include "colonflat/denoise/surgery.h"

#include <algorithm>
#include <deque>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/denoise/homology.h"

namespace cf {

SurgeryResult cut_and_cap(Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop, const SurgeryOptions& opts,
                          HomologyBasis* homology) {
  const std::size_t k = loop.size();
  if (k < 3) throw PreconditionError("surgery: a loop needs at least 3 vertices (got " + std::to_string(k) + ")");
  {
    std::unordered_set<int> seen;
    for (auto v : loop) {
      if (!seen.insert(v.idx()).second)
        throw PreconditionError("surgery: loop is not simple (vertex " + std::to_string(v.idx()) + " repeats)");
      if (mesh.is_boundary(v))
        throw PreconditionError("surgery: loop vertex " + std::to_string(v.idx()) + " lies on the boundary");
    }
  }
  std::vector<Mesh::HalfedgeHandle> h(k);
  for (std::size_t i = 0; i < k; ++i) {
    h[i] = mesh.find_halfedge(loop[i], loop[(i + 1) % k]);
    if (!h[i].is_valid())
      throw PreconditionError("surgery: loop vertices " + std::to_string(loop[i].idx()) + " and " +
                              std::to_string(loop[(i + 1) % k].idx()) + " share no edge");
  }
  std::unordered_set<int> on_loop;
  for (auto v : loop) on_loop.insert(v.idx());

  // 1. Gather, before any change: the interior outgoing halfedges of each left fan, and the
  //    left faces (faces left of some h[i]).
  std::vector<std::vector<Mesh::HalfedgeHandle>> fan(k);
  for (std::size_t i = 0; i < k; ++i) {
    const auto stop = mesh.opposite_halfedge_handle(h[(i + k - 1) % k]);
    auto o = mesh.ccw_rotated_halfedge_handle(h[i]);
    std::size_t guard = 0;
    while (o != stop) {
      fan[i].push_back(o);
      o = mesh.ccw_rotated_halfedge_handle(o);
      if (++guard > 1000000) throw Error("surgery: corrupt vertex fan");
    }
  }
  std::vector<Mesh::FaceHandle> left_faces;
  for (std::size_t i = 0; i < k; ++i) left_faces.push_back(mesh.face_handle(h[i]));
  for (std::size_t i = 0; i < k; ++i)
    for (auto o : fan[i]) left_faces.push_back(mesh.face_handle(o));
  std::sort(left_faces.begin(), left_faces.end());
  left_faces.erase(std::unique(left_faces.begin(), left_faces.end()), left_faces.end());
  std::vector<std::array<Mesh::HalfedgeHandle, 3>> face_cycle(left_faces.size());
  for (std::size_t j = 0; j < left_faces.size(); ++j) {
    auto a = mesh.halfedge_handle(left_faces[j]);
    face_cycle[j] = {a, mesh.next_halfedge_handle(a), mesh.next_halfedge_handle(mesh.next_halfedge_handle(a))};
  }

  // 2. Left copies and the new edges y_i: left^i -> left^(i+1) (x_i = opposite, boundary).
  SurgeryResult r;
  r.right_ring = loop;
  for (std::size_t i = 0; i < k; ++i) r.left_ring.push_back(mesh.add_vertex(mesh.point(loop[i])));
  std::vector<Mesh::HalfedgeHandle> y(k), x(k);
  std::unordered_map<int, Mesh::HalfedgeHandle> repl;
  for (std::size_t i = 0; i < k; ++i) {
    y[i] = mesh.new_edge(r.left_ring[i], r.left_ring[(i + 1) % k]);
    x[i] = mesh.opposite_halfedge_handle(y[i]);
    repl[h[i].idx()] = y[i];
  }
  // 3. Re-point the left fans to the left copies.
  for (std::size_t i = 0; i < k; ++i)
    for (auto o : fan[i]) mesh.set_vertex_handle(mesh.opposite_halfedge_handle(o), r.left_ring[i]);
  // 4. Relink left faces with y_i in place of h_i.
  auto R = [&](Mesh::HalfedgeHandle a) {
    auto it = repl.find(a.idx());
    return it == repl.end() ? a : it->second;
  };
  for (std::size_t j = 0; j < left_faces.size(); ++j) {
    const auto& c = face_cycle[j];
    for (int t = 0; t < 3; ++t) {
      mesh.set_next_halfedge_handle(R(c[t]), R(c[(t + 1) % 3]));
      mesh.set_face_handle(R(c[t]), left_faces[j]);
    }
    mesh.set_halfedge_handle(left_faces[j], R(c[0]));
  }
  // 5. Boundary rings: right ring is h_0 -> h_1 -> ...; left ring is x_i -> x_(i-1).
  for (std::size_t i = 0; i < k; ++i) {
    mesh.set_face_handle(h[i], Mesh::FaceHandle());
    mesh.set_face_handle(x[i], Mesh::FaceHandle());
  }
  for (std::size_t i = 0; i < k; ++i) {
    mesh.set_next_halfedge_handle(h[i], h[(i + 1) % k]);
    mesh.set_next_halfedge_handle(x[i], x[(i + k - 1) % k]);
    mesh.set_halfedge_handle(loop[i], h[i]);
    mesh.set_halfedge_handle(r.left_ring[i], x[(i + k - 1) % k]);
  }

  // 6. Pull each ring into its own side (after the split, a ring vertex's non-ring neighbours are
  //    exactly its own side's).
  auto pull = [&](const std::vector<Mesh::VertexHandle>& ring) {
    std::unordered_set<int> in_ring;
    for (auto v : ring) in_ring.insert(v.idx());
    std::vector<Vec3> target(ring.size());
    for (std::size_t i = 0; i < ring.size(); ++i) {
      Vec3 c(0, 0, 0);
      int n = 0;
      for (auto w : mesh.vv_range(ring[i]))
        if (!in_ring.count(w.idx())) {
          c += mesh.point(w);
          ++n;
        }
      if (n == 0) {  // all neighbours on the ring: use the barycentres of its faces
        for (auto f : mesh.vf_range(ring[i])) {
          Vec3 b(0, 0, 0);
          for (auto w : mesh.fv_range(f)) b += mesh.point(w);
          c += b / 3.0;
          ++n;
        }
      }
      target[i] = n ? c / double(n) : mesh.point(ring[i]);
    }
    for (std::size_t i = 0; i < ring.size(); ++i)
      mesh.point(ring[i]) += opts.ring_pull * (target[i] - mesh.point(ring[i]));
  };
  pull(r.left_ring);
  pull(r.right_ring);

  // 7. Caps: a fan from the centroid of each ring.
  auto cap = [&](const std::vector<Mesh::HalfedgeHandle>& ring_halfedges, const std::vector<Mesh::VertexHandle>& ring) {
    Vec3 c(0, 0, 0);
    for (auto v : ring) c += mesh.point(v);
    const auto w = mesh.add_vertex(c / double(ring.size()));
    for (auto b : ring_halfedges) {
      const auto f = mesh.add_face(mesh.from_vertex_handle(b), mesh.to_vertex_handle(b), w);
      if (!f.is_valid()) throw Error("surgery: could not add a cap triangle");
    }
    return w;
  };
  r.right_cap = cap(h, r.right_ring);
  r.left_cap = cap(x, r.left_ring);

  // 8. Classes of the new edges: y_i copies h_i; spokes are prefix sums along the ring, so that
  //    every cap triangle sums to zero (the ring itself is the loop's class, which the caller
  //    quotients out).
  if (homology) {
    const int W = homology->words();
    for (std::size_t i = 0; i < k; ++i) {
      std::vector<std::uint64_t> c(homology->edge_class(mesh.edge_handle(h[i])),
                                   homology->edge_class(mesh.edge_handle(h[i])) + W);
      homology->set_edge_class(mesh.edge_handle(y[i]), c.data());
    }
    auto spokes = [&](Mesh::VertexHandle w, const std::vector<Mesh::VertexHandle>& ring) {
      std::vector<std::uint64_t> acc(W, 0);
      for (std::size_t i = 0; i < k; ++i) {
        const auto he = mesh.find_halfedge(w, ring[i]);
        homology->set_edge_class(mesh.edge_handle(he), acc.data());
        const auto ring_edge = mesh.edge_handle(mesh.find_halfedge(ring[i], ring[(i + 1) % k]));
        xor_into(acc.data(), homology->edge_class(ring_edge), W);
      }
    };
    spokes(r.right_cap, r.right_ring);
    spokes(r.left_cap, r.left_ring);
  }
  return r;
}

bool vertices_connected(const Mesh& mesh, Mesh::VertexHandle a, Mesh::VertexHandle b) {
  if (a == b) return true;
  // mark: 1 = reached from a, 2 = reached from b
  std::unordered_map<int, std::uint8_t> mark;
  std::deque<Mesh::VertexHandle> qa{a}, qb{b};
  mark[a.idx()] = 1;
  mark[b.idx()] = 2;
  while (!qa.empty() && !qb.empty()) {
    const bool from_a = qa.size() <= qb.size();
    auto& q = from_a ? qa : qb;
    const std::uint8_t me = from_a ? 1 : 2;
    const std::size_t layer = q.size();
    for (std::size_t i = 0; i < layer; ++i) {
      const auto v = q.front();
      q.pop_front();
      for (auto w : mesh.vv_range(v)) {
        auto it = mark.find(w.idx());
        if (it == mark.end()) {
          mark[w.idx()] = me;
          q.push_back(w);
        } else if (it->second != me) {
          return true;
        }
      }
    }
  }
  return false;
}

}  // namespace cf
