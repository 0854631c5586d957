// analyze_topology against a slow, independent reference (an std::map edge table, breadth-first
// searches for components, orientations and boundary loops, fans by label propagation) on
// broken and valid meshes: every field of the report must be identical, down to the example
// ids, the component numbering and the last bit of the mean edge length.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <utility>

#include "colonflat/core/synthetic.h"
#include "colonflat/core/topology.h"

namespace cf {
namespace {

using Half = std::pair<int, int>;  // (face, corner k): the half-edge tri[k] -> tri[(k + 1) % 3]
using EdgeTable = std::map<std::pair<int, int>, std::vector<Half>>;

int corner_at(const std::array<int, 3>& t, int v) { return t[0] == v ? 0 : (t[1] == v ? 1 : 2); }

// Labels of the connected parts of a graph given as neighbour lists, numbered in order of the
// first node of each part.
std::vector<int> parts(const std::vector<std::vector<int>>& nbr) {
  std::vector<int> label(nbr.size(), -1);
  int next = 0;
  for (std::size_t s = 0; s < nbr.size(); ++s) {
    if (label[s] >= 0) continue;
    std::vector<int> stack{static_cast<int>(s)};
    label[s] = next;
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      for (int y : nbr[x])
        if (label[y] < 0) label[y] = next, stack.push_back(y);
    }
    ++next;
  }
  return label;
}

// Whether the faces of each component can be oriented: 2-colouring over manifold edges.
std::vector<bool> face_orientable(const TriangleList& m, const EdgeTable& edges, const std::vector<int>& comp, int n) {
  std::vector<std::vector<std::pair<int, int>>> nbr(m.triangles.size());  // (face, flip)
  for (const auto& [key, hs] : edges) {
    if (hs.size() != 2) continue;
    const int flip = m.triangles[hs[0].first][hs[0].second] == m.triangles[hs[1].first][hs[1].second];
    nbr[hs[0].first].push_back({hs[1].first, flip});
    nbr[hs[1].first].push_back({hs[0].first, flip});
  }
  std::vector<int> colour(m.triangles.size(), -1);
  std::vector<bool> ok(n, true);
  for (std::size_t s = 0; s < colour.size(); ++s) {
    if (colour[s] >= 0) continue;
    std::vector<int> stack{static_cast<int>(s)};
    colour[s] = 0;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (auto [g, flip] : nbr[f]) {
        if (colour[g] < 0) colour[g] = colour[f] ^ flip, stack.push_back(g);
        else if (colour[g] != (colour[f] ^ flip)) ok[comp[f]] = false;
      }
    }
  }
  return ok;
}

// Vertex v has one fan: its corners joined along its manifold edges form one part.
bool one_fan(const TriangleList& m, const EdgeTable& edges, int v) {
  std::vector<int> corners;  // 3 f + k
  for (std::size_t f = 0; f < m.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k)
      if (m.triangles[f][k] == v) corners.push_back(static_cast<int>(3 * f + k));
  std::vector<std::vector<int>> nbr(corners.size());
  auto local = [&](int f) {
    const int c = 3 * f + corner_at(m.triangles[f], v);
    return static_cast<int>(std::find(corners.begin(), corners.end(), c) - corners.begin());
  };
  for (const auto& [key, hs] : edges)
    if (hs.size() == 2 && (key.first == v || key.second == v)) {
      nbr[local(hs[0].first)].push_back(local(hs[1].first));
      nbr[local(hs[1].first)].push_back(local(hs[0].first));
    }
  const std::vector<int> label = parts(nbr);
  return *std::max_element(label.begin(), label.end()) == 0;
}

template <class T>
void example(std::vector<T>& v, const T& x) {
  if (v.size() < TopologyReport::kMaxExamples) v.push_back(x);
}

// Edges, examples and vertex marks from the map, in key order.
void reference_edges(const TriangleList& m, const EdgeTable& edges, TopologyReport& r, std::vector<char>& bad_vertex,
                     std::vector<char>& bad_face, std::vector<std::vector<int>>& boundary_nbr) {
  double sum = 0;
  for (const auto& [key, hs] : edges) {
    const auto& a = m.points[key.first];
    const auto& b = m.points[key.second];
    sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    const std::array<int, 2> e{key.first, key.second};
    if (hs.size() == 1) {
      ++r.boundary_edges, example(r.example_boundary_edges, e);
      boundary_nbr[e[0]].push_back(e[1]), boundary_nbr[e[1]].push_back(e[0]);
    } else if (hs.size() == 2) {
      if (m.triangles[hs[0].first][hs[0].second] == m.triangles[hs[1].first][hs[1].second])
        ++r.inconsistent_edges, example(r.example_inconsistent_edges, e);
    } else {
      ++r.nonmanifold_edges, example(r.example_nonmanifold_edges, e);
      bad_vertex[e[0]] = bad_vertex[e[1]] = 1;
      for (auto h : hs) bad_face[h.first] = 1;
    }
  }
  r.edges = edges.size();
  r.mean_edge_length = edges.empty() ? 0.0 : sum / static_cast<double>(edges.size());
}

TopologyReport reference_topology(const TriangleList& m) {
  TopologyReport r;
  const int P = static_cast<int>(m.points.size()), F = static_cast<int>(m.triangles.size());
  r.faces = F;
  EdgeTable edges;
  std::vector<std::vector<int>> faces_at(P);
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles[f][k], b = m.triangles[f][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back({f, k});
      if (faces_at[a].empty() || faces_at[a].back() != f) faces_at[a].push_back(f);
    }
  const double inf = std::numeric_limits<double>::infinity();
  r.bbox_min = {inf, inf, inf}, r.bbox_max = {-inf, -inf, -inf};
  for (int v = 0; v < P; ++v) {
    if (faces_at[v].empty()) {
      ++r.unreferenced_vertices;
      continue;
    }
    ++r.vertices;
    for (int a = 0; a < 3; ++a)
      r.bbox_min[a] = std::min(r.bbox_min[a], m.points[v][a]), r.bbox_max[a] = std::max(r.bbox_max[a], m.points[v][a]);
  }
  if (r.vertices == 0) {
    r.bbox_min = r.bbox_max = {0, 0, 0};
    return r;
  }
  std::vector<char> bad_vertex(P, 0), bad_face(F, 0);
  std::vector<std::vector<int>> boundary_nbr(P);
  reference_edges(m, edges, r, bad_vertex, bad_face, boundary_nbr);
  for (int v = 0; v < P; ++v)
    if (!faces_at[v].empty() && (bad_vertex[v] || !one_fan(m, edges, v)))
      bad_vertex[v] = 1, ++r.nonmanifold_vertices, example(r.example_nonmanifold_vertices, v);
  std::vector<std::vector<int>> face_nbr(F);
  for (const auto& fs : faces_at)
    for (int f : fs)
      for (int g : fs)
        if (f != g) face_nbr[f].push_back(g);
  const std::vector<int> comp = parts(face_nbr);
  const int n = F ? *std::max_element(comp.begin(), comp.end()) + 1 : 0;
  std::vector<ComponentTopology> cs(n);
  const std::vector<bool> orientable = face_orientable(m, edges, comp, n);
  for (int c = 0; c < n; ++c) cs[c].manifold = true, cs[c].orientable = orientable[c];
  for (int f = 0; f < F; ++f) ++cs[comp[f]].faces, cs[comp[f]].manifold = cs[comp[f]].manifold && !bad_face[f];
  for (int v = 0; v < P; ++v)
    if (!faces_at[v].empty()) ++cs[comp[faces_at[v][0]]].vertices, cs[comp[faces_at[v][0]]].manifold = cs[comp[faces_at[v][0]]].manifold && !bad_vertex[v];
  for (const auto& [key, hs] : edges) ++cs[comp[hs[0].first]].edges, cs[comp[hs[0].first]].boundary_edges += hs.size() == 1;
  const std::vector<int> loop = parts(boundary_nbr);
  std::vector<char> loop_seen(P, 0);
  for (int v = 0; v < P; ++v)
    if (!boundary_nbr[v].empty() && !loop_seen[loop[v]]) loop_seen[loop[v]] = 1, ++cs[comp[faces_at[v][0]]].boundary_loops;
  int genus = 0;
  bool all = true;
  for (auto& c : cs) {
    c.euler = static_cast<long long>(c.vertices) - static_cast<long long>(c.edges) + static_cast<long long>(c.faces);
    c.closed = c.boundary_edges == 0;
    if (c.manifold && c.orientable) c.genus = static_cast<int>((2 - c.euler - static_cast<long long>(c.boundary_loops)) / 2), genus += *c.genus;
    else all = false;
    r.boundary_loops += c.boundary_loops;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return cs[x].faces > cs[y].faces; });
  std::vector<int> new_id(n);
  for (int i = 0; i < n; ++i) new_id[order[i]] = i, r.components.push_back(cs[order[i]]);
  for (int f = 0; f < F; ++f) r.face_component.push_back(new_id[comp[f]]);
  r.euler = static_cast<long long>(r.vertices) - static_cast<long long>(r.edges) + F;
  r.closed = r.boundary_edges == 0;
  r.manifold = r.nonmanifold_edges == 0 && r.nonmanifold_vertices == 0;
  r.orientable = std::all_of(cs.begin(), cs.end(), [](const ComponentTopology& c) { return c.orientable; });
  r.consistently_oriented = r.inconsistent_edges == 0 && r.manifold;
  if (all) r.genus = genus;
  return r;
}

void expect_same(const TopologyReport& a, const TopologyReport& b) {
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.unreferenced_vertices, b.unreferenced_vertices);
  EXPECT_EQ(a.boundary_edges, b.boundary_edges);
  EXPECT_EQ(a.boundary_loops, b.boundary_loops);
  EXPECT_EQ(a.nonmanifold_edges, b.nonmanifold_edges);
  EXPECT_EQ(a.nonmanifold_vertices, b.nonmanifold_vertices);
  EXPECT_EQ(a.inconsistent_edges, b.inconsistent_edges);
  EXPECT_EQ(a.euler, b.euler);
  EXPECT_EQ(a.closed, b.closed);
  EXPECT_EQ(a.manifold, b.manifold);
  EXPECT_EQ(a.orientable, b.orientable);
  EXPECT_EQ(a.consistently_oriented, b.consistently_oriented);
  EXPECT_EQ(a.genus, b.genus);
  EXPECT_EQ(a.bbox_min, b.bbox_min);
  EXPECT_EQ(a.bbox_max, b.bbox_max);
  EXPECT_EQ(a.mean_edge_length, b.mean_edge_length);  // same edges summed in the same order: bit for bit
  EXPECT_EQ(a.example_boundary_edges, b.example_boundary_edges);
  EXPECT_EQ(a.example_nonmanifold_edges, b.example_nonmanifold_edges);
  EXPECT_EQ(a.example_inconsistent_edges, b.example_inconsistent_edges);
  EXPECT_EQ(a.example_nonmanifold_vertices, b.example_nonmanifold_vertices);
  EXPECT_EQ(a.face_component, b.face_component);
  ASSERT_EQ(a.components.size(), b.components.size());
  for (std::size_t c = 0; c < a.components.size(); ++c) {
    const auto &x = a.components[c], &y = b.components[c];
    EXPECT_EQ(x.vertices, y.vertices) << "component " << c;
    EXPECT_EQ(x.edges, y.edges) << "component " << c;
    EXPECT_EQ(x.faces, y.faces) << "component " << c;
    EXPECT_EQ(x.boundary_edges, y.boundary_edges) << "component " << c;
    EXPECT_EQ(x.boundary_loops, y.boundary_loops) << "component " << c;
    EXPECT_EQ(x.euler, y.euler) << "component " << c;
    EXPECT_EQ(x.closed, y.closed) << "component " << c;
    EXPECT_EQ(x.manifold, y.manifold) << "component " << c;
    EXPECT_EQ(x.orientable, y.orientable) << "component " << c;
    EXPECT_EQ(x.genus, y.genus) << "component " << c;
  }
}

// Random triangles over a few vertices: non-manifold edges and vertices, degenerate triangles
// (a repeated vertex), flipped and Moebius-like pieces, boundaries, several components and
// unreferenced vertices, all at once.
TriangleList random_soup(std::mt19937& rng, int points, int triangles, double degenerate) {
  TriangleList m;
  std::uniform_real_distribution<double> coord(-1, 1), unit(0, 1);
  std::uniform_int_distribution<int> id(0, points - 1);
  for (int i = 0; i < points; ++i) m.points.push_back({coord(rng), coord(rng), coord(rng)});
  for (int f = 0; f < triangles; ++f) {
    std::array<int, 3> t{id(rng), id(rng), id(rng)};
    if (unit(rng) >= degenerate)
      while (t[1] == t[0]) t[1] = id(rng);
    if (unit(rng) >= degenerate)
      while (t[2] == t[0] || t[2] == t[1]) t[2] = id(rng);
    m.triangles.push_back(t);
  }
  return m;
}

// Broken soups, from sparse (many components, boundaries) to dense (non-manifold everywhere),
// with and without degenerate triangles, give the reference's report field by field.
TEST(TopologyReference, RandomBrokenSoupsMatch) {
  std::mt19937 rng(12);
  for (int round = 0; round < 300; ++round) {
    const int points = 4 + round % 40, triangles = 1 + (round * 7) % 60;
    const TriangleList m = random_soup(rng, points, triangles, round % 3 == 0 ? 0.2 : 0.0);
    SCOPED_TRACE("round " + std::to_string(round));
    expect_same(analyze_topology(m), reference_topology(m));
  }
}

// Valid surfaces and surfaces with one local defect (flipped triangle, bowtie, torn fan, a
// duplicated face, a Moebius strip) give the reference's report field by field.
TEST(TopologyReference, SurfacesWithLocalDefectsMatch) {
  using namespace synthetic;
  std::vector<TriangleList> cases{sphere(1, 12, 6), torus(3, 1, 16, 8), torus_chain(3, 3, 1, 12, 8, 10),
                                  disk(1, 4, 12)};
  TriangleList flipped = sphere(1, 8, 4);
  std::swap(flipped.triangles[5][1], flipped.triangles[5][2]);
  cases.push_back(flipped);
  TriangleList torn = torus(3, 1, 12, 6);  // a vertex of one triangle replaced: a hole and a fan split
  torn.triangles[7][0] = torn.triangles[40][1];
  cases.push_back(torn);
  TriangleList twice = sphere(1, 8, 4);  // a face repeated: three triangles on its edges
  twice.triangles.push_back(twice.triangles[3]);
  cases.push_back(twice);
  TriangleList two = sphere(1, 8, 4);  // two spheres sharing one vertex: a bowtie vertex
  const std::size_t n = two.points.size();
  for (std::size_t v = 0; v < n; ++v) two.points.push_back({two.points[v][0] + 2, two.points[v][1], two.points[v][2]});
  for (std::size_t f = 0, nf = two.triangles.size(); f < nf; ++f) {
    auto t = two.triangles[f];
    for (int& v : t) v = v == 0 ? 0 : v + static_cast<int>(n);
    two.triangles.push_back(t);
  }
  cases.push_back(two);
  TriangleList strip;  // Moebius strip: 8 quads, the last one glued with a half twist
  for (int i = 0; i < 8; ++i) strip.points.push_back({double(i), 0, 0}), strip.points.push_back({double(i), 1, 0});
  for (int i = 0; i < 8; ++i) {
    const int a = 2 * i, b = 2 * i + 1, c = i < 7 ? 2 * i + 2 : 1, d = i < 7 ? 2 * i + 3 : 0;
    strip.triangles.push_back({a, c, b});
    strip.triangles.push_back({b, c, d});
  }
  cases.push_back(strip);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    expect_same(analyze_topology(cases[i]), reference_topology(cases[i]));
  }
}

// The reference itself is not vacuous: it sees the defects the random soups are built to have.
TEST(TopologyReference, RandomSoupsHaveTheDefectsTheyTest) {
  std::mt19937 rng(12);
  std::size_t nonmanifold = 0, boundary = 0, degenerate_bad = 0, several = 0, genus = 0;
  for (int round = 0; round < 300; ++round) {
    const TriangleList m = random_soup(rng, 4 + round % 40, 1 + (round * 7) % 60, round % 3 == 0 ? 0.2 : 0.0);
    const TopologyReport r = reference_topology(m);
    nonmanifold += r.nonmanifold_edges > 0 && r.nonmanifold_vertices > 0;
    boundary += r.boundary_loops > 0;
    degenerate_bad += round % 3 == 0 && !r.manifold;
    several += r.components.size() > 1;
    genus += r.genus.has_value();
  }
  EXPECT_GT(nonmanifold, 50u);
  EXPECT_GT(boundary, 200u);
  EXPECT_GT(degenerate_bad, 30u);
  EXPECT_GT(several, 20u);
  EXPECT_GT(genus, 5u);
}

}  // namespace
}  // namespace cf
