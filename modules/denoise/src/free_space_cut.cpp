// The free-space minimum cut (free_space_cut.h): cells, terminals, Boost.Graph's
// boykov_kolmogorov_max_flow on a compressed-sparse-row graph (the pattern of the segment stage's
// graph cut), then the cut's squares split into connected pieces and the disks among them kept.
#include "colonflat/denoise/free_space_cut.h"

#include "free_space_disks.h"

#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

namespace cf {

namespace {

using Csr = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                               boost::no_property, std::uint32_t, std::uint32_t>;
using CsrEdge = boost::graph_traits<Csr>::edge_descriptor;
constexpr int kTerminal = 1000;  // capacity of a terminal's link: more than its six squares
constexpr std::uint8_t kBlocked = 1, kSourceFace = 2, kSinkFace = 4;

// True when the projections of v on `axis` and of a box of half sizes h about the origin are apart.
bool apart_on(const Vec3& axis, const std::array<Vec3, 3>& v, const Vec3& h) {
  const double p0 = OpenMesh::dot(axis, v[0]), p1 = OpenMesh::dot(axis, v[1]), p2 = OpenMesh::dot(axis, v[2]);
  const double r = h[0] * std::fabs(axis[0]) + h[1] * std::fabs(axis[1]) + h[2] * std::fabs(axis[2]);
  return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

struct Lattice {
  const FreeSpaceBox& box;
  std::size_t cells() const { return std::size_t(box.n[0]) * box.n[1] * box.n[2]; }
  std::size_t stride(int a) const { return a == 0 ? 1 : a == 1 ? std::size_t(box.n[0]) : std::size_t(box.n[0]) * box.n[1]; }
  std::array<int, 3> coords(std::size_t c) const {
    return {int(c % box.n[0]), int(c / box.n[0] % box.n[1]), int(c / (std::size_t(box.n[0]) * box.n[1]))};
  }
  std::size_t index(int x, int y, int z) const { return x + std::size_t(box.n[0]) * (y + std::size_t(box.n[1]) * z); }
  // Lattice vertices (cell corners) by (x, y, z) in 0..n.
  long long vertex(int x, int y, int z) const { return x + (box.n[0] + 1LL) * (y + (box.n[1] + 1LL) * z); }
  Vec3 point(long long v) const {
    const long long nx = box.n[0] + 1LL, ny = box.n[1] + 1LL;
    return box.lo + box.cell * Vec3(double(v % nx), double(v / nx % ny), double(v / (nx * ny)));
  }
  // The neighbour of cell c along axis a, direction d (-1 or +1); false at the box's side.
  bool neighbour(std::size_t c, int a, int d, std::size_t* out) const {
    const int x = coords(c)[a] + d;
    if (x < 0 || x >= box.n[a]) return false;
    *out = d < 0 ? c - stride(a) : c + stride(a);
    return true;
  }
};

// Per cell: kBlocked when a triangle meets its cube, with the sides of those triangles, and an
// obstacle (a triangle of side >= 3: a group of faces the rings' flood did not reach) it holds;
// obstacles that share a cell are merged (the cells round them must lie on one side together).
struct CellMarks {
  std::vector<std::uint8_t> mark;
  std::vector<int> obstacle;  // per cell: -1 or a side >= 3 (see root())
  std::unordered_map<int, int> parent;
  int root(int g) {
    auto it = parent.try_emplace(g, g).first;
    while (it->second != g) {
      g = it->second;
      it = parent.find(g);
    }
    return g;
  }
};

CellMarks mark_cells(const Lattice& L, const std::vector<SidedTriangle>& tris) {
  CellMarks m{std::vector<std::uint8_t>(L.cells(), 0), std::vector<int>(L.cells(), -1), {}};
  const double c = L.box.cell, grow = 1e-6 * c;
  for (const auto& t : tris) {
    std::array<int, 3> a{}, b{};
    for (int k = 0; k < 3; ++k) {
      const double lo = std::min({t.p[0][k], t.p[1][k], t.p[2][k]}), hi = std::max({t.p[0][k], t.p[1][k], t.p[2][k]});
      a[k] = std::max(0, int(std::floor((lo - grow - L.box.lo[k]) / c)));
      b[k] = std::min(L.box.n[k] - 1, int(std::floor((hi + grow - L.box.lo[k]) / c)));
    }
    const std::uint8_t bits = kBlocked | (t.side == 1 ? kSourceFace : t.side == 2 ? kSinkFace : 0);
    for (int z = a[2]; z <= b[2]; ++z)
      for (int y = a[1]; y <= b[1]; ++y)
        for (int x = a[0]; x <= b[0]; ++x) {
          const Vec3 lo = L.box.lo + c * Vec3(x, y, z) - Vec3(grow, grow, grow);
          const Vec3 hi = lo + Vec3(c + 2 * grow, c + 2 * grow, c + 2 * grow);
          if (!triangle_meets_box(t.p, lo, hi)) continue;
          const std::size_t q = L.index(x, y, z);
          m.mark[q] |= bits;
          if (t.side < 3) continue;
          if (m.obstacle[q] < 0) {
            m.obstacle[q] = t.side;
            continue;
          }
          const int held = m.root(m.obstacle[q]), mine = m.root(t.side);
          if (held != mine) m.parent[mine] = held;
        }
  }
  return m;
}

struct Terminals {
  std::vector<std::int8_t> term;  // per cell: -1 blocked, 0 free, 1 source, 2 sink
  std::vector<std::vector<int>> hubs;  // per cell: the obstacles next to it (hub indices, sorted)
  int n_hubs = 0;
};

// Terminals: a free cell whose blocked 6-neighbours hold triangles of one side only; the hubs of
// the obstacles its blocked neighbours hold.
Terminals terminals(const Lattice& L, CellMarks& m, FreeSpaceCutStats* st) {
  Terminals t{std::vector<std::int8_t>(m.mark.size(), 0), std::vector<std::vector<int>>(m.mark.size()), 0};
  std::unordered_map<int, int> hub;  // obstacle root -> hub index
  for (std::size_t c = 0; c < m.mark.size(); ++c) {
    if (m.mark[c] & kBlocked) {
      t.term[c] = -1;
      continue;
    }
    ++st->free;
    std::uint8_t sides = 0;
    std::size_t d;
    for (int a = 0; a < 3; ++a)
      for (int dir : {-1, 1}) {
        if (!L.neighbour(c, a, dir, &d)) continue;
        sides |= m.mark[d] & (kSourceFace | kSinkFace);
        if (m.obstacle[d] >= 0)
          t.hubs[c].push_back(hub.try_emplace(m.root(m.obstacle[d]), int(hub.size())).first->second);
      }
    std::sort(t.hubs[c].begin(), t.hubs[c].end());
    t.hubs[c].erase(std::unique(t.hubs[c].begin(), t.hubs[c].end()), t.hubs[c].end());
    t.term[c] = sides == kSourceFace ? 1 : sides == kSinkFace ? 2 : 0;
    st->sources += t.term[c] == 1;
    st->sinks += t.term[c] == 2;
  }
  t.n_hubs = int(hub.size());
  return t;
}

struct FlowGraph {
  std::vector<std::uint32_t> node;  // per cell: node index, or UINT32_MAX (blocked)
  std::vector<std::size_t> cell;    // per cell node; then the hubs, S and T
  std::uint32_t hubs = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;  // sorted by source, then target
  std::vector<int> cap;
  std::vector<std::uint32_t> first;
  std::uint32_t n() const { return std::uint32_t(cell.size()); }
  std::uint32_t S() const { return n() + hubs; }
  std::uint32_t T() const { return n() + hubs + 1; }
  void add(std::uint32_t u, std::uint32_t v, int c) {
    edges.emplace_back(u, v);
    cap.push_back(c);
  }
};

// A cell's out-edges, sorted by target: free 6-neighbours (ascending), its hubs, S, T.
void cell_edges(const Lattice& L, const Terminals& t, std::uint32_t i, FlowGraph* g) {
  static const int order[6][2] = {{2, -1}, {1, -1}, {0, -1}, {0, 1}, {1, 1}, {2, 1}};
  std::size_t d;
  for (const auto& od : order)
    if (L.neighbour(g->cell[i], od[0], od[1], &d) && g->node[d] != UINT32_MAX) g->add(i, g->node[d], 1);
  for (int h : t.hubs[g->cell[i]]) g->add(i, g->n() + std::uint32_t(h), kTerminal);
  g->add(i, g->S(), 0);
  g->add(i, g->T(), t.term[g->cell[i]] == 2 ? kTerminal : 0);
}

// Nodes: the free cells, one hub per obstacle (joined to the cells next to it by links no cut
// takes: the obstacle lies wholly on one side), S and T.
FlowGraph flow_graph(const Lattice& L, const Terminals& t) {
  FlowGraph g;
  g.node.assign(t.term.size(), UINT32_MAX);
  for (std::size_t c = 0; c < t.term.size(); ++c)
    if (t.term[c] >= 0) {
      g.node[c] = std::uint32_t(g.cell.size());
      g.cell.push_back(c);
    }
  g.hubs = std::uint32_t(t.n_hubs);
  const std::uint32_t n = g.n();
  g.first.assign(g.T() + 2, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    g.first[i] = std::uint32_t(g.edges.size());
    cell_edges(L, t, i, &g);
  }
  std::vector<std::vector<std::uint32_t>> hub_cells(g.hubs);
  for (std::uint32_t i = 0; i < n; ++i)
    for (int h : t.hubs[g.cell[i]]) hub_cells[h].push_back(i);
  for (std::uint32_t h = 0; h < g.hubs; ++h) {
    g.first[n + h] = std::uint32_t(g.edges.size());
    for (std::uint32_t i : hub_cells[h]) g.add(n + h, i, kTerminal);
  }
  for (std::uint32_t from : {g.S(), g.T()}) {
    g.first[from] = std::uint32_t(g.edges.size());
    for (std::uint32_t i = 0; i < n; ++i) g.add(from, i, from == g.S() && t.term[g.cell[i]] == 1 ? kTerminal : 0);
  }
  g.first[g.T() + 1] = std::uint32_t(g.edges.size());
  return g;
}

// Per node: true when it is on the source side of the minimum cut (Boykov-Kolmogorov: black).
std::vector<char> source_side(const FlowGraph& g, FreeSpaceCutStats* st) {
  std::vector<CsrEdge> rev(g.edges.size());
  for (std::uint32_t e = 0; e < g.edges.size(); ++e) {
    const auto [u, v] = g.edges[e];
    const auto r = std::lower_bound(g.edges.begin() + g.first[v], g.edges.begin() + g.first[v + 1], std::make_pair(v, u));
    rev[e] = CsrEdge(v, std::uint32_t(r - g.edges.begin()));
  }
  const std::uint32_t n = g.n(), nodes = g.T() + 1;
  Csr csr(boost::edges_are_sorted, g.edges.begin(), g.edges.end(), nodes);
  std::vector<int> cap = g.cap, res(cap.size(), 0);
  std::vector<boost::default_color_type> color(nodes);
  std::vector<CsrEdge> pred(nodes);
  std::vector<long> dist(nodes, 0);
  auto eim = boost::get(boost::edge_index, csr);
  auto vim = boost::get(boost::vertex_index, csr);
  st->flow = boost::boykov_kolmogorov_max_flow(
      csr, boost::make_iterator_property_map(cap.begin(), eim), boost::make_iterator_property_map(res.begin(), eim),
      boost::make_iterator_property_map(rev.begin(), eim), boost::make_iterator_property_map(pred.begin(), vim),
      boost::make_iterator_property_map(color.begin(), vim), boost::make_iterator_property_map(dist.begin(), vim), vim,
      g.S(), g.T());
  const auto black = boost::color_traits<boost::default_color_type>::black();
  std::vector<char> in(n);
  for (std::uint32_t i = 0; i < n; ++i) in[i] = color[i] == black;
  return in;
}

// The squares between source-side nodes and free cells off it, as lattice-vertex corners with
// the right-hand normal pointing away from the source side.
std::vector<std::array<long long, 4>> cut_squares(const Lattice& L, const FlowGraph& g, const std::vector<char>& in) {
  std::vector<std::array<long long, 4>> sq;
  for (std::uint32_t i = 0; i < g.cell.size(); ++i) {
    if (!in[i]) continue;
    const auto c = L.coords(g.cell[i]);
    for (int a = 0; a < 3; ++a)
      for (int d : {-1, 1}) {
        std::size_t nb;
        if (!L.neighbour(g.cell[i], a, d, &nb) || g.node[nb] == UINT32_MAX || in[g.node[nb]]) continue;
        const int b = (a + 1) % 3, e = (a + 2) % 3;
        std::array<int, 3> p = c;
        p[a] += d > 0 ? 1 : 0;
        std::array<long long, 4> q;
        const int off[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (int k = 0; k < 4; ++k) {
          std::array<int, 3> v = p;
          v[b] += off[k][0];
          v[e] += off[k][1];
          q[k] = L.vertex(v[0], v[1], v[2]);
        }
        if (d < 0) std::swap(q[1], q[3]);  // normal along -a
        sq.push_back(q);
      }
  }
  return sq;
}

}  // namespace

bool triangle_meets_box(const std::array<Vec3, 3>& t, const Vec3& lo, const Vec3& hi) {
  const Vec3 c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  const std::array<Vec3, 3> v{t[0] - c, t[1] - c, t[2] - c};
  const Vec3 axes[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  for (const auto& a : axes)
    if (apart_on(a, v, h)) return false;
  if (apart_on(OpenMesh::cross(v[1] - v[0], v[2] - v[0]), v, h)) return false;
  for (int i = 0; i < 3; ++i)
    for (const auto& a : axes)
      if (apart_on(OpenMesh::cross(a, v[(i + 1) % 3] - v[i]), v, h)) return false;
  return true;
}

std::vector<CutDisk> free_space_cut(const FreeSpaceBox& box, const std::vector<SidedTriangle>& tris,
                                    FreeSpaceCutStats* stats) {
  FreeSpaceCutStats local;
  FreeSpaceCutStats* st = stats ? stats : &local;
  *st = FreeSpaceCutStats{};
  const Lattice L{box};
  st->cells = L.cells();
  CellMarks marks = mark_cells(L, tris);
  const Terminals term = terminals(L, marks, st);
  if (st->sources == 0 || st->sinks == 0) return {};
  const FlowGraph g = flow_graph(L, term);
  const std::vector<char> in = source_side(g, st);
  const auto squares = cut_squares(L, g, in);
  st->squares = squares.size();
  std::vector<CutDisk> disks = detail::cut_disks(squares, [&L](long long v) { return L.point(v); }, &st->pieces);
  st->disks = disks.size();
  return disks;
}

}  // namespace cf
