#include "colonflat/denoise/surgery.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <unordered_map>
#include <unordered_set>

#include "colonflat/core/error.h"
#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/face_grid.h"
#include "colonflat/denoise/homology.h"

namespace cf {

namespace {
// Loops up to this many vertices get triangulated caps (O(k^3) time, O(k^2) memory: about 10 s
// and 0.7 GB at 2000 vertices); longer ones get concentric-ring caps in one placement.
constexpr std::size_t kMaxTriangulatedLoop = 2000;
}  // namespace

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
  for (std::size_t i = 0; i < k; ++i) {
    const Vec3 p = mesh.point(loop[i]);  // a copy: add_vertex may reallocate the point array
    r.left_ring.push_back(mesh.add_vertex(p));
  }
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

  // 6. Side targets: after the split, a ring vertex's non-ring neighbours are exactly its own
  //    side's; a ring is pulled towards the centroid of those (face barycentres as a fallback).
  auto side_targets = [&](const std::vector<Mesh::VertexHandle>& ring) {
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
      if (n == 0) {
        for (auto f : mesh.vf_range(ring[i])) {
          Vec3 b(0, 0, 0);
          for (auto w : mesh.fv_range(f)) b += mesh.point(w);
          c += b / 3.0;
          ++n;
        }
      }
      target[i] = n ? c / double(n) : mesh.point(ring[i]);
      Vec3 nrm(0, 0, 0);
      for (auto f : mesh.vf_range(ring[i])) {
        auto it = mesh.cfv_iter(f);
        const Vec3 a = mesh.point(*it), b = mesh.point(*++it), d = mesh.point(*++it);
        nrm += OpenMesh::cross(b - a, d - a);
      }
      if (nrm.norm() > 0) {
        nrm /= nrm.norm();
        const Vec3 move = target[i] - mesh.point(ring[i]);
        target[i] = mesh.point(ring[i]) + move - OpenMesh::dot(move, nrm) * nrm;
      }
    }
    return target;
  };
  const std::vector<Vec3> target_left = side_targets(r.left_ring), target_right = side_targets(r.right_ring);
  std::vector<Vec3> p0(k);
  for (std::size_t i = 0; i < k; ++i) p0[i] = mesh.point(loop[i]);

  // 6b. Classes of the left copies of the loop edges (needed by the caps): y_i copies h_i.
  const int W = homology ? homology->words() : 0;
  if (homology) {
    for (std::size_t i = 0; i < k; ++i) {
      std::vector<std::uint64_t> c(homology->edge_class(mesh.edge_handle(h[i])),
                                   homology->edge_class(mesh.edge_handle(h[i])) + W);
      homology->set_edge_class(mesh.edge_handle(y[i]), c.data());
    }
  }

  // 7. Caps (topology): a disk spanning each ring, made of m concentric rings around a centre
  //    vertex (m = 1: the paper's fan). Classes: each cap vertex gets a potential P (ring vertex
  //    i: prefix sum of the ring's edge classes; interior: 0) and each new edge (x, y) the class
  //    P(x) ^ P(y), so every cap triangle sums to zero (the closing one to the loop's class,
  //    which the caller quotients out).
  struct Cap {
    std::vector<std::vector<Mesh::VertexHandle>> rings;  // rings[0] = the cut ring, boundary order
    Mesh::VertexHandle centre;
    std::vector<Mesh::FaceHandle> faces;
  };
  auto make_cap = [&](const std::vector<Mesh::HalfedgeHandle>& ring_halfedges) {
    Cap cap;
    const std::size_t n = ring_halfedges.size();
    std::vector<Mesh::VertexHandle> a(n);
    for (std::size_t i = 0; i < n; ++i) a[i] = mesh.from_vertex_handle(ring_halfedges[i]);
    const int m = std::max(1, std::min(opts.cap_rings, static_cast<int>(n) / 4));
    cap.rings.push_back(a);
    for (int j = 1; j < m; ++j) {
      std::vector<Mesh::VertexHandle> rj(n);
      for (std::size_t i = 0; i < n; ++i) rj[i] = mesh.add_vertex(Vec3(0, 0, 0));
      cap.rings.push_back(std::move(rj));
    }
    cap.centre = mesh.add_vertex(Vec3(0, 0, 0));
    auto add = [&](Mesh::VertexHandle x, Mesh::VertexHandle y2, Mesh::VertexHandle z) {
      const auto f = mesh.add_face(x, y2, z);
      if (!f.is_valid()) throw Error("surgery: could not add a cap triangle");
      cap.faces.push_back(f);
    };
    for (int j = 0; j + 1 < m; ++j)
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t i1 = (i + 1) % n;
        add(cap.rings[j][i], cap.rings[j][i1], cap.rings[j + 1][i1]);
        add(cap.rings[j][i], cap.rings[j + 1][i1], cap.rings[j + 1][i]);
      }
    for (std::size_t i = 0; i < n; ++i) add(cap.rings[m - 1][i], cap.rings[m - 1][(i + 1) % n], cap.centre);
    if (homology) {
      std::unordered_map<int, std::vector<std::uint64_t>> P;
      std::vector<std::uint64_t> acc(W, 0);
      for (std::size_t i = 0; i < n; ++i) {
        P[a[i].idx()] = acc;
        xor_into(acc.data(), homology->edge_class(mesh.edge_handle(ring_halfedges[i])), W);
      }
      const std::vector<std::uint64_t> zero(W, 0);
      auto pot = [&](Mesh::VertexHandle v) -> const std::vector<std::uint64_t>& {
        auto it = P.find(v.idx());
        return it == P.end() ? zero : it->second;
      };
      std::vector<std::uint64_t> cls(W);
      std::vector<Mesh::VertexHandle> inner;
      for (int j = 1; j < m; ++j) inner.insert(inner.end(), cap.rings[j].begin(), cap.rings[j].end());
      inner.push_back(cap.centre);
      for (auto v : inner)  // every new edge has an interior endpoint
        for (auto he : mesh.voh_range(v)) {
          const auto& q0 = pot(v);
          const auto& q1 = pot(mesh.to_vertex_handle(he));
          for (int i = 0; i < W; ++i) cls[i] = q0[i] ^ q1[i];
          homology->set_edge_class(mesh.edge_handle(he), cls.data());
        }
    }
    return cap;
  };
  // 7a. With a guard, loops up to kMaxTriangulatedLoop vertices first try minimum-area
  //     triangulations of the pulled rings: no interior vertex; on an elongated loop around a
  //     thin curved band they join opposite sides and follow the band, where a spanning minimal
  //     surface would cut through its wall. If the plain one intersects something, the dynamic
  //     programme runs again over triangles that intersect nothing (surface, other cap, existing
  //     edges). Kept when neither the caps nor the faces around the pulled rings intersect
  //     anything; tried for several ring placements (pulls, tangential or along side edges).
  if (opts.guard && k <= kMaxTriangulatedLoop) {
    std::vector<Mesh::VertexHandle> order_r = r.right_ring, order_l{r.left_ring[0]};
    for (std::size_t i = k - 1; i >= 1; --i) order_l.push_back(r.left_ring[i]);  // x_(k-1) -> ... -> x_0
    // Edge targets: the far end of the side edge most across the ring (direction least aligned
    // with the ring's tangent). A ring vertex moved along an edge of its own side stays on the
    // old surface, which keeps the faces around it from folding where the surface is creased
    // (marching-cubes junctions) and the averaged normal of the tangential target misleads.
    auto edge_targets = [&](const std::vector<Mesh::VertexHandle>& ring) {
      std::unordered_set<int> in_ring;
      for (auto v : ring) in_ring.insert(v.idx());
      std::vector<Vec3> target(ring.size());
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Vec3 p = mesh.point(ring[i]);
        Vec3 tangent = mesh.point(ring[(i + 1) % k]) - mesh.point(ring[(i + k - 1) % k]);
        if (tangent.norm() > 0) tangent /= tangent.norm();
        target[i] = p;
        double best = 2;
        for (auto w : mesh.vv_range(ring[i])) {
          if (in_ring.count(w.idx())) continue;
          Vec3 d = mesh.point(w) - p;
          const double len = d.norm();
          if (len == 0) continue;
          const double align = std::fabs(OpenMesh::dot(d / len, tangent));
          if (align < best) {
            best = align;
            target[i] = mesh.point(w);
          }
        }
      }
      return target;
    };
    const std::vector<Vec3> edge_left = edge_targets(r.left_ring), edge_right = edge_targets(r.right_ring);
    std::vector<Mesh::FaceHandle> ring_faces;
    for (const auto* ring : {&r.left_ring, &r.right_ring})
      for (auto v : *ring)
        for (auto f : mesh.vf_range(v)) ring_faces.push_back(f);
    std::sort(ring_faces.begin(), ring_faces.end());
    ring_faces.erase(std::unique(ring_faces.begin(), ring_faces.end()), ring_faces.end());
    // A diagonal that is already a mesh edge (a chord on that side) would make the cap non-manifold.
    auto chord = [&](Mesh::VertexHandle a, Mesh::VertexHandle b) { return mesh.find_halfedge(a, b).is_valid(); };
    auto triangulate = [&](const std::vector<Mesh::VertexHandle>& ring, bool avoid,
                           const std::vector<std::array<int, 3>>& other) {
      return triangulate_ring(mesh, ring, chord, avoid ? opts.guard : nullptr, other);
    };
    std::vector<std::array<int, 3>> tri_r, tri_l;
    bool found = false;
    struct Try {
      double pull;
      bool along_edge;
    };
    const double p1 = opts.ring_pull;
    for (const Try tr : {Try{p1, false}, Try{p1, true}, Try{0.4, false}, Try{0.4, true}, Try{0.15, false},
                         Try{0.15, true}, Try{0.08, true}}) {
      const double pull = tr.pull;
      if (pull <= 0) continue;
      const auto& tl = tr.along_edge ? edge_left : target_left;
      const auto& tg = tr.along_edge ? edge_right : target_right;
      for (std::size_t i = 0; i < k; ++i) {
        mesh.point(r.left_ring[i]) = p0[i] + pull * (tl[i] - p0[i]);
        mesh.point(r.right_ring[i]) = p0[i] + pull * (tg[i] - p0[i]);
      }
      for (auto f : ring_faces) opts.guard->insert(mesh, f);
      if (opts.guard->count_intersections(mesh, ring_faces) != 0) continue;
      for (bool avoid : {false, true}) {
        tri_r = triangulate(order_r, avoid, {});
        if (tri_r.empty()) continue;
        tri_l = triangulate(order_l, avoid, tri_r);
        if (tri_l.empty()) continue;
        std::vector<std::array<int, 3>> all = tri_r;
        all.insert(all.end(), tri_l.begin(), tri_l.end());
        if (opts.guard->count_triangles(mesh, all) == 0) {
          found = true;
          break;
        }
      }
      if (found) break;
    }
    if (found) {
      add_cap(mesh, tri_r, opts.guard, "surgery");  // ear order: each face joins the hole's boundary
      add_cap(mesh, tri_l, opts.guard, "surgery");
      if (homology) {
        auto classes = [&](const std::vector<Mesh::VertexHandle>& ring) {
          std::unordered_map<int, std::vector<std::uint64_t>> P;
          std::vector<std::uint64_t> acc(W, 0), cls(W);
          for (std::size_t i = 0; i < k; ++i) {
            P[ring[i].idx()] = acc;
            const auto he = mesh.find_halfedge(ring[i], ring[(i + 1) % k]);
            xor_into(acc.data(), homology->edge_class(mesh.edge_handle(he)), W);
          }
          for (std::size_t i = 0; i < k; ++i)
            for (auto he : mesh.voh_range(ring[i])) {
              const auto w = mesh.to_vertex_handle(he);
              auto it = P.find(w.idx());
              if (it == P.end()) continue;                                   // not a chord of this ring
              const std::size_t j = static_cast<std::size_t>(std::find(ring.begin(), ring.end(), w) - ring.begin());
              if (j == (i + 1) % k || i == (j + 1) % k) continue;           // a ring edge (old)
              for (int b = 0; b < W; ++b) cls[b] = P[ring[i].idx()][b] ^ it->second[b];
              homology->set_edge_class(mesh.edge_handle(he), cls.data());
            }
        };
        classes(order_r);
        classes(order_l);
      }
      r.right_cap = r.right_ring[0];
      r.left_cap = r.left_ring[0];
      r.intersections = 0;
      return r;
    }
  }

  Cap cap_right = make_cap(h);                                                             // h_0 -> h_1 -> ...
  Cap cap_left = make_cap(std::vector<Mesh::HalfedgeHandle>(x.rbegin(), x.rend()));  // x_(k-1) -> ... -> x_0
  r.right_cap = cap_right.centre;
  r.left_cap = cap_left.centre;

  // 8. Geometry. A placement = ring pull p (towards the side targets) + cap shape: interior rings
  //    interpolated towards the ring centroid and relaxed to a discrete minimal surface (uniform
  //    Laplacian, ring fixed), then bulged by `dome` (x mean ring edge) against the cap's normal,
  //    i.e. into its own side, so the two caps of one loop part even where the pull runs nearly
  //    in the cap's plane.
  auto place_cap = [&](Cap& cap, double dome) {
    const auto& a = cap.rings[0];
    const std::size_t n = a.size();
    const int m = static_cast<int>(cap.rings.size());
    Vec3 c(0, 0, 0);
    double edge = 0;
    for (std::size_t i = 0; i < n; ++i) {
      c += mesh.point(a[i]);
      edge += (mesh.point(a[(i + 1) % n]) - mesh.point(a[i])).norm();
    }
    c /= double(n);
    edge /= double(n);
    for (int j = 1; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i) {
        const double t = double(j) / m;
        mesh.point(cap.rings[j][i]) = (1 - t) * mesh.point(a[i]) + t * c;
      }
    mesh.point(cap.centre) = c;
    std::vector<Mesh::VertexHandle> inner;
    for (int j = 1; j < m; ++j) inner.insert(inner.end(), cap.rings[j].begin(), cap.rings[j].end());
    inner.push_back(cap.centre);
    std::vector<Vec3> next(inner.size());
    for (int it = 0; it < 20 * m && m > 1; ++it) {
      for (std::size_t q = 0; q < inner.size(); ++q) {
        Vec3 sum(0, 0, 0);
        int deg = 0;
        for (auto nb : mesh.vv_range(inner[q])) {
          sum += mesh.point(nb);
          ++deg;
        }
        next[q] = sum / double(deg);
      }
      for (std::size_t q = 0; q < inner.size(); ++q) mesh.point(inner[q]) = next[q];
    }
    if (dome != 0) {
      Vec3 nrm(0, 0, 0);
      for (auto f : cap.faces) {
        auto it = mesh.cfv_iter(f);
        const Vec3 p1 = mesh.point(*it), p2 = mesh.point(*++it), p3 = mesh.point(*++it);
        nrm += OpenMesh::cross(p2 - p1, p3 - p1);
      }
      if (nrm.norm() > 0) nrm /= nrm.norm();
      for (int j = 1; j < m; ++j) {
        const double t = double(j) / m;
        for (auto v : cap.rings[j]) mesh.point(v) -= dome * edge * (1 - (1 - t) * (1 - t)) * nrm;
      }
      mesh.point(cap.centre) -= dome * edge * nrm;
    }
  };
  auto place = [&](double pull, double dome) {
    for (std::size_t i = 0; i < k; ++i) {
      mesh.point(r.left_ring[i]) = p0[i] + pull * (target_left[i] - p0[i]);
      mesh.point(r.right_ring[i]) = p0[i] + pull * (target_right[i] - p0[i]);
    }
    place_cap(cap_left, dome);
    place_cap(cap_right, dome);
  };
  place(opts.ring_pull, 0.0);
  if (opts.guard) {
    // Faces whose geometry the placement moves: both caps and the faces around both rings.
    std::vector<Mesh::FaceHandle> moving = cap_left.faces;
    moving.insert(moving.end(), cap_right.faces.begin(), cap_right.faces.end());
    for (const auto* ring : {&r.left_ring, &r.right_ring})
      for (auto v : *ring)
        for (auto f : mesh.vf_range(v)) moving.push_back(f);
    std::sort(moving.begin(), moving.end());
    moving.erase(std::unique(moving.begin(), moving.end()), moving.end());
    auto refresh = [&]() {
      for (auto f : moving) opts.guard->insert(mesh, f);
    };
    refresh();
    std::size_t best = opts.guard->count_intersections(mesh, moving);
    double best_pull = opts.ring_pull, best_dome = 0;
    if (best > 0 && k <= kMaxTriangulatedLoop) {  // other placements (each a full check)
      for (double pull : {opts.ring_pull, 0.4, 0.15})
        for (double dome : {0.25, 0.5, 1.0, 0.0, -0.25}) {
          if (pull <= 0 && dome == 0) continue;
          place(pull, dome);
          refresh();
          const std::size_t n = opts.guard->count_intersections(mesh, moving);
          if (n < best) {
            best = n;
            best_pull = pull;
            best_dome = dome;
          }
          if (best == 0) break;
        }
      place(best_pull, best_dome);
      refresh();
    }
    r.intersections = best;
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
