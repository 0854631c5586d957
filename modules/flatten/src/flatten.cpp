// flatten_colon: per colon segment, open the ends, solve the conformal map, reparametrise along
// the centreline and balance the area (default map), measure; then label the ends, order the
// segments rectum -> cecum and lay them out.
#include "colonflat/flatten/flatten.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_map>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/topology.h"
#include "flatten_internal.h"

namespace cf {
namespace {

using namespace flat_detail;

Surface component_surface(const TriangleList& mesh, const TopologyReport& topo, int c) {
  Surface s;
  std::vector<int> map(mesh.points.size(), -1);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (topo.face_component[f] != c) continue;
    Tri t;
    for (int k = 0; k < 3; ++k) {
      int& m = map[mesh.triangles[f][k]];
      if (m < 0) {
        m = int(s.p.size());
        const auto& q = mesh.points[mesh.triangles[f][k]];
        s.p.emplace_back(q[0], q[1], q[2]);
        s.src.push_back(mesh.triangles[f][k]);
      }
      t[k] = m;
    }
    s.t.push_back(t);
  }
  return s;
}

// Signed volume (x6) of the surface closed by cones to its centroid: > 0 when normals point out.
double signed_volume(const Surface& s) {
  V3 centroid = V3::Zero();
  for (const auto& p : s.p) centroid += p;
  centroid /= double(s.p.size());
  double vol = 0;
  for (const Tri& t : s.t) vol += (s.p[t[0]] - centroid).dot((s.p[t[1]] - centroid).cross(s.p[t[2]] - centroid));
  return vol;
}

void check_component(const ComponentTopology& ct, std::size_t c) {
  if (!ct.genus) throw PreconditionError("segment " + std::to_string(c) + " is not an orientable 2-manifold");
  if (*ct.genus > 0)
    throw PreconditionError("colon segment " + std::to_string(c) + " has genus " + std::to_string(*ct.genus) +
                            " (handles); flatten needs genus 0: run denoise first");
  if (ct.boundary_loops > 2)
    throw PreconditionError("colon segment " + std::to_string(c) + " has " + std::to_string(ct.boundary_loops) +
                            " boundary loops; flatten needs a closed surface or a tube with two open ends");
}

// Opens the segment into an annulus; returns its two end loops (end A first: the loop holding the
// smallest input vertex id, for determinism).
std::vector<std::vector<int>> open_annulus(const Surface& s, std::size_t nloops, const FlattenOptions& o,
                                           std::size_t c, SegmentWork& w) {
  {
    const Edges E0 = build_edges(s.t);
    Opened op = open_ends(s, E0, nloops, o.end_cut_radius);
    w.ann = std::move(op.annulus);
    w.seg.removed_faces = op.removed;
  }
  const Edges E = build_edges(w.ann.t);
  auto loops = boundary_loops(w.ann, E);
  const long long chi = (long long)w.ann.p.size() - (long long)E.ev.size() + (long long)w.ann.t.size();
  if (loops.size() != 2 || chi != 0)
    throw Error("could not open the ends of colon segment " + std::to_string(c) + " into a tube (" +
                std::to_string(loops.size()) + " boundary loops, Euler characteristic " + std::to_string(chi) + ")");
  auto min_src = [&](const std::vector<int>& l) {
    int m = INT32_MAX;
    for (int v : l) m = std::min(m, w.ann.src[v]);
    return m;
  };
  if (min_src(loops[1]) < min_src(loops[0])) std::swap(loops[0], loops[1]);
  return loops;
}

V3 loop_centre(const Surface& s, const std::vector<int>& l) {
  V3 m = V3::Zero();
  for (int v : l) m += s.p[v];
  return m / double(l.size());
}

std::size_t count_bad(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate) {
  std::size_t n = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && emb.area2(s, int(f)) <= 1e-7 * face_area_3d(s, int(f))) ++n;
  return n;
}

// Conformal map scaled to the area-preserving rectangle, fold-overs untangled. With "auto"
// weights on the conformal map, retried with clamped weights if more than 1 % of faces are bad.
Embedding conformal_step(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& loops,
                         const std::vector<std::vector<int>>& vf, const std::vector<char>& fixed,
                         const std::vector<char>& degenerate, const FlattenOptions& o) {
  const Surface& s = w.ann;
  auto attempt = [&](bool clamp, std::size_t& bad) {
    const Harmonic h = solve_harmonic(s, E, loops[0], loops[1], clamp);
    Embedding emb = embed_conformal(s, E, h, 1.0, 1.0);
    double signed_area = 0;
    for (std::size_t f = 0; f < s.t.size(); ++f) signed_area += emb.area2(s, int(f));
    const double scale = std::sqrt(w.seg.area_3d / h.period);
    emb = embed_conformal(s, E, h, signed_area >= 0 ? 1.0 : -1.0, scale);
    w.seg.untangled_vertices = untangle(s, vf, emb, fixed, degenerate);
    w.seg.weights = h.weights;
    w.seg.dirichlet_period_ratio = h.energy_u / h.period;
    bad = count_bad(s, emb, degenerate);
    return emb;
  };
  std::size_t bad = 0;
  Embedding emb = attempt(o.weights == "clamped", bad);
  if (o.weights == "auto" && o.map == "conformal" && bad > s.t.size() / 100) {
    std::size_t bad2 = 0;
    const FlatSegment keep = w.seg;
    Embedding e2 = attempt(true, bad2);
    if (bad2 < bad) return e2;
    w.seg = keep;
  }
  return emb;
}

// COLONFLAT_FLATTEN_DEBUG=1: distortion after each step on stderr.
void debug_stats(const char* step, const SegmentWork& w, const std::vector<char>& degenerate) {
  if (!std::getenv("COLONFLAT_FLATTEN_DEBUG")) return;
  std::vector<FaceDistortion> fd;
  for (std::size_t f = 0; f < w.ann.t.size(); ++f) {
    const Tri& t = w.ann.t[f];
    const auto c = w.emb.corners(w.ann, int(f));
    fd.push_back(face_distortion(w.ann.p[t[0]], w.ann.p[t[1]], w.ann.p[t[2]], c[0], c[1], c[2]));
    fd.back().degenerate = degenerate[f];
  }
  const DistortionStats st = stats_of(fd);
  std::fprintf(stderr, "flatten debug %s: flipped %zu qc mean %.3f p95 %.3f max %.3g area p05 %.4f p50 %.3f p95 %.3f\n",
               step, st.flipped, st.qc_mean, st.qc_p95, st.qc_max, st.area_p05, st.area_median, st.area_p95);
}

// Area-balanced map: x = L A(u) / A, with A(u) the wall area below the level set u and L the
// centreline length (each slice of the colon gets a band width proportional to its wall area;
// band length = centreline length), y scaled so that the band's area is the wall area, fold-overs
// untangled, then the regions still out of bounds balanced (symmetric Dirichlet).
void area_balanced_step(SegmentWork& w, const Centreline& cl, const std::vector<std::vector<int>>& vf,
                        const std::vector<char>& fixed, const std::vector<char>& degenerate,
                        const FlattenOptions& o) {
  Embedding& emb = w.emb;
  const double conformal_length = w.seg.length;
  const double period = w.seg.area_3d / cl.length;
  const double yscale = period / emb.period;
  for (auto& q : emb.pos) q = V2(cl.length * cl.area_fraction_of_u(q.x() / conformal_length), q.y() * yscale);
  for (std::size_t i = 0; i < cl.knot_u.size(); ++i)
    w.seg.centreline_x.push_back({cl.knot_s[i], cl.length * cl.area_fraction_of_u(cl.knot_u[i])});
  for (auto& d : emb.dy)
    for (double& x : d) x *= yscale;
  emb.period = period;
  w.seg.length = cl.length;
  w.seg.period = period;
  w.seg.untangled_vertices += untangle(w.ann, vf, emb, fixed, degenerate);
  debug_stats("reparametrised", w, degenerate);
  w.seg.balanced_vertices = balance_area(w.ann, vf, emb, fixed, degenerate, o).vertices;
}

// Distortion, faces left out (zero or negative area) and coverage of a segment.
void measure(SegmentWork& w, const Edges& E, const std::vector<char>& degenerate, const FlattenOptions& o,
             double cap_area) {
  const Surface& s = w.ann;
  std::vector<FaceDistortion> fd(s.t.size());
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const Tri& t = s.t[f];
    const auto c = w.emb.corners(s, int(f));
    fd[f] = face_distortion(s.p[t[0]], s.p[t[1]], s.p[t[2]], c[0], c[1], c[2]);
    fd[f].degenerate = degenerate[f];
  }
  w.in_map.assign(s.t.size(), 1);
  std::vector<FaceDistortion> kept;
  kept.reserve(fd.size());
  double a2 = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (!degenerate[f] && fd[f].area2 <= 1e-7 * fd[f].area3) w.in_map[f] = 0, ++w.seg.crowded_faces;
    else kept.push_back(fd[f]), a2 += std::abs(fd[f].area2);
  }
  w.seg.stats = stats_of(kept);
  const double scale = a2 > 0 ? w.seg.area_3d / a2 : 1.0;
  std::vector<double> ratio(s.t.size(), 1.0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && fd[f].area3 > 0) ratio[f] = fd[f].area2 * scale / fd[f].area3;
  w.seg.coverage = coverage_of(s, E, w.in_map, ratio, o.coverage_min_ratio, cap_area);
}

SegmentWork flatten_segment(const Surface& s, const ComponentTopology& ct, std::size_t c, double lumen_sign,
                            const FlattenOptions& o) {
  SegmentWork w;
  w.lumen_sign = lumen_sign;
  w.seg.component = int(c);
  w.seg.input_kind = ct.boundary_loops == 0 ? "closed" : ct.boundary_loops == 1 ? "one open end" : "tube";
  w.seg.map = o.map;
  double total_area = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f) total_area += face_area_3d(s, int(f));
  const auto loops = open_annulus(s, ct.boundary_loops, o, c, w);
  phase_done("ends opened");
  const Surface& ann = w.ann;
  const Edges E = build_edges(ann.t);
  const V3 ca = loop_centre(ann, loops[0]), cb = loop_centre(ann, loops[1]);
  w.seg.end_a = {ca.x(), ca.y(), ca.z()};
  w.seg.end_b = {cb.x(), cb.y(), cb.z()};
  for (std::size_t f = 0; f < ann.t.size(); ++f) w.seg.area_3d += face_area_3d(ann, int(f));
  std::vector<char> degenerate(ann.t.size(), 0);
  const double mean_area = w.seg.area_3d / double(ann.t.size());
  for (std::size_t f = 0; f < ann.t.size(); ++f) degenerate[f] = face_area_3d(ann, int(f)) <= 1e-6 * mean_area;
  std::vector<char> fixed(ann.p.size(), 0);
  for (const auto& l : loops)
    for (int v : l) fixed[v] = 1;
  const auto vf = vertex_faces(ann);
  w.emb = conformal_step(w, E, loops, vf, fixed, degenerate, o);
  phase_done("conformal map");
  w.seg.length = w.seg.area_3d / w.emb.period;  // the conformal rectangle: length x period = area
  w.seg.period = w.emb.period;
  std::vector<double> u(ann.p.size());
  for (std::size_t v = 0; v < ann.p.size(); ++v) u[v] = std::clamp(w.emb.pos[v].x() / w.seg.length, 0.0, 1.0);
  std::vector<char> use_face(ann.t.size(), 1);
  {
    const double conformal_scale = w.seg.area_3d / (w.seg.length * w.seg.period);
    for (std::size_t f = 0; f < ann.t.size(); ++f)
      use_face[f] = w.emb.area2(ann, int(f)) * conformal_scale >= 0.05 * face_area_3d(ann, int(f));
  }
  const Centreline cl = centreline_from_u(ann, u, use_face, ca, cb);
  w.seg.centreline = cl.points;
  w.seg.centreline_length = cl.length;
  w.along.resize(ann.p.size());
  for (std::size_t v = 0; v < ann.p.size(); ++v) w.along[v] = cl.s_of_u(u[v]);
  phase_done("centreline");
  debug_stats("conformal", w, degenerate);
  if (o.map == "area-balanced") area_balanced_step(w, cl, vf, fixed, degenerate, o);
  if (o.map == "area-balanced") phase_done("area balance");
  debug_stats("final", w, degenerate);
  w.seg.faces = ann.t.size();
  w.seg.vertices = ann.p.size();
  measure(w, E, degenerate, o, total_area - w.seg.area_3d);
  phase_done("distortion and coverage");
  return w;
}

}  // namespace

FlatMap flatten_colon(const Mesh& mesh, const FlattenOptions& opts) {
  return flatten_colon(to_triangle_list(mesh), opts);
}

FlatMap flatten_colon(const TriangleList& mesh, const FlattenOptions& opts) {
  if (opts.weights != "cotan" && opts.weights != "clamped" && opts.weights != "auto")
    throw UsageError("--weights must be cotan, clamped or auto (got '" + opts.weights + "')");
  if (opts.map != "area-balanced" && opts.map != "conformal")
    throw UsageError("--map must be area-balanced or conformal (got '" + opts.map + "')");
  const TopologyReport topo = analyze_topology(mesh);
  FlatMap out;
  out.input_vertices = topo.vertices;
  out.input_faces = topo.faces;
  if (topo.faces == 0) throw PreconditionError("the surface has no triangles");
  if (!topo.manifold) throw PreconditionError("the surface is not a 2-manifold; flatten needs a clean colon surface");
  const std::size_t largest = topo.components[0].faces;
  std::vector<SegmentWork> work;
  for (std::size_t c = 0; c < topo.components.size(); ++c) {
    const ComponentTopology& ct = topo.components[c];
    if (double(ct.faces) < opts.min_segment_fraction * double(largest) || ct.faces < 8) {
      ++out.skipped_components;
      continue;
    }
    check_component(ct, c);
    const Surface s = component_surface(mesh, topo, int(c));
    // Normals out of the lumen (the reconstruct convention): a closed component enclosing a
    // negative volume is the wall of a cavity (a blob floating in the lumen): skipped.
    const double vol = signed_volume(s);
    if (ct.boundary_loops == 0 && vol < 0) {
      ++out.skipped_components;
      continue;
    }
    work.push_back(flatten_segment(s, ct, c, vol >= 0 ? 1.0 : -1.0, opts));
  }
  if (work.empty()) throw PreconditionError("no colon segment large enough to flatten");
  double xmin = 1e300, xmax = -1e300;
  for (const auto& p : mesh.points) xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
  std::vector<FlatSegment> segs;
  for (const auto& w : work) segs.push_back(w.seg);
  std::vector<char> reversed;
  label_ends(segs, 0.5 * (xmin + xmax), reversed);
  for (std::size_t i = 0; i < work.size(); ++i) work[i].seg = segs[i];
  flat_detail::emit_segments(work, reversed, opts, out);
  return out;
}

TriangleList flat_to_surface(const FlatMap& flat, std::vector<int>* flat_to_3d) {
  TriangleList t;
  std::unordered_map<int, int> map;
  std::vector<int> f2d(flat.uv.size());
  for (std::size_t i = 0; i < flat.uv.size(); ++i) {
    auto it = map.find(flat.source_vertex[i]);
    if (it == map.end()) {
      it = map.emplace(flat.source_vertex[i], int(t.points.size())).first;
      t.points.push_back(flat.position[i]);
    }
    f2d[i] = it->second;
  }
  t.triangles.reserve(flat.triangles.size());
  for (const auto& tr : flat.triangles) t.triangles.push_back({f2d[tr[0]], f2d[tr[1]], f2d[tr[2]]});
  if (flat_to_3d) *flat_to_3d = std::move(f2d);
  return t;
}

}  // namespace cf
