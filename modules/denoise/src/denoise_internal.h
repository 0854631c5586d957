#pragma once
// Internal to the denoise module: state shared by the exact and paper methods.
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/denoise/denoise.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/surgery.h"
#include "search_worker.h"

namespace cf::detail {

// Cell size of the cap guard grid, in mean edge lengths: larger cells mean fewer cells per face
// to fill at the build (1.56 M-face sphere: surgery 0.56 s at 2, 0.45 s at 3) and more
// candidates per cap check, a small cost next to the build.
constexpr double kGuardCellEdges = 3.0;

// Threads denoise uses at most (cf::thread_count() above it is capped): a batch of group searches
// holds at most 16 groups (ExactGreedy::batch_size()), and each thread keeps its own per-vertex
// search state (about 40 bytes per vertex), so more threads would only hold memory.
constexpr int kMaxThreads = 16;

struct Timers {
  double homology = 0, search = 0, surgery = 0, verify = 0, stumps = 0;
};

// The mesh being denoised and what is known of its vertices.
struct DenoiseState {
  // The result's mesh, worked on in place: OpenMesh meshes have no move operations (their
  // virtual destructors suppress them), so handing over a separate one would copy 140 MB at
  // 1.56 M faces.
  explicit DenoiseState(Mesh& result_mesh) : mesh(result_mesh) {}
  Mesh& mesh;
  std::size_t n_input = 0;
  std::vector<int> origin;      // vertex -> input vertex id, or -1 (cap centres)
  std::vector<int> component;   // vertex -> input component id
  std::vector<int> genus_left;  // per input component
  std::vector<LoopRecord> loops;
  std::vector<std::vector<Mesh::VertexHandle>> cap_rings;  // both rings of every surgery
  Timers t;
  std::unique_ptr<FaceGrid> guard;  // built at the first surgery when caps are checked (or by prepare_input())
  double mean_edge = 0;
  std::unique_ptr<SearchWorker> worker;             // the helper threads (cf::thread_count() > 1), else null
  long long left_caps_ahead = 0;  // SurgeryResult::left_caps_ahead summed over the surgeries (kept or undone)
  std::unique_ptr<HomologyBasis> initial_homology;  // built by prepare_input() with helper threads, taken by the exact method

  // Registers vertices created by a surgery: copies[i] is a copy of copies_of[i]; the others
  // (caps) have no input id.
  void extend_vertices(const std::vector<Mesh::VertexHandle>& copies_of, const std::vector<Mesh::VertexHandle>& copies,
                       int comp);
  LoopRecord& record(const std::vector<Mesh::VertexHandle>& loop, int iteration, bool separating);
};

// Copies `input` into st.mesh (garbage-collected) and analyses the input's topology into
// `before` (time in *t_analysis). With st.worker, the analysis runs on the helper thread while
// this one copies the mesh and builds the cap guard grid and (exact method) the first homology
// basis. `known` (optional) = analyze_topology(input) made by the caller: taken instead of a new
// analysis when it fits the input (its size, no garbage), and then the helper builds the grid
// beside the copy and the first basis. Throws PreconditionError when the input is not a valid
// denoise input.
void prepare_input(DenoiseState& st, const Mesh& input, const DenoiseOptions& o, TopologyReport* before,
                   double* t_analysis, const TopologyReport* known = nullptr);

// How hard a surgery looks for clean caps (with --check-caps): kFull, every step; kFirst, every
// step, but the concentric placements are only searched for a clean one (a loop's first cut,
// undone unless clean: if no alternative is clean either, the loop is cut again with kAgain);
// kTrial, an attempt undone unless its caps are clean (concentric caps in one placement: their
// pairs are only counted up to the first); kPlainTrial, a trial without the restricted
// triangulations; kAgain, kFull without the triangulated caps, for a loop cut again after its kFirst
// cut on the same mesh found none of them clean (the same steps on the same input fail again).
enum class CapAttempt { kFull, kFirst, kTrial, kPlainTrial, kAgain };

// Surgery plus bookkeeping; returns whether the two sides stayed connected.
bool cut_loop(DenoiseState& st, const std::vector<Mesh::VertexHandle>& loop, const DenoiseOptions& o,
              HomologyBasis* hb, SurgeryResult* out, CapAttempt attempt = CapAttempt::kFull);

// Both return the reason the method stopped; `stats` receives method-specific counters.
std::string run_exact(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                      double mean_edge, nlohmann::json& stats);
std::string run_paper(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                      nlohmann::json& stats);

}  // namespace cf::detail
