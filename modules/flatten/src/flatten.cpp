// flatten_colon: per colon segment, open the ends, solve the conformal map, reparametrise along
// the centreline and balance the area (default map), measure; then label the ends, order the
// segments rectum -> cecum and lay them out.
#include "colonflat/flatten/flatten.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <unordered_map>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "band_faces.h"
#include "branch_ends.h"
#include "branch_bands.h"
#include "disk_map.h"
#include "face_blocks.h"
#include "factor_memory.h"
#include "hidden_patches.h"
#include "flatten_internal.h"

namespace cf {
namespace {

using namespace flat_detail;

// A side job (the elimination order beside the opening of the ends, the side branches beside the
// colon's own steps) runs on a thread of its own when the process may use more than one
// (--threads), else when its result is needed: the same result either way.
std::launch side_launch() { return thread_count() > 1 ? std::launch::async : std::launch::deferred; }

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

// Opens the segment into an annulus; returns its two end loops (end A first: the loop holding the
// smallest input vertex id, for determinism), sets `E` to the annulus' edges (from the closed
// surface's). The conformal solve's elimination order (w.prior.order_when_ready, restricted to the
// annulus) is computed on a second thread meanwhile: on a large segment nested dissection's, launched
// first (its graph from the faces, not the edges built here); else small_segment_vertex_order's (AMD's,
// or METIS's where AMD's costs too much). Kept in w.dissection for the band's systems (area-balanced).
std::vector<std::vector<int>> open_annulus(const Surface& s, std::size_t nloops, const FlattenOptions& o,
                                           std::size_t c, SegmentWork& w, Edges& E) {
  {
    const int nv = int(s.p.size());
    const bool dissect = uses_dissection(s.p.size(), o.map), balanced = o.map == "area-balanced";
    std::shared_future<SegmentOrder> order;
    // (s outlives the order: flatten_surface waits for it, or an exception's unwinding of w does)
    if (dissect) order = std::async(side_launch(), [t = &s.t, nv] { return SegmentOrder{nested_dissection_vertex_order(*t, nv), true}; });
    auto E0 = std::make_shared<const Edges>(build_edges(s.t));
    if (!dissect) order = std::async(side_launch(), [E0, nv, balanced] { return small_segment_vertex_order(*E0, nv, balanced); });
    Opened op = open_ends(s, *E0, nloops, o.end_cut_radius);
    w.ann = std::move(op.annulus);
    E = std::move(op.edges);
    w.seg.removed_faces = op.removed;
    auto to_annulus = std::make_shared<const std::vector<int>>(std::move(op.new_of_old));
    w.prior.order_when_ready = [order, to_annulus] {
      std::vector<int> restricted;
      for (int v : order.get().order)
        if ((*to_annulus)[std::size_t(v)] >= 0) restricted.push_back((*to_annulus)[std::size_t(v)]);
      return restricted;
    };
    if (balanced) w.keep_order(order, *to_annulus);  // (dissect implies balanced)
  }
  auto loops = boundary_loops(w.ann, E);
  const long long chi = (long long)w.ann.p.size() - (long long)E.ev.size() + (long long)w.ann.t.size();
  if (loops.size() != 2 || chi != 0)
    throw Error("could not open the ends of component " + std::to_string(c) + " (" + std::to_string(s.t.size()) +
                " faces) into a tube: it is not tube-like (" + std::to_string(loops.size()) +
                " boundary loops after opening, Euler characteristic " + std::to_string(chi) + ")");
  auto min_src = [&](const std::vector<int>& l) {  // the smallest input vertex id on loop l
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

// (Counted in blocks of faces on the worker threads: an integer, the same for any thread count.)
std::size_t count_bad(const Surface& s, const Embedding& emb, const std::vector<char>& degenerate) {
  return std::size_t(block_sum(s.t.size(), [&](std::size_t begin, std::size_t end) {
    double n = 0;
    for (std::size_t f = begin; f < end; ++f)
      n += !degenerate[f] && too_small_in_map(emb.area2(s, int(f)), face_area_3d(s, int(f)));
    return n;
  }));
}

// Conformal map scaled to the area-preserving rectangle, fold-overs untangled. With "auto"
// weights, retried with clamped weights (no negative weight: folds are rare) if more than 1 % of
// the faces are bad (conformal map), or if any is (a side branch's band: its pouch folds where the
// cotangent weights of its steep walls are negative and untangle cannot repair it; the clamped
// solve costs little on a branch). The solve needs only E; then `faces_ready` waits for the rest.
Embedding conformal_step(SegmentWork& w, const Edges& E, const std::vector<std::vector<int>>& loops,
                         const std::vector<std::vector<int>>& vf, const std::vector<char>& fixed,
                         const std::vector<char>& degenerate, const FlattenOptions& o,
                         const std::function<void()>& faces_ready) {
  const Surface& s = w.ann;
  auto attempt = [&](bool clamp, std::size_t& bad) {
    Harmonic h = solve_harmonic(s, E, loops[0], loops[1], clamp, &w.prior);
    faces_ready();
    w.prior = PriorSolve{h.vertex_order, std::move(h.factor), {}, {}};
    Embedding emb = embed_conformal(s, E, h, 1.0, 1.0);
    std::vector<double> area2(s.t.size());  // each face's in blocks on the worker threads, summed in face order
    for_each_block(s.t.size(), [&](std::size_t b, std::size_t e) {
      for (; b < e; ++b) area2[b] = emb.area2(s, int(b));
    });
    double signed_area = 0;
    for (double a : area2) signed_area += a;
    const double scale = std::sqrt(w.seg.area_3d / h.period);
    emb = embed_conformal(s, E, h, signed_area >= 0 ? 1.0 : -1.0, scale);
    w.seg.untangled_vertices = w.folds_pending ? 0 : untangle(s, vf, emb, fixed, degenerate);
    w.seg.weights = h.weights;
    w.seg.dirichlet_period_ratio = h.energy_u / h.period;
    bad = count_bad(s, emb, degenerate);
    return emb;
  };
  std::size_t bad = 0;
  Embedding emb = attempt(o.weights == "clamped", bad);
  const std::size_t tolerated = o.map == "conformal" || !w.branch ? s.t.size() / 100 : 0;
  if (o.weights == "auto" && (o.map == "conformal" || w.branch) && bad > tolerated) {
    std::size_t bad2 = 0;
    const FlatSegment keep = w.seg;
    Embedding e2 = attempt(true, bad2);
    if (bad2 < bad) return e2;
    w.seg = keep;
  }
  return emb;
}

void conformal(SegmentWork& w, const std::vector<std::vector<int>>& loops, const Prepared& p, const FlattenOptions& o,
               const std::function<void()>& faces_ready = [] {}) {
  w.emb = conformal_step(w, p.E, loops, p.vf, p.fixed, p.degenerate, o, faces_ready);
  w.seg.length = w.seg.area_3d / w.emb.period;  // the conformal rectangle: length x period = area
  w.seg.period = w.emb.period;
}

constexpr int kMaxBranchDepth = 3;  // branches of branches of branches
constexpr int kMaxPatchDepth = kMaxBranchDepth + 2;  // patches (hidden_patches.h) of bands down to this depth
std::vector<SegmentWork> flatten_surface(const Surface& s, std::size_t nloops, std::size_t c, double lumen_sign,
                                         const FlattenOptions& o, int depth, bool limb = false);

// Flattens the cut-off branches (each as a band of its own, recursively, side by side:
// branch_bands.h); returns their works and adds their wall area to `placed`. A branch that cannot
// be flattened counts as wall not shown.
std::vector<SegmentWork> flatten_branches(const std::vector<BranchPiece>& pieces, int component, double lumen_sign,
                                          const FlattenOptions& o, int depth, double& placed) {
  FlattenOptions bo = o;
  bo.end_cut_radius = std::min(o.end_cut_radius, 5.0);  // the tip of a pouch is wall, not an end
  return flatten_branch_pieces(pieces, [&](const BranchPiece& piece) {
    return tube_or_disk(piece, flatten_surface(piece.surface, piece.loops, std::size_t(component), lumen_sign, bo,
                                               depth + 1, piece.limb),
                        [&](const Surface& d) { return flatten_disk(d, component, lumen_sign, bo); }, depth + 1);
  }, placed);
}

// The side branches' works and the wall area the cut leaves in no band (faces dropped at a neck,
// branches that could not be flattened).
struct FlattenedBranches {
  std::vector<SegmentWork> works;
  double lost_area = 0;
};

// Cuts the side branches off the annulus and starts flattening them on a second thread, then
// re-solves the conformal map of what remains here: the segment goes on (centreline, area
// balance) while its branches are flattened. The future is invalid when nothing was cut.
std::future<FlattenedBranches> cut_branches(SegmentWork& w, std::vector<std::vector<int>>& loops, Prepared& p,
                                      const FlattenOptions& o, int depth) {
  auto cuts = find_branches(w.ann, p.E, w.emb, w.seg.length, w.lumen_sign, o.branch_min_area);
  const std::vector<char> keep = band_faces_after_cuts(w.ann, p.E, loops, cuts);  // the ends keep every vertex
  if (depth == 0) debug_clock("branches found");
  w.folds_pending = false;
  if (cuts.empty()) {  // this map stays: its folds are untangled now
    w.seg.untangled_vertices = untangle(w.ann, p.vf, w.emb, p.fixed, p.degenerate);
    return std::future<FlattenedBranches>();
  }
  std::vector<int> new_of_old;
  Surface rest = sub_surface(w.ann, keep, &new_of_old);
  Edges rest_edges = sub_edges(p.E, keep, new_of_old);
  std::vector<BranchPiece> pieces;
  FaceSetScratch scratch;  // one for the cuts
  for (const auto& cut : cuts) {  // each branch from its own faces (not a mask of the annulus' faces)
    const std::vector<int> in = clean_face_set(w.ann, p.E, cut.faces, &scratch);
    BranchPiece piece;
    piece.surface = sub_surface(w.ann, in);
    piece.neck_mm = cut.neck_mm;
    piece.tissue = cut.tissue;
    piece.limb = cut.neck_mm >= kLimbNeck * w.seg.period;
    for (int f : in)
      for (int v : w.ann.t[std::size_t(f)])
        if (new_of_old[v] >= 0) piece.neck.push_back(new_of_old[v]);
    pieces.push_back(std::move(piece));
  }
  const double annulus_area = surface_area(w.ann);
  for (auto& l : loops)
    for (int& v : l) v = new_of_old[v];
  std::vector<int> order;  // the colon's elimination order, restricted to what remains
  for (int v : w.prior.vertex_order)
    if (new_of_old[v] >= 0) order.push_back(new_of_old[v]);
  for (int& v : w.dissection_to_annulus)  // (a large colon: its nested dissection order instead, below)
    if (v >= 0) v = new_of_old[std::size_t(v)];
  w.prior.new_of_old = new_of_old;  // the re-solve updates the colon's factorisation
  w.ann = std::move(rest);
  w.prior.vertex_order = w.has_band_order() ? w.band_order() : std::move(order);
  const double cut_area = annulus_area - surface_area(w.ann);
  auto flattened = std::async(side_launch(), [pieces = std::move(pieces), component = w.seg.component,
                                                   lumen_sign = w.lumen_sign, o, depth, cut_area] {
    FlattenedBranches b;
    double placed = 0;
    b.works = flatten_branches(pieces, component, lumen_sign, o, depth, placed);
    b.lost_area = cut_area - placed;
    return b;
  });
  p = Prepared{std::move(rest_edges), {}, {}, {}};  // (an exception below joins the branches' future)
  if (depth == 0) debug_clock("branches cut off");
  // The rest's faces beside its solve (which reads neither them nor w.seg.area_3d; one-thread update).
  auto faces = std::async(side_launch(), [&w, &p] { prepare_faces(w, p); });
  conformal(w, loops, p, o, [&faces] { faces.wait(); });
  return flattened;
}

// The wall the band's finished map still hides, cut out as patches and flattened as bands of their
// own (hidden_patches.h; p.E and p.degenerate follow the cut, p.vf and p.fixed are stale after it);
// `new_of_old` gets the band's vertex map (empty: nothing cut).
std::vector<SegmentWork> flatten_patches(SegmentWork& w, Prepared& p, const FlattenOptions& o, int depth,
                                         std::vector<int>& new_of_old) {
  if (o.map != "area-balanced" || !(o.branch_min_area > 0) || depth >= kMaxPatchDepth) return {};
  PatchCut cut = cut_patches(w, p.E, p.degenerate,
                             hidden_patches(w, p.E, p.vf, p.degenerate, o.coverage_min_ratio, o.branch_min_area));
  if (cut.pieces.empty()) return {};
  new_of_old = std::move(cut.new_of_old);
  double placed = 0;
  std::vector<SegmentWork> works = flatten_branches(cut.pieces, w.seg.component, w.lumen_sign, o, depth, placed);
  for (SegmentWork& pw : works)
    if (pw.parent == -1) pw.seg.holds = "wall";  // the patches themselves (not branches found inside one)
  w.lost_area += cut.area_mm2 - placed;
  if (depth == 0) debug_clock("hidden wall cut out as patches and flattened");
  return works;
}

// Where each direct branch hangs on this segment: mean centreline position and LPS of its neck.
void attach_branches(const SegmentWork& w, std::vector<SegmentWork>& branches) {
  for (auto& b : branches) {
    if (b.parent != -1 || b.neck.empty()) continue;
    std::sort(b.neck.begin(), b.neck.end());
    b.neck.erase(std::unique(b.neck.begin(), b.neck.end()), b.neck.end());
    V3 m = V3::Zero();
    double along = 0;
    for (int v : b.neck) m += w.ann.p[v], along += w.along[v];
    m /= double(b.neck.size());
    b.seg.attach_lps = {m.x(), m.y(), m.z()};
    b.seg.attach_mm = along / double(b.neck.size());
  }
}

// Centreline from the level sets of u (crowded faces left out) and each vertex's arc length.
Centreline centreline_step(SegmentWork& w, const std::vector<std::vector<int>>& loops) {
  const Surface& ann = w.ann;
  std::vector<double> u(ann.p.size());  // (each vertex and face on its own, in blocks on the worker threads)
  for_each_block(ann.p.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) u[v] = std::clamp(w.emb.pos[v].x() / w.seg.length, 0.0, 1.0);
  });
  std::vector<char> use_face(ann.t.size(), 1);
  const double conformal_scale = w.seg.area_3d / (w.seg.length * w.seg.period);
  for_each_block(ann.t.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t f = begin; f < end; ++f)
      use_face[f] = w.emb.area2(ann, int(f)) * conformal_scale >= 0.05 * face_area_3d(ann, int(f));
  });
  const V3 ca = loop_centre(ann, loops[0]), cb = loop_centre(ann, loops[1]);
  Centreline cl = centreline_from_u(ann, u, use_face, ca, cb);
  w.seg.centreline = cl.points;
  w.seg.centreline_length = cl.length;
  w.along.resize(ann.p.size());
  for_each_block(ann.p.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) w.along[v] = cl.s_of_u(u[v]);
  });
  return cl;
}

// One colon segment (or side branch): the segment's work first, then its branches (parent = index
// in the returned list; -1 for the first). A `limb`-sized branch that is a colon stretch
// (branch_bands.h) gets the colon band's axis; other branches a pouch's.
std::vector<SegmentWork> flatten_surface(const Surface& s, std::size_t nloops, std::size_t c, double lumen_sign,
                                         const FlattenOptions& o, int depth, bool limb) {
  SegmentWork w;
  w.lumen_sign = lumen_sign;
  w.branch = depth > 0;
  w.seg.component = int(c);
  w.seg.input_kind = nloops == 0 ? "closed" : nloops == 1 ? "one open end" : "tube";
  w.seg.map = o.map;
  auto phase = [depth](const char* what) {  // progress lines for the colon segments, not their branches
    if (depth == 0) phase_done(what), debug_clock(what);
  };
  const DebugClockScope clock_scope(depth == 0);
  BandTimer timer;
  Edges edges;
  auto loops = open_annulus(s, nloops, o, c, w, edges);
  const V3 ca = loop_centre(w.ann, loops[0]), cb = loop_centre(w.ann, loops[1]);
  w.seg.end_a = {ca.x(), ca.y(), ca.z()};
  w.seg.end_b = {cb.x(), cb.y(), cb.z()};
  Prepared p{std::move(edges), {}, {}, {}};
  prepare_faces(w, p);
  w.cap_area = surface_area(s) - w.seg.area_3d;  // (prepare: the annulus' area)
  phase("ends opened");
  timer.mark("opened");
  const bool may_cut = o.map == "area-balanced" && o.branch_min_area > 0 && depth < kMaxBranchDepth;
  // A colon map that side branches may replace is untangled only if it stays (branch detection
  // reads the collapse, which untangling cannot lift).
  w.folds_pending = may_cut && !w.branch;
  conformal(w, loops, p, o);
  if (depth == 0) debug_stats("first conformal", w, p.degenerate);
  phase("conformal map");
  std::future<FlattenedBranches> cut;
  if (may_cut) cut = cut_branches(w, loops, p, o, depth);
  w.prior = PriorSolve{};  // the last factorisation's memory back
  if (cut.valid()) phase("side branches cut, conformal map again");
  timer.mark("conformal");
  const Centreline cl = centreline_step(w, loops);
  phase("centreline");
  debug_stats("conformal", w, p.degenerate);
  const bool pouch = depth > 0 && !(limb && colon_stretch(cl.length, w.seg.length, w.seg.period, w.ann.t.size()));
  if (o.map == "area-balanced") area_balanced_step(w, cl, loops, p.E, p.vf, p.fixed, p.degenerate, o, pouch);
  if (o.map == "area-balanced") phase("area balance");
  timer.mark("balance");
  w.dissection = {};  // the order's memory back (it is not needed after the balance)
  w.dissection_to_annulus = {};
  debug_stats("final", w, p.degenerate);
  std::vector<int> patched;  // the band's vertex map when patches were cut out of it
  std::vector<SegmentWork> patches = flatten_patches(w, p, o, depth, patched);
  timer.mark("patches");
  const bool any_cut = cut.valid();
  FlattenedBranches flattened = any_cut ? cut.get() : FlattenedBranches{};
  timer.mark("branches waited");
  if (any_cut) phase("side branches flattened (beside the above)");
  std::vector<SegmentWork>& branches = flattened.works;
  join_patches(branches, patched, patches);
  w.lost_area += flattened.lost_area;
  attach_branches(w, branches);
  w.seg.faces = w.ann.t.size();
  w.seg.vertices = w.ann.p.size();
  measure(w, p.E, p.degenerate, o);
  phase("distortion and coverage");
  timer.mark("measured");
  timer.report(depth, s.t.size(), w.ann.t.size(), patches.size(), branches.size());
  std::vector<SegmentWork> out;
  out.push_back(std::move(w));
  for (auto& b : branches) {
    b.parent += 1;  // -1 (this segment) -> 0; others shift by one
    out.push_back(std::move(b));
  }
  return out;
}

// One colon segment to flatten: its surface, boundary loops, component id and lumen side.
struct SegmentJob {
  Surface surface;
  std::size_t loops = 0, component = 0;
  double lumen_sign = 1;
  std::vector<SegmentWork> works;  // the result: the segment's work, then its branches
};

// The segments flattened side by side on the worker threads (each on its own: the results do not
// depend on which thread or in which order), their works gathered in segment order.
std::vector<SegmentWork> flatten_segments(std::vector<SegmentJob>& jobs, const FlattenOptions& o) {
  std::vector<std::function<void()>> tasks;
  for (SegmentJob& j : jobs)
    tasks.push_back([&j, &o] {
      j.works = flatten_surface(j.surface, j.loops, j.component, j.lumen_sign, o, 0);
      j.surface = Surface{};  // its memory back
    });
  parallel_tasks(tasks);
  std::vector<SegmentWork> work;
  for (SegmentJob& j : jobs) {
    const int base = int(work.size());
    for (auto& w : j.works) {
      if (w.parent >= 0) w.parent += base;
      work.push_back(std::move(w));
    }
  }
  return work;
}

}  // namespace

FlatMap flatten_colon(const Mesh& mesh, const FlattenOptions& opts) {
  return flatten_colon(to_triangle_list(mesh), opts);
}

FlatMap flatten_colon(const TriangleList& mesh, const FlattenOptions& opts, const TopologyReport* topology) {
  const flat_detail::TrimKeptBlocksAtScopeEnd factor_memory_given_back;  // factor_memory.h
  if (opts.weights != "cotan" && opts.weights != "clamped" && opts.weights != "auto")
    throw UsageError("--weights must be cotan, clamped or auto (got '" + opts.weights + "')");
  if (opts.map != "area-balanced" && opts.map != "conformal")
    throw UsageError("--map must be area-balanced or conformal (got '" + opts.map + "')");
  TopologyReport analysed;  // unless the caller's fits the mesh
  const TopologyReport& topo =
      topology && topology_fits(*topology, mesh) ? *topology : (analysed = analyze_topology(mesh));
  FlatMap out;
  out.input_vertices = topo.vertices;
  out.input_faces = topo.faces;
  if (topo.faces == 0) throw PreconditionError("the surface has no triangles");
  if (!topo.manifold) throw PreconditionError("the surface is not a 2-manifold; flatten needs a clean colon surface");
  ComponentScreen screen(mesh, topo, opts);
  std::vector<SegmentJob> jobs;
  for (std::size_t c = 0; c < topo.components.size(); ++c) {
    if (!screen.admit(c)) continue;
    jobs.push_back({component_surface(mesh, topo, int(c)), topo.components[c].boundary_loops, c, screen.lumen_sign(c), {}});
  }
  out.skipped_components = screen.skipped().size();
  out.skipped = screen.skipped();
  if (jobs.empty()) screen.nothing_flattened();
  std::vector<SegmentWork> work = flatten_segments(jobs, opts);
  double xmin = 1e300, xmax = -1e300;
  for (const auto& p : mesh.points) xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
  const std::vector<char> reversed = label_and_order(work, 0.5 * (xmin + xmax));
  flat_detail::emit_segments(work, reversed, opts, out);
  return out;
}

TriangleList flat_to_surface(const FlatMap& flat, std::vector<int>* flat_to_3d) {
  TriangleList t;
  std::unordered_map<int, int> map;
  map.reserve(flat.uv.size());
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

namespace cf::flat_detail {

// (flatten_internal.h)
void prepare_faces(SegmentWork& w, Prepared& p) {
  const Surface& ann = w.ann;
  std::vector<double> area(ann.t.size());  // w.seg.area_3d: summed as surface_area sums
  w.seg.area_3d = 0;
  for (std::size_t f = 0; f < ann.t.size(); ++f) area[f] = face_area_3d(ann, int(f)), w.seg.area_3d += area[f];
  p.degenerate.assign(ann.t.size(), 0);
  const double mean_area = w.seg.area_3d / double(ann.t.size());
  for (std::size_t f = 0; f < ann.t.size(); ++f) p.degenerate[f] = area[f] <= 1e-6 * mean_area;
  p.fixed.assign(ann.p.size(), 0);  // the ends and the rims of cut-off branches
  for (std::size_t e = 0; e < p.E.ev.size(); ++e)
    if (p.E.ef[e][1] < 0) p.fixed[p.E.ev[e][0]] = p.fixed[p.E.ev[e][1]] = 1;
  p.vf = vertex_faces(ann);
}

}  // namespace cf::flat_detail
