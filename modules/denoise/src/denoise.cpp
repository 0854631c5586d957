#include "colonflat/denoise/denoise.h"

#include <algorithm>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/stumps.h"
#include "denoise_internal.h"

namespace cf {

void validate_denoise_options(const DenoiseOptions& o) {
  if (o.method != "exact" && o.method != "paper")
    throw UsageError("--method must be exact or paper (got '" + o.method + "')");
  if (o.policy != "shortest" && o.policy != "cut" && o.policy != "fill")
    throw UsageError("--policy must be shortest, cut or fill (got '" + o.policy + "')");
  if (!(o.max_loop_length > 0)) throw UsageError("--max-loop-length must be > 0 (got " + format_number(o.max_loop_length) + ")");
  if (o.target_genus < 0) throw UsageError("--target-genus must be >= 0 (got " + std::to_string(o.target_genus) + ")");
  if (!(o.ring_pull >= 0 && o.ring_pull <= 0.5))
    throw UsageError("--ring-pull must be in [0, 0.5] (got " + format_number(o.ring_pull) + ")");
  if (!(o.initial_radius >= 0)) throw UsageError("--initial-radius must be >= 0");
  if (!(o.remove_stumps >= 0)) throw UsageError("--remove-stumps must be >= 0 (got " + format_number(o.remove_stumps) + ")");
  if (o.method == "paper" && o.remove_stumps > 0)
    throw UsageError("--remove-stumps needs --method exact (the paper's method is kept as published)");
  if (o.method == "paper" && o.policy != "shortest")
    throw UsageError("--policy " + o.policy + " needs --method exact (the paper's method has no loop types)");
}

DenoiseResult denoise(const Mesh& input, const DenoiseOptions& o, const DenoiseProgress& progress) {
  validate_denoise_options(o);
  Stopwatch total;
  DenoiseResult res;
  detail::DenoiseState st;
  st.mesh = input;
  st.mesh.garbage_collection();
  Stopwatch sw;
  res.before = analyze_topology(st.mesh);
  const double t_analysis = sw.seconds();
  const TopologyReport& b = res.before;
  if (b.faces == 0) throw PreconditionError("input mesh has no faces");
  if (!b.manifold || !b.orientable)
    throw PreconditionError("input must be an orientable 2-manifold; got " + std::to_string(b.nonmanifold_edges) +
                            " non-manifold edges, " + std::to_string(b.nonmanifold_vertices) + " non-manifold vertices" +
                            (b.orientable ? "" : ", non-orientable"));
  if (b.unreferenced_vertices) throw PreconditionError("input has unreferenced vertices");
  if (o.method == "paper" && !b.closed)
    throw PreconditionError("--method paper needs closed components (the paper's Algorithm 4 input); got " +
                            std::to_string(b.boundary_loops) + " boundary loops - use --method exact");
  st.n_input = st.mesh.n_vertices();
  st.mean_edge = b.mean_edge_length;
  st.origin.resize(st.n_input);
  for (std::size_t v = 0; v < st.n_input; ++v) st.origin[v] = static_cast<int>(v);
  st.component.assign(st.n_input, -1);
  for (auto f : st.mesh.faces())
    for (auto v : st.mesh.fv_range(f)) st.component[v.idx()] = b.face_component[f.idx()];
  for (const auto& c : b.components) st.genus_left.push_back(*c.genus);
  const int genus_before = *b.genus;
  const int needed = std::max(0, genus_before - o.target_genus);

  nlohmann::json stats = nlohmann::json::object();
  std::string reason = "target genus reached";
  if (needed > 0) {
    reason = o.method == "exact" ? detail::run_exact(st, o, needed, progress, b.mean_edge_length, stats)
                                 : detail::run_paper(st, o, needed, progress, stats);
  }
  sw.restart();
  res.after = analyze_topology(st.mesh);
  st.t.verify += sw.seconds();

  // Postconditions.
  const TopologyReport& a = res.after;
  nlohmann::json comps = nlohmann::json::array();
  if (o.method == "exact") {
    if (a.components.size() != b.components.size() || a.boundary_loops != b.boundary_loops || !a.manifold ||
        !a.consistently_oriented)
      throw Error("denoise: postcondition failed: components " + std::to_string(b.components.size()) + " -> " +
                  std::to_string(a.components.size()) + ", boundary loops " + std::to_string(b.boundary_loops) +
                  " -> " + std::to_string(a.boundary_loops) + (a.manifold ? "" : ", not manifold"));
    // Match components through an input vertex of each.
    std::vector<int> rep(b.components.size(), -1);
    for (auto f : st.mesh.faces()) {
      if (f.idx() >= static_cast<int>(b.face_component.size())) break;
      const int c = b.face_component[f.idx()];
      if (rep[c] < 0) rep[c] = a.face_component[f.idx()];
    }
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
  } else {
    for (std::size_t c = 0; c < a.components.size(); ++c)
      comps.push_back({{"id", c}, {"genus_after", a.components[c].genus ? nlohmann::json(*a.components[c].genus) : nlohmann::json(nullptr)},
                       {"faces_after", a.components[c].faces}});
  }

  // Stumps: after the checks above (they match components through input face ids, which the
  // removal's garbage collection renumbers); topology is checked again.
  nlohmann::json stumps = nullptr;
  if (o.remove_stumps > 0) {
    sw.restart();
    const std::vector<StumpRecord> recs = remove_stumps(st.mesh, st.cap_rings, StumpOptions{o.remove_stumps, 1.5});
    TopologyReport after = analyze_topology(st.mesh);
    auto genera = [](const TopologyReport& t) {
      std::vector<int> g;
      for (const auto& c : t.components) g.push_back(c.genus ? *c.genus : -1);
      std::sort(g.begin(), g.end());
      return g;
    };
    if (after.components.size() != a.components.size() || genera(after) != genera(a) ||
        after.boundary_loops != a.boundary_loops || !after.manifold || !after.consistently_oriented)
      throw Error("denoise: postcondition failed after stump removal: components " +
                  std::to_string(a.components.size()) + " -> " + std::to_string(after.components.size()) +
                  ", genus " + std::to_string(*a.genus) + " -> " + (after.genus ? std::to_string(*after.genus) : "?"));
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
    stumps = {{"removed", recs.size()}, {"rings_examined", st.cap_rings.size()}, {"faces_removed", removed_faces},
              {"max_length_mm", o.remove_stumps}, {"stumps", list}};
    res.after = std::move(after);
    st.t.stumps = sw.seconds();
  }

  res.loops = st.loops;
  res.mesh = std::move(st.mesh);
  std::size_t loop_vertices = 0, cap_intersections = 0;
  double loop_len = 0;
  nlohmann::json loops = nlohmann::json::array();
  for (const auto& L : res.loops) {
    loop_vertices += L.vertex_ids.size();
    loop_len += L.length;
    cap_intersections += L.cap_intersections;
    loops.push_back({{"id", L.id},
                     {"iteration", L.iteration},
                     {"component", L.component},
                     {"vertex_ids", L.vertex_ids},
                     {"vertex_count", L.vertex_ids.size()},
                     {"length_mm", L.length},
                     {"type", L.type},
                     {"separating", L.separating},
                     {"cap_intersections", L.cap_intersections}});
  }
  auto g = [](const TopologyReport& t) { return t.genus ? nlohmann::json(*t.genus) : nlohmann::json(nullptr); };
  res.report = {{"method", o.method},
                {"policy", o.policy},
                {"genus_before", g(b)},
                {"genus_after", g(a)},
                {"components_before", b.components.size()},
                {"components_after", a.components.size()},
                {"faces_before", b.faces},
                {"faces_after", a.faces},
                {"per_component", comps},
                {"stop_reason", reason},
                {"loops", loops},
                {"totals", {{"loops", res.loops.size()}, {"loop_vertices", loop_vertices}, {"loop_length_mm", loop_len}, {"cap_intersections", cap_intersections}}},
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
                {"units", "mm"}};
  return res;
}

}  // namespace cf
