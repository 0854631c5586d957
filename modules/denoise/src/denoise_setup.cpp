// Setting up a denoise run: the working copy of the input, the input's topology and, with
// helper threads, the cap guard grid built at the same time and then the first homology basis.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <iterator>

#include "colonflat/core/error.h"
#include "colonflat/core/huge_pages.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_debug.h"
#include "denoise_internal.h"

namespace cf::detail {

namespace {

// The arrays every search and build reads at random (connectivity, points) on huge pages.
void mesh_on_huge_pages(const Mesh& m) {
  if (m.n_vertices() == 0 || m.n_edges() == 0 || m.n_faces() == 0) return;
  collapse_to_huge_pages(&m.vertex(Mesh::VertexHandle(0)), m.n_vertices() * sizeof(Mesh::Vertex));
  collapse_to_huge_pages(&m.edge(Mesh::EdgeHandle(0)), m.n_edges() * sizeof(Mesh::Edge));
  collapse_to_huge_pages(&m.face(Mesh::FaceHandle(0)), m.n_faces() * sizeof(Mesh::Face));
  collapse_to_huge_pages(m.points(), m.n_vertices() * sizeof(Vec3));
}

// Whether `m` holds only what every Mesh holds (points, connectivity, vertex/edge/face status):
// then copy_onto_huge_pages() copies all of it.
bool only_standard_properties(const Mesh& m) {
  static const Mesh plain;
  auto live = [](auto begin, auto end) { return std::count_if(begin, end, [](const auto* p) { return p != nullptr; }); };
  return live(m.vprops_begin(), m.vprops_end()) == live(plain.vprops_begin(), plain.vprops_end()) &&
         live(m.hprops_begin(), m.hprops_end()) == live(plain.hprops_begin(), plain.hprops_end()) &&
         live(m.eprops_begin(), m.eprops_end()) == live(plain.eprops_begin(), plain.eprops_end()) &&
         live(m.fprops_begin(), m.fprops_end()) == live(plain.fprops_begin(), plain.fprops_end()) &&
         live(m.mprops_begin(), m.mprops_end()) == live(plain.mprops_begin(), plain.mprops_end()) &&
         m.has_vertex_status() && m.has_edge_status() && m.has_face_status() && !m.has_halfedge_status();
}

// Copies `input` into the empty `out` with room for (nv, ne, nf) elements, every array advised
// onto huge pages before the copy first writes it. A copy assignment clones the arrays into fresh
// 4 KiB pages (1.56 M faces: 0.44 s, mostly page faults, then 0.17 s to collapse them onto huge
// pages). Precondition: only_standard_properties(input).
void copy_onto_huge_pages(const Mesh& input, Mesh& out, std::size_t nv, std::size_t ne, std::size_t nf) {
  out.reserve(nv, ne, nf);
  // One element of each kind, so that each array's first element is addressable; the copy
  // below replaces them.
  out.resize(1, 1, 1);
  // The element arrays are read-only through the public interface; the mesh is ours to advise.
  advise_huge_pages(const_cast<Mesh::Vertex*>(&out.vertex(Mesh::VertexHandle(0))), nv * sizeof(Mesh::Vertex));
  advise_huge_pages(const_cast<Mesh::Edge*>(&out.edge(Mesh::EdgeHandle(0))), ne * sizeof(Mesh::Edge));
  advise_huge_pages(const_cast<Mesh::Face*>(&out.face(Mesh::FaceHandle(0))), nf * sizeof(Mesh::Face));
  advise_huge_pages(&out.point(Mesh::VertexHandle(0)), nv * sizeof(Vec3));
  advise_huge_pages(&out.status(Mesh::VertexHandle(0)), nv * sizeof(OpenMesh::Attributes::StatusInfo));
  advise_huge_pages(&out.status(Mesh::EdgeHandle(0)), ne * sizeof(OpenMesh::Attributes::StatusInfo));
  advise_huge_pages(&out.status(Mesh::FaceHandle(0)), nf * sizeof(OpenMesh::Attributes::StatusInfo));
  out.assign_connectivity(input);  // the elements, into the reserved arrays; properties resized
  auto copy_array = [](const auto& from, auto& to) { std::copy(from.begin(), from.end(), to.begin()); };
  copy_array(input.property(input.points_pph()).data_vector(), out.property(out.points_pph()).data_vector());
  copy_array(input.property(input.vertex_status_pph()).data_vector(), out.property(out.vertex_status_pph()).data_vector());
  copy_array(input.property(input.edge_status_pph()).data_vector(), out.property(out.edge_status_pph()).data_vector());
  copy_array(input.property(input.face_status_pph()).data_vector(), out.property(out.face_status_pph()).data_vector());
}

// Whether garbage_collection() would change anything (elements marked deleted).
bool has_garbage(const Mesh& m) {
  auto count = [](auto range) { return static_cast<std::size_t>(std::distance(range.begin(), range.end())); };
  return count(m.vertices()) != m.n_vertices() || count(m.edges()) != m.n_edges() || count(m.faces()) != m.n_faces();
}

void check_input(const TopologyReport& b, const DenoiseOptions& o) {
  if (b.faces == 0) throw PreconditionError("input mesh has no faces");
  if (!b.manifold || !b.orientable)
    throw PreconditionError("input must be an orientable 2-manifold; got " + std::to_string(b.nonmanifold_edges) +
                            " non-manifold edges, " + std::to_string(b.nonmanifold_vertices) + " non-manifold vertices" +
                            (b.orientable ? "" : ", non-orientable"));
  if (b.unreferenced_vertices) throw PreconditionError("input has unreferenced vertices");
  if (o.method == "paper" && !b.closed)
    throw PreconditionError("--method paper needs closed components (the paper's Algorithm 4 input); got " +
                            std::to_string(b.boundary_loops) + " boundary loops - use --method exact");
}

void init_state(DenoiseState& st, const TopologyReport& b) {
  st.n_input = st.mesh.n_vertices();
  st.mean_edge = b.mean_edge_length;
  st.origin.resize(st.n_input);
  for (std::size_t v = 0; v < st.n_input; ++v) st.origin[v] = static_cast<int>(v);
  st.component.assign(st.n_input, -1);
  for (auto v : st.mesh.vertices()) {  // the component of any face at v (a boundary vertex's outgoing halfedge has none)
    auto h = st.mesh.halfedge_handle(v);
    if (!h.is_valid()) continue;
    if (st.mesh.is_boundary(h)) h = st.mesh.opposite_halfedge_handle(h);
    st.component[v.idx()] = b.face_component[st.mesh.face_handle(h).idx()];
  }
  for (const auto& c : b.components) st.genus_left.push_back(*c.genus);
}

// Mean edge length over the mesh's edges (the guard grid's cells are kGuardCellEdges of it).
double mean_edge_length(const Mesh& mesh) {
  double sum = 0;
  for (auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
  return mesh.n_edges() ? sum / static_cast<double>(mesh.n_edges()) : 0.0;
}

// The cap guard grid the first surgery needs, built while the helper thread analyses the input
// (wasted when the input needs no cut). Reads `from` only: st.mesh, or the input when it has no
// garbage (the copy then has its element ids and points, so the grid is the same).
void build_guard(DenoiseState& st, const DenoiseOptions& o, const Mesh& from) {
  Stopwatch sw;
  if (o.check_caps) st.guard = std::make_unique<FaceGrid>(from, kGuardCellEdges * mean_edge_length(from));
  st.t.surgery += sw.seconds();  // where cut_loop() counts it when it builds the grid
  if (denoise_debug()) std::fprintf(stderr, "denoise debug: set-up: guard grid %.3f s\n", sw.seconds());
}

// The exact method's first homology basis, once the input has passed its checks and has a handle
// to cut, with the cut graph's pruning on the helper beside the annotation (HomologyBasis::build:
// the same basis). It used to follow the guard grid on this thread while the helper, done with
// the analysis, waited (real CT surface: copy + grid + basis 1.7-3.0 s, analysis 1.1-1.9 s).
// With `beside` false the pruning follows the annotation on this thread (the helper is busy):
// the same basis.
void build_first_homology(DenoiseState& st, const DenoiseOptions& o, const TopologyReport& b, bool beside = true) {
  if (o.method != "exact" || *b.genus <= o.target_genus) return;
  Stopwatch sw;
  st.initial_homology = std::make_unique<HomologyBasis>();
  st.initial_homology->build(st.mesh, beside ? on_helper(st.worker.get()) : RunBoth{});
  st.t.homology += sw.seconds();
}

// Whether `t` can stand for analyze_topology(input): given, and of a mesh of the input's size
// with no garbage (analyze_topology's precondition; the caller vouches for the rest).
bool usable_topology(const TopologyReport* t, const Mesh& input) {
  return t && t->faces == input.n_faces() && t->vertices + t->unreferenced_vertices == input.n_vertices() &&
         !has_garbage(input);
}

}  // namespace

void prepare_input(DenoiseState& st, const Mesh& input, const DenoiseOptions& o, TopologyReport* before,
                   double* t_analysis, const TopologyReport* known) {
  auto copy = [&] {
    // Room for what surgery adds: the element arrays keep their capacity through the copy
    // (doubling the 2 M-edge array at the first surgery that overflows it cost 0.3 s).
    auto grown = [](std::size_t n) { return n + n / 16 + 4096; };
    const std::size_t nv = grown(input.n_vertices()), ne = grown(input.n_edges()), nf = grown(input.n_faces());
    if (only_standard_properties(input)) {
      copy_onto_huge_pages(input, st.mesh, nv, ne, nf);
      if (has_garbage(st.mesh)) st.mesh.garbage_collection();
      return;
    }
    st.mesh.reserve(nv, ne, nf);
    st.mesh = input;
    if (has_garbage(st.mesh)) st.mesh.garbage_collection();
    // The properties were cloned at the input's size: room for surgery now, before the arrays
    // go onto huge pages (a later growth would move them off).
    st.mesh.reserve(nv, ne, nf);
    mesh_on_huge_pages(st.mesh);
  };
  auto analyse = [&](const Mesh& m) {
    Stopwatch sw;
    *before = analyze_topology(m);
    *t_analysis = sw.seconds();
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: set-up: topology analysis %.3f s\n", *t_analysis);
  };
  auto copy_timed = [&] {
    Stopwatch sw;
    copy();
    if (denoise_debug()) std::fprintf(stderr, "denoise debug: set-up: copy %.3f s\n", sw.seconds());
  };
  if (usable_topology(known, input)) {  // no analysis: the grid on the helper beside the copy and first basis
    *before = *known;
    *t_analysis = 0;
    check_input(*before, o);
    if (st.worker)
      run_both(
          *st.worker,
          [&] {
            copy_timed();
            build_first_homology(st, o, *before, false);
          },
          [&] { build_guard(st, o, input); });
    else
      copy();
  } else if (st.worker && !has_garbage(input)) {  // the copy keeps the input's element ids
    run_both(
        *st.worker,
        [&] {
          copy_timed();
          build_guard(st, o, st.mesh);
        },
        [&] { analyse(input); });
    check_input(*before, o);
    build_first_homology(st, o, *before);
  } else {
    copy();
    analyse(st.mesh);
    check_input(*before, o);
  }
  init_state(st, *before);
}

}  // namespace cf::detail
