// Edge graph, geodesic distances, boundary loops and the opening of closed ends into an annulus.
#include "flatten_internal.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <unordered_map>

#include "colonflat/core/bucket_slots.h"
#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "colonflat/core/union_find.h"

namespace cf::flat_detail {

namespace {
std::atomic<std::size_t> edge_graphs_built{0};
}

std::size_t build_edges_count() { return edge_graphs_built.load(); }

// The face corners bucketed by the lower vertex of the edge opposite them (a counting sort), each
// bucket sorted by (higher vertex, corner): a bucket is filled in corner order, so this is the stable
// sort by the higher vertex (corners of one edge stay in face order) without stable_sort's buffer;
// edges come out sorted by (lo, hi) in O(faces), with the same numbering as a global sort of the keys.
Edges build_edges(const std::vector<Tri>& t) {
  ++edge_graphs_built;
  int nv = 0;
  for (const Tri& tri : t) nv = std::max({nv, tri[0] + 1, tri[1] + 1, tri[2] + 1});
  BucketSlots<int> slots{std::size_t(nv)};
  for (const Tri& tri : t)
    for (int k = 0; k < 3; ++k) slots.count(std::size_t(std::min(tri[(k + 1) % 3], tri[(k + 2) % 3])));
  slots.close();
  std::vector<std::pair<int, int>> corner(3 * t.size());  // (hi, 3 f + k) per bucket
  for (std::size_t f = 0; f < t.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = t[f][(k + 1) % 3], b = t[f][(k + 2) % 3];
      corner[std::size_t(slots.place(std::size_t(std::min(a, b))))] = {std::max(a, b), int(3 * f + k)};
    }
  const std::vector<int>& start = slots.starts();
  Edges E;
  E.fe.assign(t.size(), {-1, -1, -1});
  E.ev.reserve(3 * t.size() / 2 + 1);
  E.ef.reserve(3 * t.size() / 2 + 1);
  for (int lo = 0; lo < nv; ++lo) {
    const auto first = corner.begin() + start[lo], last = corner.begin() + start[lo + 1];
    std::sort(first, last);
    for (auto i = first; i != last;) {
      auto j = i;
      while (j != last && j->first == i->first) ++j;
      if (j - i > 2) throw PreconditionError("non-manifold edge in a colon segment; flatten needs a 2-manifold");
      const int e = int(E.ev.size());
      E.ev.push_back({lo, i->first});
      E.ef.push_back({i->second / 3, j - i == 2 ? (i + 1)->second / 3 : -1});
      for (auto q = i; q != j; ++q) E.fe[q->second / 3][q->second % 3] = e;
      i = j;
    }
  }
  return E;
}

// The kept edges bucketed by their lower vertex on the sub-surface (a counting sort), each bucket
// sorted by the higher one: numbered as build_edges numbers them. Faces keep their order (sub_surface)
// and so do the two faces of an edge.
Edges sub_edges(const Edges& E, const std::vector<char>& keep, const std::vector<int>& new_of_old) {
  std::vector<int> face_id(keep.size(), -1);
  int nf = 0, nv = 0;
  for (std::size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) face_id[f] = nf++;
  for (int v : new_of_old) nv = std::max(nv, v + 1);
  auto kept = [&](std::size_t e) { return face_id[E.ef[e][0]] >= 0 || (E.ef[e][1] >= 0 && face_id[E.ef[e][1]] >= 0); };
  auto lo_hi = [&](std::size_t e) {
    const int a = new_of_old[E.ev[e][0]], b = new_of_old[E.ev[e][1]];
    return std::pair<int, int>(std::min(a, b), std::max(a, b));
  };
  BucketSlots<int> slots{std::size_t(nv)};
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (kept(e)) slots.count(std::size_t(lo_hi(e).first));
  slots.close();
  std::vector<std::pair<int, int>> slot(std::size_t(slots.total()));  // (hi, edge of E) per bucket
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (kept(e)) slot[std::size_t(slots.place(std::size_t(lo_hi(e).first)))] = {lo_hi(e).second, int(e)};
  const std::vector<int>& start = slots.starts();
  Edges S;
  S.ev.resize(slot.size()), S.ef.resize(slot.size());
  std::vector<int> new_edge(E.ev.size(), -1);
  for (int lo = 0; lo < nv; ++lo) {
    std::sort(slot.begin() + start[lo], slot.begin() + start[lo + 1]);  // hi is unique in a bucket
    for (int i = start[lo]; i < start[lo + 1]; ++i) {
      const int e = slot[i].second, f0 = face_id[E.ef[e][0]], f1 = E.ef[e][1] >= 0 ? face_id[E.ef[e][1]] : -1;
      S.ev[i] = {lo, slot[i].first};
      S.ef[i] = f0 >= 0 ? std::array<int, 2>{f0, f1} : std::array<int, 2>{f1, -1};
      new_edge[e] = i;
    }
  }
  S.fe.resize(std::size_t(nf));
  for (std::size_t f = 0; f < keep.size(); ++f)
    if (keep[f])
      for (int k = 0; k < 3; ++k) S.fe[face_id[f]][k] = new_edge[E.fe[f][k]];
  return S;
}

Csr build_csr(const Surface& s, const Edges& E) {
  Csr g;
  const std::size_t nv = s.p.size();
  BucketSlots<int> slots(nv);
  for (const auto& e : E.ev) slots.count(std::size_t(e[0])), slots.count(std::size_t(e[1]));
  slots.close();
  g.nbr.resize(std::size_t(slots.total()));
  g.len.resize(std::size_t(slots.total()));
  for (const auto& e : E.ev) {
    const double l = (s.p[e[0]] - s.p[e[1]]).norm();
    const int i = slots.place(std::size_t(e[0])), j = slots.place(std::size_t(e[1]));
    g.nbr[std::size_t(i)] = e[1], g.len[std::size_t(i)] = l;
    g.nbr[std::size_t(j)] = e[0], g.len[std::size_t(j)] = l;
  }
  g.start = std::move(slots).take_starts();
  return g;
}

namespace {

// The unsettled vertices that hold a finite distance, in a 4-ary min-heap on d (ties in any order:
// the distances do not depend on it) with each vertex's place in it, so that a shorter distance
// moves its vertex up instead of adding a second entry (std::priority_queue's lazy deletion kept
// every stale entry: about a quarter more time on a colon's million vertices).
class DistanceHeap {
 public:
  explicit DistanceHeap(const std::vector<double>& d) : d_(d), place_(d.size(), -1) {}
  bool empty() const { return heap_.empty(); }
  int top() const { return heap_[0]; }
  void lowered(int v) {  // d[v] was set or lowered
    if (place_[std::size_t(v)] < 0) place_[std::size_t(v)] = int(heap_.size()), heap_.push_back(v);
    up(place_[std::size_t(v)]);
  }
  void pop() {
    place_[std::size_t(heap_[0])] = -1;
    heap_[0] = heap_.back();
    heap_.pop_back();
    if (!heap_.empty()) down(0);
  }

 private:
  void put(int i, int v) { heap_[std::size_t(i)] = v, place_[std::size_t(v)] = i; }
  void up(int i) {
    const int v = heap_[std::size_t(i)];
    for (int p; i > 0 && d_[std::size_t(v)] < d_[std::size_t(heap_[std::size_t(p = (i - 1) / 4)])]; i = p) put(i, heap_[std::size_t(p)]);
    put(i, v);
  }
  void down(int i) {
    const int v = heap_[std::size_t(i)], n = int(heap_.size());
    for (int c; (c = 4 * i + 1) < n;) {
      int best = c;
      for (int k = c + 1; k < std::min(c + 4, n); ++k)
        if (d_[std::size_t(heap_[std::size_t(k)])] < d_[std::size_t(heap_[std::size_t(best)])]) best = k;
      if (!(d_[std::size_t(heap_[std::size_t(best)])] < d_[std::size_t(v)])) break;
      put(i, heap_[std::size_t(best)]), i = best;
    }
    put(i, v);
  }
  const std::vector<double>& d_;
  std::vector<int> heap_, place_;
};

}  // namespace

// Each vertex is settled once, in ascending distance; a vertex's distance is the least of its
// settled neighbours' distance + edge length, whatever the order among equal distances: the result
// does not depend on the heap (the same bits as the lazy-deletion search this replaced).
std::vector<double> dijkstra(const Csr& g, const std::vector<int>& sources, double settle_up_to) {
  std::vector<double> d(g.start.size() - 1, kInf);
  DistanceHeap q(d);
  for (int s : sources) d[std::size_t(s)] = 0, q.lowered(s);
  while (!q.empty()) {
    const int v = q.top();
    const double dv = d[std::size_t(v)];
    if (dv > settle_up_to) break;
    q.pop();
    for (int k = g.start[std::size_t(v)]; k < g.start[std::size_t(v) + 1]; ++k) {
      const double nd = dv + g.len[std::size_t(k)];
      if (nd < d[std::size_t(g.nbr[std::size_t(k)])]) d[std::size_t(g.nbr[std::size_t(k)])] = nd, q.lowered(g.nbr[std::size_t(k)]);
    }
  }
  return d;
}

int argmax_finite(const std::vector<double>& d) {
  int best = 0;
  for (std::size_t i = 0; i < d.size(); ++i)
    if (std::isfinite(d[i]) && (!std::isfinite(d[best]) || d[i] > d[best])) best = int(i);
  return best;
}

namespace {

// The faces of the largest edge-connected piece of `faces` (ascending, keep[f] set for each; on a
// tie the piece found first, from the lowest face), ascending; keep cleared for the others. Only
// these faces and their edges are walked. comp: per face of the surface, -1 (again on return).
std::vector<int> largest_piece(const Edges& E, const std::vector<int>& faces, std::vector<char>& keep,
                               std::vector<int>& comp) {
  int best = -1, ncomp = 0;
  std::size_t best_size = 0;
  std::vector<int> stack;
  for (int f0 : faces) {
    if (comp[std::size_t(f0)] >= 0) continue;
    std::size_t size = 0;
    stack.push_back(f0);
    comp[std::size_t(f0)] = ncomp;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      ++size;
      for (int e : E.fe[std::size_t(f)])
        for (int g : E.ef[std::size_t(e)])
          if (g >= 0 && keep[std::size_t(g)] && comp[std::size_t(g)] < 0) comp[std::size_t(g)] = ncomp, stack.push_back(g);
    }
    if (size > best_size) best_size = size, best = ncomp;
    ++ncomp;
  }
  std::vector<int> out;
  for (int f : faces) {
    keep[std::size_t(f)] = comp[std::size_t(f)] == best;
    if (keep[std::size_t(f)]) out.push_back(f);
  }
  for (int f : faces) comp[std::size_t(f)] = -1;
  return out;
}

std::vector<int> kept_faces(const std::vector<char>& keep) {
  std::vector<int> faces;
  for (std::size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) faces.push_back(int(f));
  return faces;
}

}  // namespace

// Keeps the largest edge-connected set of faces among `keep`.
void keep_largest_component(const Edges& E, std::vector<char>& keep) {
  std::vector<int> comp(keep.size(), -1);
  largest_piece(E, kept_faces(keep), keep, comp);
}

namespace {

// Floods of the complement of a face set from its border (enclosed_by): each flood a piece, or
// part of a piece that reached the budget ("big"; floods that meet are one piece: union-find).
struct BorderFloods {
  const Edges& E;
  const std::vector<char>& in;
  std::vector<int> label, root;          // per face: its flood (-1: none); per flood: union-find parent
  std::vector<char> big;                 // per flood
  std::vector<std::vector<int>> faces;   // per flood: the faces it labelled

  int find(int a) {
    while (root[std::size_t(a)] != a) a = root[std::size_t(a)] = root[std::size_t(root[std::size_t(a)])];
    return a;
  }
  // Floods the piece of `seed` until it is complete, reaches `budget` faces or meets a big flood.
  void flood(int seed, std::size_t budget) {
    const int id = int(root.size());
    root.push_back(id), big.push_back(0), faces.emplace_back(1, seed);
    label[std::size_t(seed)] = id;
    std::vector<int> stack{seed};
    while (!stack.empty() && !big[std::size_t(id)]) {
      const int f = stack.back();
      stack.pop_back();
      for (int e : E.fe[std::size_t(f)])
        for (int g : E.ef[std::size_t(e)]) {
          if (g < 0 || in[std::size_t(g)] || label[std::size_t(g)] == id) continue;
          if (label[std::size_t(g)] >= 0) {  // another flood's face: only big floods stop unfinished
            root[std::size_t(find(id))] = find(label[std::size_t(g)]);
            big[std::size_t(id)] = 1;
            continue;
          }
          label[std::size_t(g)] = id, stack.push_back(g), faces[std::size_t(id)].push_back(g);
        }
      if (faces[std::size_t(id)].size() >= budget) big[std::size_t(id)] = 1;
    }
  }
};

}  // namespace

std::vector<int> enclosed_by(const Edges& E, const std::vector<char>& in, std::size_t budget) {
  BorderFloods fl{E, in, std::vector<int>(in.size(), -1), {}, {}, {}};
  for (std::size_t f = 0; f < in.size(); ++f)
    if (in[f])
      for (int e : E.fe[f])
        for (int g : E.ef[std::size_t(e)])
          if (g >= 0 && !in[std::size_t(g)] && fl.label[std::size_t(g)] < 0) fl.flood(g, budget);
  std::vector<int> big_roots;
  std::size_t walked = 0, outside = 0;
  for (std::size_t id = 0; id < fl.root.size(); ++id) {
    walked += fl.faces[id].size();
    if (fl.big[id]) big_roots.push_back(fl.find(int(id)));
  }
  std::sort(big_roots.begin(), big_roots.end());
  big_roots.erase(std::unique(big_roots.begin(), big_roots.end()), big_roots.end());
  for (char c : in) outside += !c;
  int largest = -1;  // the flood that is the largest piece
  if (big_roots.size() == 1) {
    largest = big_roots[0];
  } else if (big_roots.empty() && walked == outside) {  // every piece complete: keep_largest_component's choice
    std::size_t best = 0, best_first = in.size();       // (largest; ties: the piece with the first face)
    for (std::size_t id = 0; id < fl.faces.size(); ++id) {
      const std::size_t first = std::size_t(*std::min_element(fl.faces[id].begin(), fl.faces[id].end()));
      if (fl.faces[id].size() > best || (fl.faces[id].size() == best && first < best_first))
        best = fl.faces[id].size(), best_first = first, largest = int(id);
    }
  }
  std::vector<int> out;
  if (largest >= 0 || fl.faces.empty()) {
    for (std::size_t id = 0; id < fl.faces.size(); ++id)
      if (!fl.big[id] && int(id) != largest) out.insert(out.end(), fl.faces[id].begin(), fl.faces[id].end());
  } else {  // several pieces reached the budget: the whole complement
    std::vector<char> keep(in.size());
    for (std::size_t f = 0; f < in.size(); ++f) keep[f] = !in[f];
    keep_largest_component(E, keep);
    for (std::size_t f = 0; f < in.size(); ++f)
      if (!in[f] && !keep[f]) out.push_back(int(f));
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Surface made of the kept faces, reindexed.
Surface sub_surface(const Surface& s, const std::vector<char>& keep, std::vector<int>* new_of_old) {
  return sub_surface(s, kept_faces(keep), new_of_old);
}

Surface sub_surface(const Surface& s, const std::vector<int>& faces, std::vector<int>* new_of_old) {
  Surface r;
  std::vector<int> local;
  std::vector<int>& map = new_of_old ? *new_of_old : local;
  map.assign(s.p.size(), -1);
  r.t.reserve(faces.size());
  r.p.reserve(std::min(s.p.size(), 3 * faces.size()));  // (at most three new vertices a face)
  r.src.reserve(r.p.capacity());
  for (int f : faces) {
    Tri t;
    for (int k = 0; k < 3; ++k) {
      int& m = map[s.t[f][k]];
      if (m < 0) {
        m = int(r.p.size());
        r.p.push_back(s.p[s.t[f][k]]);
        r.src.push_back(s.src[s.t[f][k]]);
      }
      t[k] = m;
    }
    r.t.push_back(t);
  }
  return r;
}

// Boundary vertex sets (one per loop) of a surface, via its boundary edges.
std::vector<std::vector<int>> boundary_loops(const Surface& s, const Edges& E) {
  UnionFind uf(s.p.size());
  std::vector<char> on(s.p.size(), 0);
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (E.ef[e][1] < 0) uf.unite(E.ev[e][0], E.ev[e][1]), on[E.ev[e][0]] = on[E.ev[e][1]] = 1;
  std::unordered_map<int, int> id;
  std::vector<std::vector<int>> loops;
  for (std::size_t v = 0; v < s.p.size(); ++v) {
    if (!on[v]) continue;
    const int r = int(uf.find(v));
    auto it = id.find(r);
    if (it == id.end()) it = id.emplace(r, int(loops.size())).first, loops.emplace_back();
    loops[it->second].push_back(int(v));
  }
  return loops;
}

void clean_selection(const Surface& s, const Edges& E, std::vector<char>& keep) {
  const std::vector<int> faces = clean_face_set(s, E, kept_faces(keep));
  keep.assign(keep.size(), 0);
  for (int f : faces) keep[std::size_t(f)] = 1;
}

std::vector<int> clean_face_set(const Surface& s, const Edges& E, std::vector<int> faces, FaceSetScratch* scratch) {
  // Pinch vertices (kept faces forming several fans) make the boundary non-manifold: remove the
  // faces around them and keep the largest piece, until the boundary is clean.
  if (!std::is_sorted(faces.begin(), faces.end())) std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  FaceSetScratch own;
  FaceSetScratch& use = scratch ? *scratch : own;
  if (use.keep.size() != s.t.size()) use.keep.assign(s.t.size(), 0), use.comp.assign(s.t.size(), -1);
  if (use.bcount.size() != s.p.size()) use.bcount.assign(s.p.size(), 0);
  std::vector<char>& keep = use.keep;
  std::vector<int>& comp = use.comp;
  std::vector<int>& bcount = use.bcount;  // boundary edges at a vertex
  for (int f : faces) keep[std::size_t(f)] = 1;
  for (int iter = 0; iter < 200; ++iter) {
    faces = largest_piece(E, faces, keep, comp);
    for (int f : faces)  // an edge with one kept face is on the boundary (walked from that face only)
      for (int e : E.fe[std::size_t(f)]) {
        const auto& ef = E.ef[std::size_t(e)];
        const int g = ef[0] == f ? ef[1] : ef[0];
        if (g < 0 || !keep[std::size_t(g)]) ++bcount[std::size_t(E.ev[std::size_t(e)][0])], ++bcount[std::size_t(E.ev[std::size_t(e)][1])];
      }
    // Also faces with all three corners on the boundary: the harmonic function, constant along
    // each end, would collapse them.
    bool changed = false;
    std::vector<int> left;
    left.reserve(faces.size());
    for (int f : faces) {
      const Tri& t = s.t[std::size_t(f)];
      const auto on = [&](int k) { return bcount[std::size_t(t[k])]; };
      const bool all_on = on(0) > 0 && on(1) > 0 && on(2) > 0, pinch = on(0) > 2 || on(1) > 2 || on(2) > 2;
      if (all_on || pinch) keep[std::size_t(f)] = 0, changed = true;
      else left.push_back(f);
    }
    for (int f : faces)
      for (int v : s.t[std::size_t(f)]) bcount[std::size_t(v)] = 0;
    faces.swap(left);
    if (!changed) break;
  }
  for (int f : faces) keep[std::size_t(f)] = 0;  // (the faces dropped are 0 already)
  return faces;
}

// Removes caps around the ends of a segment with b boundary loops (b = 0 or 1) so that an annulus
// remains. Returns the annulus and which of its loops is end A.
Opened open_ends(const Surface& s, const Edges& E, std::size_t nloops, double radius) {
  const Csr g = build_csr(s, E);
  std::vector<char> remove(s.t.size(), 0);
  auto cap = [&](const std::vector<double>& d, int apex, double r) {
    for (std::size_t f = 0; f < s.t.size(); ++f) {
      const Tri& t = s.t[f];
      const double m = (d[t[0]] + d[t[1]] + d[t[2]]) / 3;
      if (m < r || t[0] == apex || t[1] == apex || t[2] == apex) remove[f] = 1;
    }
  };
  if (nloops == 2) {
    // a tube: nothing to open, only the boundary clean-up below
  } else if (nloops == 0) {
    const auto d0 = dijkstra(g, {0});
    const int a = argmax_finite(d0);
    const auto da = dijkstra(g, {a});
    const int b = argmax_finite(da);
    const double r = std::min(radius, 0.1 * da[b]);
    const auto db = dijkstra(g, {b}, 3 * r);  // a face's mean below r: its corners below 3 r
    cap(da, a, r);
    cap(db, b, r);
  } else {
    std::vector<int> bverts;
    for (std::size_t e = 0; e < E.ev.size(); ++e)
      if (E.ef[e][1] < 0) bverts.push_back(E.ev[e][0]), bverts.push_back(E.ev[e][1]);
    const auto dl = dijkstra(g, bverts);
    const int b = argmax_finite(dl);
    const double r = std::min(radius, 0.1 * dl[b]);
    cap(dijkstra(g, {b}, 3 * r), b, r);  // a face's mean below r: its corners below 3 r
  }
  std::vector<char> keep(s.t.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) keep[f] = !remove[f];
  clean_selection(s, E, keep);
  Opened o;
  o.annulus = sub_surface(s, keep, &o.new_of_old);
  o.edges = sub_edges(E, keep, o.new_of_old);
  o.removed = s.t.size() - o.annulus.t.size();
  return o;
}

double face_area_3d(const Surface& s, int f) {
  const Tri& t = s.t[f];
  return 0.5 * (s.p[t[1]] - s.p[t[0]]).cross(s.p[t[2]] - s.p[t[0]]).norm();
}

std::vector<std::vector<int>> vertex_faces(const Surface& s) {
  std::vector<std::vector<int>> vf(s.p.size());
  for (std::size_t f = 0; f < s.t.size(); ++f)
    for (int v : s.t[f]) vf[v].push_back(int(f));
  return vf;
}

}  // namespace cf::flat_detail
