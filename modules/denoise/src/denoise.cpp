#include "colonflat/denoise/denoise.h"

#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/stumps.h"
#include "denoise_internal.h"

namespace cf {

void validate_denoise_options(const DenoiseOptions& o) {
  denoise_param_table().validate(o);  // each parameter's range and choices
  if (o.method == "paper" && o.remove_stumps > 0)
    throw UsageError("--remove-stumps needs --method exact (the paper's method is kept as published)");
  if (o.method == "paper" && o.policy != "shortest")
    throw UsageError("--policy " + o.policy + " needs --method exact (the paper's method has no loop types)");
}

namespace {

// Postconditions of the exact method (components, boundaries, manifold, oriented, genus per
// component as counted); returns the per-component report.
nlohmann::json check_exact_result(const detail::DenoiseState& st, const TopologyReport& b, const TopologyReport& a) {
  if (a.components.size() != b.components.size() || a.boundary_loops != b.boundary_loops || !a.manifold ||
      !a.consistently_oriented)
    throw Error("denoise: postcondition failed: components " + std::to_string(b.components.size()) + " -> " +
                std::to_string(a.components.size()) + ", boundary loops " + std::to_string(b.boundary_loops) +
                " -> " + std::to_string(a.boundary_loops) + (a.manifold ? "" : ", not manifold"));
  std::vector<int> rep(b.components.size(), -1);  // components matched through an input face of each
  for (auto f : st.mesh.faces()) {
    if (f.idx() >= static_cast<int>(b.face_component.size())) break;
    const int c = b.face_component[f.idx()];
    if (rep[c] < 0) rep[c] = a.face_component[f.idx()];
  }
  nlohmann::json comps = nlohmann::json::array();
  for (std::size_t c = 0; c < b.components.size(); ++c) {
    const auto& ca = a.components.at(rep[c]);
    if (!ca.genus || *ca.genus != st.genus_left[c])
      throw Error("denoise: postcondition failed: component " + std::to_string(c) + " should have genus " +
                  std::to_string(st.genus_left[c]) + " after surgery, has " +
                  (ca.genus ? std::to_string(*ca.genus) : std::string("undefined")));
    comps.push_back({{"id", c},
                     {"genus_before", *b.components[c].genus},
                     {"genus_after", *ca.genus},
                     {"faces_before", b.components[c].faces},
                     {"faces_after", ca.faces},
                     {"boundary_loops", ca.boundary_loops}});
  }
  return comps;
}

nlohmann::json paper_components(const TopologyReport& a) {
  nlohmann::json comps = nlohmann::json::array();
  for (std::size_t c = 0; c < a.components.size(); ++c)
    comps.push_back({{"id", c},
                     {"genus_after", a.components[c].genus ? nlohmann::json(*a.components[c].genus) : nlohmann::json(nullptr)},
                     {"faces_after", a.components[c].faces}});
  return comps;
}

// Stump removal after the checks (they match components through input face ids, which its
// garbage collection renumbers); topology is checked again. Replaces `after`.
nlohmann::json run_stumps(detail::DenoiseState& st, const DenoiseOptions& o, TopologyReport& after) {
  Stopwatch sw;
  const std::vector<StumpRecord> recs = remove_stumps(st.mesh, st.cap_rings, StumpOptions{o.remove_stumps, 1.5});
  TopologyReport now = analyze_topology(st.mesh);
  auto genera = [](const TopologyReport& t) {
    std::vector<int> g;
    for (const auto& c : t.components) g.push_back(c.genus ? *c.genus : -1);
    std::sort(g.begin(), g.end());
    return g;
  };
  if (now.components.size() != after.components.size() || genera(now) != genera(after) ||
      now.boundary_loops != after.boundary_loops || !now.manifold || !now.consistently_oriented)
    throw Error("denoise: postcondition failed after stump removal: components " +
                std::to_string(after.components.size()) + " -> " + std::to_string(now.components.size()) +
                ", genus " + std::to_string(*after.genus) + " -> " + (now.genus ? std::to_string(*now.genus) : "?"));
  nlohmann::json list = nlohmann::json::array();
  std::size_t removed_faces = 0;
  for (const auto& r : recs) {
    removed_faces += r.faces_removed;
    list.push_back({{"length_mm", r.length_mm},
                    {"ring_length_mm", r.ring_length_mm},
                    {"base_length_mm", r.base_length_mm},
                    {"faces_removed", r.faces_removed},
                    {"cap_faces", r.cap_faces}});
  }
  after = std::move(now);
  st.t.stumps = sw.seconds();
  return {{"removed", recs.size()}, {"rings_examined", st.cap_rings.size()}, {"faces_removed", removed_faces},
          {"max_length_mm", o.remove_stumps}, {"stumps", list}};
}

nlohmann::json vec_json(const Vec3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); }

nlohmann::json loop_json(const LoopRecord& L) {
  return {{"id", L.id},
          {"iteration", L.iteration},
          {"component", L.component},
          {"vertex_ids", L.vertex_ids},
          {"vertex_count", L.vertex_ids.size()},
          {"length_mm", L.length},
          {"type", L.type},
          {"separating", L.separating},
          {"cap_intersections", L.cap_intersections},
          {"replaces_loop_of_mm", L.replaced_length},
          {"replaced_loop_cap_intersections", L.replaced_intersections},
          {"centroid_lps_mm", vec_json(L.centroid)},
          {"diameter_mm", L.diameter_mm},
          {"cross_section_area_mm2", L.cross_section_area_mm2},
          {"cross_section_normal", vec_json(L.cross_section_normal)}};
}

nlohmann::json loops_report(const std::vector<LoopRecord>& loops, nlohmann::json* totals) {
  std::size_t loop_vertices = 0, cap_intersections = 0, unclean = 0;
  double loop_len = 0, longest = 0;
  nlohmann::json list = nlohmann::json::array();
  for (const auto& L : loops) {
    loop_vertices += L.vertex_ids.size();
    loop_len += L.length;
    longest = std::max(longest, L.length);
    cap_intersections += L.cap_intersections;
    unclean += L.cap_intersections > 0;
    list.push_back(loop_json(L));
  }
  *totals = {{"loops", loops.size()},          {"loop_vertices", loop_vertices},
             {"loop_length_mm", loop_len},      {"longest_loop_mm", longest},
             {"cap_intersections", cap_intersections}, {"loops_with_cap_intersections", unclean}};
  return list;
}

// The whole run, its mesh built in `out` (empty) and the rest of the result in `res`.
void run_denoise(const Mesh& input, const DenoiseOptions& o, const DenoiseProgress& progress,
                 const TopologyReport* input_topology, Mesh& out, DenoiseResult& res) {
  validate_denoise_options(o);
  if (out.n_vertices() != 0 || out.n_faces() != 0) throw PreconditionError("denoise_into: the output mesh must be empty");
  Stopwatch total;
  detail::DenoiseState st(out);
  const int threads = std::min(thread_count(), detail::kMaxThreads);
  if (threads > 1) st.worker = std::make_unique<detail::SearchWorker>(threads);
  double t_analysis = 0;
  detail::prepare_input(st, input, o, &res.before, &t_analysis, input_topology);
  phase_done("topology analysis");
  const TopologyReport& b = res.before;
  const int needed = std::max(0, *b.genus - o.target_genus);
  nlohmann::json stats = nlohmann::json::object();
  std::string reason = "target genus reached";
  if (needed > 0)
    reason = o.method == "exact" ? detail::run_exact(st, o, needed, progress, b.mean_edge_length, stats)
                                 : detail::run_paper(st, o, needed, progress, stats);
  phase_done("loops found and cut");
  Stopwatch sw;
  res.after = analyze_topology(st.mesh);
  st.t.verify += sw.seconds();
  const nlohmann::json comps = o.method == "exact" ? check_exact_result(st, b, res.after) : paper_components(res.after);
  phase_done("verification");
  const nlohmann::json stumps = o.remove_stumps > 0 ? run_stumps(st, o, res.after) : nlohmann::json(nullptr);
  res.loops = st.loops;
  nlohmann::json totals;
  const nlohmann::json loops = loops_report(res.loops, &totals);
  if (o.strict && totals["cap_intersections"].get<std::size_t>() > 0)
    throw CapIntersectionError("--strict: " + totals["loops_with_cap_intersections"].dump() + " loop(s) have caps that intersect the surface (" +
                totals["cap_intersections"].dump() + " triangle pairs); see the report's loops[].cap_intersections");
  auto g = [](const TopologyReport& t) { return t.genus ? nlohmann::json(*t.genus) : nlohmann::json(nullptr); };
  res.report = {{"method", o.method},
                {"policy", o.policy},
                {"genus_before", g(b)},
                {"genus_after", g(res.after)},
                {"components_before", b.components.size()},
                {"components_after", res.after.components.size()},
                {"faces_before", b.faces},
                {"faces_after", res.after.faces},
                {"per_component", comps},
                {"stop_reason", reason},
                {"loops", loops},
                {"totals", totals},
                {"search", stats},
                {"stumps", stumps},
                {"time_s",
                 {{"analysis", t_analysis},
                  {"homology_and_cut_graph", st.t.homology},
                  {"loop_search", st.t.search},
                  {"surgery", st.t.surgery},
                  {"verification", st.t.verify},
                  {"stumps", st.t.stumps},
                  {"total", total.seconds()}}},
                {"units", "mm"},
                {"coordinate_system", "LPS"}};
}

}  // namespace

DenoiseResult denoise(const Mesh& input, const DenoiseOptions& o, const DenoiseProgress& progress,
                      const TopologyReport* input_topology) {
  DenoiseResult res;
  run_denoise(input, o, progress, input_topology, res.mesh, res);
  return res;
}

DenoiseResult denoise_into(Mesh& out, const Mesh& input, const DenoiseOptions& o, const DenoiseProgress& progress,
                           const TopologyReport* input_topology) {
  DenoiseResult res;
  run_denoise(input, o, progress, input_topology, out, res);
  return res;
}

}  // namespace cf
