// The disks among a free-space cut's pieces (free_space_disks.h).
#include "free_space_disks.h"

#include <algorithm>
#include <cstdint>
#include <deque>
#include <numeric>
#include <unordered_map>

namespace cf::detail {

namespace {

constexpr int kNormalPasses = 4;
// A piece with holes counts as a disk with them closed when each hole's rim has at most this
// share of the outer boundary's vertices (the cut ends round thin spots where a left-side and a
// right-side wall come within a cell, e.g. the two caps of a severed pinch).
constexpr std::size_t kMaxHoleShare = 4;

struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(int a, int b) { parent[find(a)] = find(b); }
};

// The squares with local vertex ids and their edges: per undirected edge the squares using it.
struct SquareComplex {
  std::vector<long long> key;  // per vertex: lattice key
  std::vector<std::array<int, 4>> quads;
  std::unordered_map<std::uint64_t, std::vector<int>> edge_quads;
  std::uint64_t edge(int a, int b) const {
    return std::uint64_t(std::min(a, b)) * key.size() + std::uint64_t(std::max(a, b));
  }
  const std::vector<int>& quads_on(int a, int b) const { return edge_quads.at(edge(a, b)); }
};

SquareComplex square_complex(const std::vector<std::array<long long, 4>>& squares) {
  SquareComplex sc;
  std::unordered_map<long long, int> id;
  for (const auto& s : squares) {
    std::array<int, 4> q;
    for (int k = 0; k < 4; ++k) {
      auto [it, added] = id.try_emplace(s[k], int(sc.key.size()));
      if (added) sc.key.push_back(s[k]);
      q[k] = it->second;
    }
    sc.quads.push_back(q);
  }
  for (std::size_t f = 0; f < sc.quads.size(); ++f)
    for (int k = 0; k < 4; ++k) sc.edge_quads[sc.edge(sc.quads[f][k], sc.quads[f][(k + 1) % 4])].push_back(int(f));
  return sc;
}

// Pieces: squares joined across edges that exactly two squares share; a piece with an edge of
// more than two squares is marked bad.
std::vector<std::vector<int>> pieces_of(const SquareComplex& sc, std::vector<char>* bad) {
  DisjointSets ds(sc.quads.size());
  for (const auto& [e, qs] : sc.edge_quads)
    if (qs.size() == 2) ds.join(qs[0], qs[1]);
  std::unordered_map<int, int> piece;
  std::vector<std::vector<int>> out;
  for (std::size_t f = 0; f < sc.quads.size(); ++f) {
    auto [it, added] = piece.try_emplace(ds.find(int(f)), int(out.size()));
    if (added) out.emplace_back();
    out[it->second].push_back(int(f));
  }
  bad->assign(out.size(), 0);
  for (const auto& [e, qs] : sc.edge_quads)
    if (qs.size() > 2)
      for (int f : qs) (*bad)[piece.at(ds.find(f))] = 1;
  return out;
}

// True when every vertex's squares in `piece` form one fan (joined through edges at the vertex).
bool single_fans(const SquareComplex& sc, const std::vector<int>& piece) {
  std::unordered_map<int, std::vector<int>> around;  // vertex -> its squares
  for (int f : piece)
    for (int v : sc.quads[f]) around[v].push_back(f);
  for (const auto& [v, fs] : around) {
    DisjointSets ds(fs.size());
    for (std::size_t i = 0; i < fs.size(); ++i) {
      const auto& q = sc.quads[fs[i]];
      const int k = int(std::find(q.begin(), q.end(), v) - q.begin());
      for (int w : {q[(k + 1) % 4], q[(k + 3) % 4]})
        for (int g : sc.quads_on(v, w))
          if (g != fs[i]) ds.join(int(i), int(std::find(fs.begin(), fs.end(), g) - fs.begin()));
    }
    for (std::size_t i = 0; i < fs.size(); ++i)
      if (ds.find(int(i)) != ds.find(0)) return false;
  }
  return true;
}

// The piece's boundary loops (vertices in the squares' direction), or none when a vertex starts
// two boundary edges; *edges receives the piece's edge count.
std::vector<std::vector<int>> boundary_loops(const SquareComplex& sc, const std::vector<int>& piece, std::size_t* edges) {
  std::unordered_map<int, int> next;
  std::size_t twice = 0;
  for (int f : piece)
    for (int k = 0; k < 4; ++k) {
      const int a = sc.quads[f][k], b = sc.quads[f][(k + 1) % 4];
      if (sc.quads_on(a, b).size() == 2) {
        ++twice;
        continue;
      }
      if (!next.emplace(a, b).second) return {};
    }
  *edges = next.size() + twice / 2;
  std::vector<int> starts;
  for (const auto& [a, b] : next) starts.push_back(a);
  std::sort(starts.begin(), starts.end());  // loops in the same order whatever the hash order
  std::unordered_map<int, char> used;
  std::vector<std::vector<int>> loops;
  for (int a : starts) {
    if (used[a]) continue;
    loops.emplace_back();
    for (int v = a; !used[v]; v = next.at(v)) {
      used[v] = 1;
      loops.back().push_back(v);
    }
  }
  return loops;
}

// Normals: each point's squares' mean, then kNormalPasses times the mean of the normals of the
// corners of its squares (a staircase's corner normals turn to the surface it steps along, so the
// two caps offset along them stay apart where the boundary steps).
void smooth_normals(CutDisk* d) {
  for (auto& n : d->normals)
    if (n.norm() > 0) n /= n.norm();
  for (int pass = 0; pass < kNormalPasses; ++pass) {
    std::vector<Vec3> sum(d->normals.size(), Vec3(0, 0, 0));
    for (const auto& q : d->quads) {
      const Vec3 mean = d->normals[q[0]] + d->normals[q[1]] + d->normals[q[2]] + d->normals[q[3]];
      for (int v : q) sum[v] += mean;
    }
    for (std::size_t v = 0; v < sum.size(); ++v)
      if (sum[v].norm() > 0) d->normals[v] = sum[v] / sum[v].norm();
  }
}

// The piece as a CutDisk: its own vertex ids, normals, squares in breadth-first order from the
// boundary (loops[0]), the other loops as holes.
CutDisk make_disk(const SquareComplex& sc, const std::vector<int>& piece, const std::vector<std::vector<int>>& loops,
                  const std::function<Vec3(long long)>& point) {
  const std::vector<int>& loop = loops[0];
  CutDisk d;
  std::unordered_map<int, int> local;
  auto id = [&](int v) {
    auto [it, added] = local.try_emplace(v, int(d.points.size()));
    if (added) {
      d.points.push_back(point(sc.key[v]));
      d.normals.emplace_back(0, 0, 0);
    }
    return it->second;
  };
  for (int v : loop) d.boundary.push_back(id(v));
  std::unordered_map<int, char> seen;
  std::deque<int> queue;
  for (int f : piece) seen[f] = 0;
  for (std::size_t i = 0; i < loop.size(); ++i)
    for (int f : sc.quads_on(loop[i], loop[(i + 1) % loop.size()]))
      if (seen.count(f) && !seen[f]) seen[f] = 1, queue.push_back(f);
  while (!queue.empty()) {
    const int f = queue.front();
    queue.pop_front();
    const auto& q = sc.quads[f];
    std::array<int, 4> out;
    for (int k = 0; k < 4; ++k) out[k] = id(q[k]);
    const Vec3 nrm = OpenMesh::cross(d.points[out[1]] - d.points[out[0]], d.points[out[3]] - d.points[out[0]]);
    for (int v : out) d.normals[v] += nrm;
    d.quads.push_back(out);
    for (int k = 0; k < 4; ++k)
      for (int g : sc.quads_on(q[k], q[(k + 1) % 4]))
        if (!seen[g]) seen[g] = 1, queue.push_back(g);
  }
  smooth_normals(&d);
  for (std::size_t h = 1; h < loops.size(); ++h) {
    d.holes.emplace_back();
    for (int v : loops[h]) d.holes.back().push_back(local.at(v));
  }
  return d;
}

}  // namespace

std::vector<CutDisk> cut_disks(const std::vector<std::array<long long, 4>>& squares,
                               const std::function<Vec3(long long)>& point, std::size_t* pieces) {
  const SquareComplex sc = square_complex(squares);
  std::vector<char> bad;
  const auto all = pieces_of(sc, &bad);
  *pieces = all.size();
  std::vector<CutDisk> disks;
  for (std::size_t p = 0; p < all.size(); ++p) {
    if (bad[p]) continue;
    std::size_t edges = 0;
    std::vector<std::vector<int>> loops = boundary_loops(sc, all[p], &edges);
    if (loops.empty()) continue;
    std::stable_sort(loops.begin(), loops.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
    if (loops.size() > 1 && loops[1].size() * kMaxHoleShare > loops[0].size()) continue;
    std::vector<int> verts;
    for (int f : all[p]) verts.insert(verts.end(), sc.quads[f].begin(), sc.quads[f].end());
    std::sort(verts.begin(), verts.end());
    const auto n_verts = std::size_t(std::unique(verts.begin(), verts.end()) - verts.begin());
    if (long(n_verts) - long(edges) + long(all[p].size()) != 2 - long(loops.size()) || !single_fans(sc, all[p])) continue;
    disks.push_back(make_disk(sc, all[p], loops, point));
  }
  return disks;
}

}  // namespace cf::detail
