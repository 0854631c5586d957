// Setting up a denoise run: the working copy of the input, the input's topology and, with two
// threads, the cap guard grid and the first homology basis built at the same time.
#include <exception>
#include <iterator>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/topology.h"
#include "colonflat/denoise/face_grid.h"
#include "denoise_internal.h"

namespace cf::detail {

namespace {

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
  for (auto f : st.mesh.faces())
    for (auto v : st.mesh.fv_range(f)) st.component[v.idx()] = b.face_component[f.idx()];
  for (const auto& c : b.components) st.genus_left.push_back(*c.genus);
}

// Runs `mine` here and `theirs` on the helper thread; rethrows the helper's exception.
void run_both(SearchWorker& worker, const std::function<void()>& mine, const std::function<void()>& theirs) {
  std::exception_ptr error;
  worker.run_both(mine, [&] {
    try {
      theirs();
    } catch (...) {
      error = std::current_exception();
    }
  });
  if (error) std::rethrow_exception(error);
}

}  // namespace

void prepare_input(DenoiseState& st, const Mesh& input, const DenoiseOptions& o, TopologyReport* before,
                   double* t_analysis) {
  auto copy = [&] {
    st.mesh = input;
    if (has_garbage(st.mesh)) st.mesh.garbage_collection();
  };
  auto analyse = [&](const Mesh& m) {
    Stopwatch sw;
    *before = analyze_topology(m);
    *t_analysis = sw.seconds();
  };
  if (st.worker && !has_garbage(input)) {  // the copy keeps the input's element ids
    run_both(*st.worker, copy, [&] { analyse(input); });
  } else {
    copy();
    analyse(st.mesh);
  }
  check_input(*before, o);
  init_state(st, *before);
}

void prepare_search(DenoiseState& st, const DenoiseOptions& o) {
  if (!st.worker) return;
  auto guard = [&] {
    Stopwatch grid_sw;
    if (o.check_caps && !st.guard) st.guard = std::make_unique<FaceGrid>(st.mesh, 2.0 * st.mean_edge);
    st.t.surgery += grid_sw.seconds();  // where cut_loop() counts it when it builds the grid
  };
  if (o.method != "exact") return guard();
  Stopwatch sw;
  run_both(
      *st.worker,
      [&] {
        st.initial_homology = std::make_unique<HomologyBasis>();
        st.initial_homology->build(st.mesh);
        st.t.homology += sw.seconds();
      },
      guard);
}

}  // namespace cf::detail
