// Wall a finished band's map hides, cut out as patches (see hidden_patches.h).
#include "hidden_patches.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "face_rings.h"
#include "patch_slit.h"

namespace cf::flat_detail {
namespace {

// Per face of w.ann: hidden as measure() counts it (out of the map, or shown below min_ratio at the
// band's area scale; degenerate faces never). `hidden_area`: their 3D area.
std::vector<char> hidden_faces(const SegmentWork& w, const std::vector<char>& degenerate, double min_ratio,
                               double& hidden_area) {
  const std::vector<FaceDistortion> fd = band_distortion(w, degenerate);
  const std::size_t nf = w.ann.t.size();
  std::vector<char> out_of_map(nf, 0);
  double a2 = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    out_of_map[f] = !degenerate[f] && too_small_in_map(fd[f].area2, fd[f].area3);
    if (!out_of_map[f]) a2 += std::abs(fd[f].area2);
  }
  const double scale = a2 > 0 ? w.seg.area_3d / a2 : 1.0;
  std::vector<char> hidden(nf, 0);
  hidden_area = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    if (degenerate[f]) continue;
    hidden[f] = out_of_map[f] || (fd[f].area3 > 0 && fd[f].area2 * scale / fd[f].area3 < min_ratio);
    if (hidden[f]) hidden_area += fd[f].area3;
  }
  return hidden;
}

// Edge-connected pieces of the faces marked in `in` (each ascending, in order of their first face).
std::vector<std::vector<int>> face_pieces(const Edges& E, const std::vector<char>& in) {
  std::vector<char> seen(in.size(), 0);
  std::vector<std::vector<int>> pieces;
  for (std::size_t f0 = 0; f0 < in.size(); ++f0) {
    if (!in[f0] || seen[f0]) continue;
    std::vector<int> piece, stack{int(f0)};
    seen[f0] = 1;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      piece.push_back(f);
      for (int e : E.fe[std::size_t(f)])
        for (int g : E.ef[std::size_t(e)])
          if (g >= 0 && in[std::size_t(g)] && !seen[std::size_t(g)]) seen[std::size_t(g)] = 1, stack.push_back(g);
    }
    std::sort(piece.begin(), piece.end());
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

// `in` grown by `rings` vertex rings (every face touching a vertex of a marked face), from its faces
// in ascending order (grow_face_rings).
void grow_rings(const Surface& s, const std::vector<std::vector<int>>& vf, int rings, std::vector<char>& in) {
  std::vector<int> ring;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (in[f]) ring.push_back(int(f));
  grow_face_rings(s, vf, rings, ring, [&](int g) {
    if (in[std::size_t(g)]) return false;
    in[std::size_t(g)] = 1;
    return true;
  });
}

// The boundary loops and Euler characteristic of a patch's own surface.
struct PatchShape {
  std::size_t loops = 0;
  long long chi = 0;
  // Open ends: 1 for a disk, 2 for an annulus, 0 otherwise.
  std::size_t open_ends() const { return (loops == 1 && chi == 1) ? 1 : (loops == 2 && chi == 0) ? 2 : 0; }
};
PatchShape patch_shape(const Surface& p) {
  const Edges e = build_edges(p.t);
  return {boundary_loops(p, e).size(), (long long)p.p.size() - (long long)e.ev.size() + (long long)p.t.size()};
}

// Per vertex of s: the index of the boundary loop it lies on (-1: none).
std::vector<int> loop_of_vertex(const Surface& s, const Edges& E) {
  std::vector<int> loop(s.p.size(), -1);
  const std::vector<std::vector<int>> loops = boundary_loops(s, E);
  for (std::size_t l = 0; l < loops.size(); ++l)
    for (int v : loops[l]) loop[std::size_t(v)] = int(l);
  return loop;
}

// A patch (`faces` of s, ascending) that holds more than one of the band's boundary loops (`loop`:
// per vertex of s; the rims of several cut-off branches) split into one piece per loop: each face
// goes with the loop nearest along the patch's own edges (its corners' summed distance; ties: the
// lower loop index), each piece split into its edge-connected parts. One loop or none: the patch.
std::vector<std::vector<int>> split_by_band_loops(const Surface& s, const Edges& E, const std::vector<int>& loop,
                                                  const std::vector<int>& faces) {
  std::vector<int> new_of_old;
  const Surface sub = sub_surface(s, faces, &new_of_old);
  std::vector<std::vector<int>> sources;  // per loop met: its vertices in sub
  std::vector<int> slot;                  // loop index -> entry of sources
  for (std::size_t v = 0; v < new_of_old.size(); ++v) {
    const int l = loop[v];
    if (new_of_old[v] < 0 || l < 0) continue;
    if (slot.size() <= std::size_t(l)) slot.resize(std::size_t(l) + 1, -1);
    if (slot[std::size_t(l)] < 0) slot[std::size_t(l)] = int(sources.size()), sources.emplace_back();
    sources[std::size_t(slot[std::size_t(l)])].push_back(new_of_old[v]);
  }
  if (sources.size() < 2) return {faces};
  const Csr g = build_csr(sub, build_edges(sub.t));
  std::vector<std::vector<double>> d;
  for (const auto& src : sources) d.push_back(dijkstra(g, src));
  std::vector<std::vector<char>> mask(sources.size(), std::vector<char>(s.t.size(), 0));
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Tri& t = sub.t[i];
    std::size_t best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < d.size(); ++k) {
      const double m = d[k][std::size_t(t[0])] + d[k][std::size_t(t[1])] + d[k][std::size_t(t[2])];
      if (m < best_d) best_d = m, best = k;
    }
    mask[best][std::size_t(faces[i])] = 1;
  }
  std::vector<std::vector<int>> out;
  for (const auto& m : mask)
    for (auto& piece : face_pieces(E, m)) out.push_back(std::move(piece));
  return out;
}

// COLONFLAT_FLATTEN_DEBUG=1: one line per patch (faces, area, open ends, Euler characteristic).
void debug_patch(const Surface& p, const PatchShape& shape, bool kept) {
  std::fprintf(stderr, "flatten debug hidden patch: %zu faces, %.1f mm2, %zu loops, chi %lld: %s\n", p.t.size(),
               surface_area(p), shape.loops, shape.chi, kept ? "cut out" : "left");
}

// Per edge of E between a face in a patch and a face outside it (another patch's or the rest's),
// its length added to that patch's rim length (`pieces[i]`: patch i's), edges in ascending order,
// and its ends that the rest keeps to the patch's neck (where it hangs on the band). The ends of an
// edge between two patches alone are in no face of the rest (new_of_old -1): they are not on the
// band, so they stay out of the neck (they were read as vertex -1 of the band, a read before its
// arrays that made the patch's attach point change from run to run; issue 26, session 32).
void add_rims(const Surface& s, const Edges& E, const std::vector<int>& patch_of, const std::vector<int>& new_of_old,
              std::vector<BranchPiece>& pieces) {
  for (std::size_t e = 0; e < E.ev.size(); ++e) {
    const int f0 = E.ef[e][0], f1 = E.ef[e][1];
    if (f1 < 0 || patch_of[std::size_t(f0)] == patch_of[std::size_t(f1)]) continue;
    for (int f : {f0, f1}) {
      const int i = patch_of[std::size_t(f)];
      if (i < 0) continue;
      pieces[std::size_t(i)].neck_mm += (s.p[std::size_t(E.ev[e][0])] - s.p[std::size_t(E.ev[e][1])]).norm();
      for (int v : E.ev[e])
        if (new_of_old[std::size_t(v)] >= 0) pieces[std::size_t(i)].neck.push_back(new_of_old[std::size_t(v)]);
    }
  }
}

}  // namespace

std::vector<std::vector<int>> hidden_patches(const SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& vf,
                                             const std::vector<char>& degenerate, double min_ratio, double min_area_mm2) {
  double hidden_area = 0;
  const std::vector<char> hidden = hidden_faces(w, degenerate, min_ratio, hidden_area);
  if (!(hidden_area > kHiddenWallTolerance * w.seg.area_3d)) return {};
  std::vector<char> in(hidden.size(), 0);
  for (const std::vector<int>& c : face_pieces(E, hidden)) {
    double a = 0;
    for (int f : c) a += face_area_3d(w.ann, f);
    if (a >= min_area_mm2)
      for (int f : c) in[std::size_t(f)] = 1;
  }
  grow_rings(w.ann, vf, kPatchRings, in);
  const std::size_t faces_in = std::size_t(std::count(in.begin(), in.end(), 1));
  if (faces_in == 0) return {};
  for (int f : enclosed_by(E, in, 2 * faces_in + 4096)) in[std::size_t(f)] = 1;
  std::vector<std::vector<int>> patches, pieces;
  const std::vector<int> loop = loop_of_vertex(w.ann, E);
  for (const std::vector<int>& grown : face_pieces(E, in))
    for (auto& piece : split_by_band_loops(w.ann, E, loop, grown)) pieces.push_back(std::move(piece));
  FaceSetScratch scratch;
  for (std::vector<int>& piece : pieces) {
    std::vector<int> clean = clean_face_set(w.ann, E, std::move(piece), &scratch);
    const Surface sub = sub_surface(w.ann, clean);
    const PatchShape shape = patch_shape(sub);
    const bool ok = !clean.empty() && clean.size() < w.ann.t.size() && shape.open_ends() > 0;
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG")) debug_patch(sub, shape, ok);
    if (ok) patches.push_back(std::move(clean));
  }
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug hidden patches: band %zu faces, %.1f of %.1f mm2 hidden, %zu patches\n",
                 w.ann.t.size(), hidden_area, w.seg.area_3d, patches.size());
  return patches;
}

PatchCut cut_patches(SegmentWork& w, Edges& E, std::vector<char>& degenerate, const std::vector<std::vector<int>>& patches) {
  PatchCut cut;
  if (patches.empty()) return cut;
  const std::size_t nf = w.ann.t.size();
  std::vector<char> keep(nf, 1);
  std::vector<int> patch_of(nf, -1);
  for (std::size_t i = 0; i < patches.size(); ++i)
    for (int f : patches[i]) keep[std::size_t(f)] = 0, patch_of[std::size_t(f)] = int(i);
  Surface rest = sub_surface(w.ann, keep, &cut.new_of_old);
  for (const auto& patch : patches) {
    BranchPiece piece;
    piece.surface = sub_surface(w.ann, patch);
    piece.loops = patch_shape(piece.surface).open_ends();
    cut.area_mm2 += surface_area(piece.surface);
    if (piece.loops == 1) {  // a disk: opened along its ridge (patch_slit.h), else at a tip cap
      Surface slit = slit_disk(piece.surface);
      if (!slit.t.empty()) piece.disk = std::move(piece.surface), piece.surface = std::move(slit), piece.loops = 2;
    }
    cut.pieces.push_back(std::move(piece));
  }
  add_rims(w.ann, E, patch_of, cut.new_of_old, cut.pieces);
  E = sub_edges(E, keep, cut.new_of_old);
  std::vector<V2> pos(rest.p.size());
  std::vector<double> along(w.along.empty() ? 0 : rest.p.size());
  for (std::size_t v = 0; v < cut.new_of_old.size(); ++v) {
    const int n = cut.new_of_old[v];
    if (n < 0) continue;
    pos[std::size_t(n)] = w.emb.pos[v];
    if (!along.empty()) along[std::size_t(n)] = w.along[v];
  }
  std::vector<std::array<double, 3>> dy;
  std::vector<char> deg;
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f]) dy.push_back(w.emb.dy[f]), deg.push_back(degenerate[f]);
  w.emb.pos = std::move(pos), w.emb.dy = std::move(dy), w.along = std::move(along), degenerate = std::move(deg);
  w.ann = std::move(rest);
  w.seg.area_3d = surface_area(w.ann);
  return cut;
}

void join_patches(std::vector<SegmentWork>& branches, const std::vector<int>& new_of_old, std::vector<SegmentWork>& patches) {
  if (new_of_old.empty()) return;
  for (auto& b : branches) {
    if (b.parent != -1) continue;
    std::vector<int> neck;
    for (int v : b.neck)
      if (new_of_old[std::size_t(v)] >= 0) neck.push_back(new_of_old[std::size_t(v)]);
    b.neck = std::move(neck);
  }
  const int base = int(branches.size());
  for (auto& pw : patches) {
    if (pw.parent >= 0) pw.parent += base;
    branches.push_back(std::move(pw));
  }
}

}  // namespace cf::flat_detail
