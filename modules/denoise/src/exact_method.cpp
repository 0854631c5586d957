// The exact method: at every step the shortest non-separating edge cycle of the current mesh,
// found by bounded Dijkstra searches from a source set, with per-source lower bounds shared
// between nearby sources (docs/denoise.md, "How it is fast").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numeric>

#include "colonflat/core/error.h"
#include "colonflat/core/geodesic_ball.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/loop_search.h"
#include "denoise_debug.h"
#include "exact_greedy.h"

namespace cf::detail {

void DenoiseState::extend_vertices(const std::vector<Mesh::VertexHandle>& copies_of,
                                   const std::vector<Mesh::VertexHandle>& copies, int comp) {
  origin.resize(mesh.n_vertices(), -1);
  component.resize(mesh.n_vertices(), comp);
  for (std::size_t i = 0; i < copies.size(); ++i) origin[copies[i].idx()] = origin[copies_of[i].idx()];
}

LoopRecord& DenoiseState::record(const std::vector<Mesh::VertexHandle>& loop, int iteration, bool separating) {
  LoopRecord r;
  r.id = static_cast<int>(loops.size());
  r.iteration = iteration;
  r.component = component[loop.front().idx()];
  for (auto v : loop) {
    r.vertex_ids.push_back(origin[v.idx()]);
    r.points.push_back(mesh.point(v));
  }
  r.length = loop_length(mesh, loop);
  describe_cross_section(&r);
  r.type = loop_type_name(classify_loop(mesh, loop));
  r.separating = separating;
  loops.push_back(std::move(r));
  return loops.back();
}

bool cut_loop(DenoiseState& st, const std::vector<Mesh::VertexHandle>& loop, const DenoiseOptions& o,
              HomologyBasis* hb, SurgeryResult* out, CapAttempt attempt) {
  const int comp = st.component[loop.front().idx()];
  Stopwatch sw;
  SurgeryOptions so;
  so.ring_pull = o.ring_pull;
  so.cap_rings = o.method == "paper" && o.ring_pull == 0 ? 1 : so.cap_rings;
  so.trial = attempt == CapAttempt::kTrial || attempt == CapAttempt::kPlainTrial;
  so.probe_concentric = attempt == CapAttempt::kFirst;
  so.restricted = attempt != CapAttempt::kPlainTrial;
  so.triangulated = attempt != CapAttempt::kAgain;
  so.front = o.front_caps;
  so.mincut = o.mincut_caps && attempt == CapAttempt::kAgain;  // a loop's last cut only
  so.mincut_cell = o.mincut_cell;
  so.mincut_widen = o.mincut_widen;
  so.run_both = on_helper(st.worker.get());
  if (o.check_caps) {
    if (!st.guard) st.guard = std::make_unique<FaceGrid>(st.mesh, kGuardCellEdges * st.mean_edge);
    so.guard = st.guard.get();
  }
  *out = cut_and_cap(st.mesh, loop, so, hb);
  st.loops.back().cap_intersections = out->intersections;
  st.left_caps_ahead += out->left_caps_ahead;
  st.extend_vertices(out->right_ring, out->left_ring, comp);
  st.cap_rings.push_back(out->left_ring);
  st.cap_rings.push_back(out->right_ring);
  st.t.surgery += sw.seconds();
  sw.restart();
  const bool connected = vertices_connected(st.mesh, out->left_cap, out->right_cap);
  st.t.verify += sw.seconds();
  return connected;
}

ExactGreedy::ExactGreedy(DenoiseState& st, const DenoiseOptions& o, double mean_edge)
    : st_(st), opts_(o), first_radius_(o.initial_radius > 0 ? o.initial_radius : 10.0 * mean_edge) {
  worker_ = st.worker.get();  // null with one thread
  debug_cpu_ = process_cpu_seconds();
  want_type_ = o.policy != "shortest";
  wanted_ = o.policy == "cut" ? LoopType::kHandle : LoopType::kTunnel;
  accept_ = [this](const std::vector<Mesh::VertexHandle>& loop) { return classify_loop(st_.mesh, loop) == wanted_; };
}

// Crossing families need a closed surface (every class has a cycle avoiding boundary vertices)
// and the closed-walk minimum (policy shortest).
void ExactGreedy::update_crossing_wanted() {
  if (!closed_) closed_ = std::none_of(st_.mesh.vertices_begin(), st_.mesh.vertices_end(), [&](Mesh::VertexHandle v) {
                  return st_.mesh.is_boundary(v);
                }) ? 1 : -1;
  crossing_wanted_ = closed_ > 0 && !want_type_ && total_genus_left() == 1;
}

int ExactGreedy::total_genus_left() const { return std::accumulate(st_.genus_left.begin(), st_.genus_left.end(), 0); }

// Limit of the next search from a slot (lower bound m): without a known loop, twice m (at least
// the first radius, at least twice its previous own limit); once a loop of value U is known, 2U:
// the search ends at the first loop found (value/2 from the source), and when it has none up to
// 2U every source of its family within U/2 gets a bound >= U, so one search covers a stretch of
// sources instead of each searching to U itself. Never above --max-loop-length.
double ExactGreedy::search_limit(int slot) {
  const double m = slots_[slot].bound.value;
  double limit = std::max({first_radius_, 2.0 * m, 2.0 * slots_[slot].own_limit});
  const double best = best_known();
  if (std::isfinite(best) && best > m) limit = kBestFactor * best;
  limit = std::max(limit, 1.05 * m);
  return std::min(limit, opts_.max_loop_length);
}

CycleCandidate ExactGreedy::search_from(int slot, double limit) {
  Stopwatch sw;
  spec_ready_ = false;
  const int family = slots_[slot].family;
  search_->set_cochain(family == 0 ? nullptr : &families_[family].cochain);
  const int v = slots_[slot].vertex;
  const CycleCandidate c = search_->run(Mesh::VertexHandle(v), limit, want_type_ ? &accept_ : nullptr);
  ++searches_;
  settled_ += static_cast<long long>(search_->last_settled());
  settled_alone_ += static_cast<long long>(search_->last_settled());
  largest_limit_ = std::max(largest_limit_, limit);
  slots_[slot].own_limit = limit;
  const double own = c.found ? c.value : c.truncated ? limit : kInf;
  set_bound(slot, SourceBound{own, c.found, v, 0});
  if (!want_type_) {  // with a type filter F is no closed-walk minimum
    const std::vector<int>& ball = search_->last_settled_vertices();
    distances_.resize(ball.size());
    for (std::size_t i = 0; i < ball.size(); ++i) distances_[i] = search_->distance(ball[i]);
    spread_bounds(slot, own, ball, distances_);
  }
  if (crossing_ && families_.size() == 2 && c.found) add_transversal_family(c);  // Z
  st_.t.search += sw.seconds();
  return c;
}

bool ExactGreedy::stop_before(const QueueEntry& top, std::string* reason) const {
  const bool too_long = top.exact ? top.key > opts_.max_loop_length : top.key >= opts_.max_loop_length;
  if (too_long) *reason = "no loop shorter than --max-loop-length remains";
  return too_long;
}

// Invariant: every active slot is in the queue with its current bound (or dropped with F = inf),
// and the minimum over the queue of F is the shortest non-separating cycle of the current mesh.
std::string ExactGreedy::run(int needed, const DenoiseProgress& progress) {
  genus_at_build_ = total_genus_left();
  build_homology();
  update_crossing_wanted();
  int cuts = 0;
  while (cuts < needed) {
    if (queue_.empty() && crossing_ && families_.size() < 3) leave_crossing_mode();  // no Z: never on a closed surface
    if (queue_.empty())
      return want_type_ ? "no further " + std::string(opts_.policy == "cut" ? "handle" : "tunnel") + " loops found"
                        : "no further non-separating loops found";
    const QueueEntry top = queue_.top();
    queue_.pop();
    if (!slots_[top.slot].active || top.version != slots_[top.slot].bound.version) continue;
    std::string reason;
    if (stop_before(top, &reason)) return reason;
    if (!top.exact) {
      queue_.push(top);  // still pending; the order below does not change what is cut
      if (crossing_wanted_ && !crossing_ && std::isfinite(best_exact_value())) {
        enter_crossing_mode();
        continue;
      }
      const double best = best_known();
      const int far = want_type_ ? -1 : farthest_pending(best);
      const int s = far >= 0 ? far : top.slot;
      if (!want_type_ && std::isfinite(best)) search_group(s, best);
      else search_from(s, search_limit(s));
      continue;
    }
    // Exact and the smallest key: the global minimum if the value still holds on the current
    // mesh (surgery elsewhere can only have raised it). With crossing families, only once Z's
    // family exists (before, the top is the shortest cycle crossing A, which becomes Z).
    const CycleCandidate c = search_from(top.slot, top.key * (1 + 1e-12) + 1e-12);
    if (!c.found || c.value > top.key * (1 + 1e-12) + 1e-12) continue;  // re-queued with its new bound
    cut(top.slot, c, ++cuts);
    if (progress) progress(cuts, needed);
    if (cuts < needed && crossing_) leave_crossing_mode();
    if (cuts < needed) maybe_rebuild(cuts, total_genus_left());
    update_crossing_wanted();
  }
  return "target genus reached";
}

void ExactGreedy::cut(int slot, const CycleCandidate& c, int iteration) {
  spec_ready_ = false;
  set_bound(slot, SourceBound{0, false, -1, 0});  // searched again after the surgery
  last_cut_value_ = c.value;
  const std::vector<Mesh::VertexHandle> pick = search_->extract(c);
  std::vector<Mesh::VertexHandle> loop;  // the loop cut
  std::vector<std::uint64_t> cls = search_->cycle_class(pick);
  std::vector<std::uint64_t> reduced = cls;
  if (span_.reduce(reduced.data())) throw Error("denoise: internal error: a chosen loop's class was already cut");
  const int comp = st_.component[pick.front().idx()];
  const double surgery0 = st_.t.surgery;
  const bool wide = shortcut_gate(pick);
  SurgeryResult sr = cut_cleanly(pick, reduced, iteration, &cls, &loop);
  if (wide) sr = shortcut_first(sr, iteration, pick, &loop, &cls);  // may cut another loop instead
  if (denoise_debug()) debug_cut(iteration, st_.t.surgery - surgery0);
  if (shortcut_) shortcut_->block(shortcut_ids(loop));
  span_.insert(cls.data());  // the class of the loop cut (a same-class replacement: the same span)
  --st_.genus_left[comp];
  if (crossing_) return;  // back to the span family on the new mesh
  Stopwatch sw;
  lower_bounds_near(sr);
  add_surgery_sources(sr);
  st_.t.search += sw.seconds();
}

// COLONFLAT_DENOISE_DEBUG: one stderr line per cut (what the cut and the searches before it cost).
void ExactGreedy::debug_cut(int iteration, double surgery_s) {
  const LoopRecord& L = st_.loops.back();
  std::fprintf(stderr,
               "denoise debug: cut %d: %.1f mm, %zu vertices, %zu cap pairs%s; since the last cut: %.2f s (CPU %.2f s) "
               "(search %.2f s, %lld searches, %lld settled, %lld of them alone, busiest lanes of batches %lld; "
               "fallback searches %.2f s, %lld settled), surgery %.2f s; "
               "%zu sources, %d homology builds in all\n",
               iteration, L.length, L.vertex_ids.size(), L.cap_intersections,
               L.replaced_length > 0 ? " (replaced a loop)" : "", debug_clock_.seconds(), process_cpu_seconds() - debug_cpu_,
               st_.t.search - debug_search_,
               searches_ - debug_searches_, settled_ - debug_settled_, settled_alone_ - debug_alone_,
               settled_longest_lane_ - debug_longest_lane_, fallback_s_, fallback_settled_, surgery_s,
               active_.size(), builds_);
  fallback_s_ = 0;
  fallback_settled_ = 0;
  debug_clock_.restart();
  debug_cpu_ = process_cpu_seconds();
  debug_search_ = st_.t.search;
  debug_searches_ = searches_;
  debug_settled_ = settled_;
  debug_alone_ = settled_alone_;
  debug_longest_lane_ = settled_longest_lane_;
}

void ExactGreedy::write_stats(nlohmann::json& stats) const {
  stats["searches"] = searches_;
  stats["settled_vertices"] = settled_;
  stats["bounds_spread"] = bounds_spread_;
  stats["farthest_first_searches"] = far_searches_;
  stats["group_searches"] = group_searches_;
  stats["group_members"] = group_members_;
  stats["group_exact_bounds"] = group_exact_;
  stats["parallel_search_pairs"] = parallel_pairs_;
  stats["batches_of_two_families"] = mixed_batches_;
  stats["settled_vertices_alone"] = settled_alone_;
  stats["bounds_lowered_after_surgery"] = bounds_reset_;
  stats["homology_builds"] = builds_;
  stats["homology_builds_pruned_beside"] = homology_.builds_on_two_threads();
  stats["bounds_carried_at_rebuild"] = bounds_carried_;
  stats["crossing_family_switches"] = crossing_modes_;
  stats["crossing_searches_to_z"] = crossing_searches_to_z_;
  stats["z_reroute_settled"] = reroute_settled_;
  stats["z_reroutes_found"] = reroutes_found_;
  stats["left_caps_triangulated_ahead"] = st_.left_caps_ahead;
  stats["loops_replaced_for_clean_caps"] = alternatives_ + crossing_alternatives_;
  stats["loops_replaced_by_crossing_loop"] = crossing_alternatives_;
  stats["first_search_radius_mm"] = first_radius_;
  stats["largest_search_limit_mm"] = largest_limit_;
  stats["sources_last"] = active_.size();
  stats["shortcut_tests"] = shortcut_tests_;
  stats["shortcut_loops_replaced"] = shortcut_replaced_;
  stats["shortcut_seconds"] = shortcut_s_;
  stats["group_searches_ahead"] = spec_runs_;
  stats["group_searches_ahead_taken"] = spec_hits_;
  stats["schedule"] = "per-source limits, bounds shared within each search ball; crossing families at genus 1";
}

std::string run_exact(DenoiseState& st, const DenoiseOptions& o, int needed, const DenoiseProgress& progress,
                      double mean_edge, nlohmann::json& stats) {
  ExactGreedy greedy(st, o, mean_edge);
  const std::string reason = greedy.run(needed, progress);
  greedy.write_stats(stats);
  return reason;
}

}  // namespace cf::detail
