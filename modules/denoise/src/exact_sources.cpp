// The exact method's source sets, search families and per-source bounds (exact_greedy.h).
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <unordered_map>

#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticPointLocator.h>

#include "colonflat/core/geodesic_ball.h"
#include "colonflat/core/run_stats.h"
#include "exact_greedy.h"

namespace cf::detail {

// Homology of the current mesh and its pruned cut graph as the span family's sources (every
// non-separating cycle meets it). Bounds of sources that stay are kept: F(s) is the same
// quantity whatever the annotations.
void ExactGreedy::build_homology() {
  Stopwatch sw;
  spec_ready_ = false;
  std::vector<std::pair<int, SourceBound>> old;  // (vertex, bound) of the span family's active sources
  for (int s : active_)
    if (slots_[s].active && slots_[s].family == 0) old.push_back({slots_[s].vertex, slots_[s].bound});
  if (st_.initial_homology) {  // built by prepare_input() while the input was analysed
    homology_ = std::move(*st_.initial_homology);
    st_.initial_homology.reset();
  } else {
    homology_.build(st_.mesh, on_helper(worker_));  // the cut graph's pruning on the helper beside the annotations
  }
  span_.reset(homology_.words());
  // The searches keep their per-vertex arrays (a fresh one page-faults 40 MB at 1.6 M vertices);
  // set_cochain(nullptr) takes the new class width.
  if (!search_) {
    adjacency_.build(st_.mesh, on_helper(worker_));  // the second half of the lists on the helper
    search_ = std::make_unique<FundamentalCycleSearch>(st_.mesh, homology_, span_);
    search_->set_adjacency(&adjacency_);
  }
  search_->set_cochain(nullptr);
  for (auto& s : searches_extra_) s->set_cochain(nullptr);
  deactivate_all_slots();
  queue_ = {};
  exact_queue_ = {};
  far_anchor_ = -1;
  families_.resize(1);
  for (int v : homology_.pruned_cut_graph_vertices()) add_source(0, v);
  const std::unordered_map<int, SourceBound> kept(old.begin(), old.end());  // vertex -> bound
  for (int s : active_) {
    const auto it = kept.find(slots_[s].vertex);
    set_bound(s, it == kept.end() ? SourceBound{} : it->second);
  }
  carry_bounds(old);
  st_.t.homology += sw.seconds();
  settled_at_build_ = settled_;
  ++builds_;
}

// Bounds of the new cut graph's sources from the old source set's (issue 26): every cycle of the
// span family meets the old sources, so a cycle through t of length F(t) < B passes through an
// old source s with bound(s) <= F(s) <= F(t) < B, at most F(t)/2 from t along the surface, so
// at least that far in space. Hence, for any B, F(t) >= min(B, 2 |t - {old s: bound(s) < B}|).
// Taken at the levels B = L r^k, k < kCarryLevels (L: the last loop cut; bounds below it spare
// no search, as the next loops are about as long), the largest kept. Without it every new source
// starts at 0 and needs its own searches up to the next loop's length, wherever it lies.
void ExactGreedy::carry_bounds(const std::vector<std::pair<int, SourceBound>>& old) {
  if (old.empty() || !(last_cut_value_ > 0)) return;
  std::vector<double> carried(active_.size(), 0.0);  // per active_ entry: the largest level value
  for (int k = 0; k < kCarryLevels; ++k) {
    const double level = last_cut_value_ * std::pow(kCarryStep, k);
    vtkNew<vtkPoints> below;  // old sources whose bound may be under the level
    below->SetDataTypeToDouble();
    for (const auto& [v, b] : old)
      if (b.value < level) below->InsertNextPoint(st_.mesh.point(Mesh::VertexHandle(v)).data());
    if (below->GetNumberOfPoints() == 0) {
      std::fill(carried.begin(), carried.end(), level);
      continue;
    }
    vtkNew<vtkPolyData> cloud;
    cloud->SetPoints(below);
    vtkNew<vtkStaticPointLocator> locator;
    locator->SetDataSet(cloud);
    locator->BuildLocator();
    for (std::size_t i = 0; i < active_.size(); ++i) {
      const Vec3& p = st_.mesh.point(Mesh::VertexHandle(slots_[active_[i]].vertex));
      double q[3];
      below->GetPoint(locator->FindClosestPoint(p.data()), q);
      carried[i] = std::max(carried[i], std::min(level, 2.0 * (p - Vec3(q[0], q[1], q[2])).norm()));
    }
  }
  for (std::size_t i = 0; i < active_.size(); ++i)
    if (carried[i] > slots_[active_[i]].bound.value) {
      set_bound(active_[i], SourceBound{carried[i], false, -1, 0});
      ++bounds_carried_;
    }
}

// Every slot leaves the source set; those not added again lose their bound (it would no
// longer be maintained across surgeries).
void ExactGreedy::deactivate_all_slots() {
  for (int s : active_) slots_[s].active = false;
  for (Slot& slot : slots_) {
    slot.bound = SourceBound{0, false, -1, slot.bound.version + 1};
    slot.own_limit = 0;
    slot.group_radius = -1;
  }
  active_.clear();
}

// A fresh cut graph of the lower-genus mesh is much smaller than the old one plus every ring,
// and searches start only from it; rebuilt once half the genus is gone, if searching has cost
// more than two builds since the last one (measured in settled vertices, kRebuildWork) and
// each cut more than kRebuildWorkPerCut. Where each cut needs only local searches (many short
// handles), the fresh sources do not shorten them: the 300-handle sphere settled 7.48 M
// vertices with its rebuild (0.06 vertex counts per cut), 7.00 M without; colon-like surfaces
// (1.7 per cut, long loops) settle far fewer with it. Also rebuilt late, once the genus left is
// at most 1/kLateRebuildRatio of the genus at the last build, whatever the work so far (issue 26):
// the last handles of a colon are the long ones, and the old cut graph (2g loops over the whole
// surface) plus every ring must all be certified against each of them; the new cut graph's
// sources start from the old bounds (carry_bounds()), not from 0.
void ExactGreedy::maybe_rebuild(int cuts, int total_genus) {
  // Not for the last handle: the crossing families start from the span family's bounds, which a
  // rebuild would drop (colon-like 60 mm contact: 29.9 M settled vertices with, 16.7 M without).
  if (total_genus < 2) return;
  const bool late = kLateRebuildRatio * total_genus <= genus_at_build_;
  const double work = double(settled_ - settled_at_build_) / double(st_.mesh.n_vertices());  // in vertex counts
  const bool costly = cuts - cuts_at_build_ >= std::max(1, genus_at_build_ / 2) && work >= kRebuildWork &&
                      work >= kRebuildWorkPerCut * (cuts - cuts_at_build_);
  if (!late && !costly) return;
  build_homology();
  cuts_at_build_ = cuts;
  genus_at_build_ = total_genus;
}

// Switches from the span family to the crossing families once a loop A is known (the best exact
// entry, re-searched to extract it), and again whenever a shorter loop turns up (a shorter A
// has fewer sources whose cycles can be as short as the loop to cut). The span family's bounds
// carry over: a crossing family's cycles are non-separating, so its F(v) >= the span family's.
void ExactGreedy::enter_crossing_mode() {
  const int anchor = exact_queue_.top().slot;
  const double value = exact_queue_.top().key;
  const CycleCandidate c = search_from(anchor, value * (1 + 1e-12) + 1e-12);
  searches_at_crossing_ = searches_;
  if (!c.found) return;  // re-queued with its new bound; tried again with the next best
  const std::vector<Mesh::VertexHandle> loop = search_->extract(c);
  if (!crossing_) {
    carried_.assign(st_.mesh.n_vertices(), 0);
    for (int s : active_)
      if (slots_[s].active) carried_[slots_[s].vertex] = slots_[s].bound.value;
  }
  spec_ready_ = false;
  deactivate_all_slots();
  queue_ = {};
  exact_queue_ = {};
  far_anchor_ = -1;
  families_.resize(1);
  crossing_ = true;
  ++crossing_modes_;
  loop_a_ = loop;
  loop_a_value_ = c.value;
  add_crossing_family(loop);
}

// Z from the shortest cycle crossing A (source s on A), rerouted to stay at least delta away from
// A except within 2 delta of s: Z's sources near A (where the bounds are tight, each needing its
// own search) are then only the few near s, not a stretch along A. Falls back to the shortest
// crossing cycle itself when no such route exists. The reroute is searched to kRerouteFactor
// times Z's length only (a ball of radius Z around s): a longer route would bring more sources
// of its own than the stretch near A it spares (real CT, last handle: no route within 4 Z + 4 delta,
// 0.31 M vertices settled for nothing; docs/denoise.md).
void ExactGreedy::add_transversal_family(const CycleCandidate& shortest) {
  std::vector<Mesh::VertexHandle> z = search_->extract(shortest);
  crossing_searches_to_z_ = std::max(crossing_searches_to_z_, searches_ - searches_at_crossing_);
  // The cycle's own root (a group search's first root need not lie on it).
  const auto source = Mesh::VertexHandle(search_->root_of(shortest.u.idx()));
  const double delta = std::max(5.0 * st_.mean_edge, loop_a_value_ / 16.0);
  std::vector<std::uint8_t> avoid(st_.mesh.n_vertices(), 0);
  for (int v : vertices_within(st_.mesh, loop_a_, delta)) avoid[v] = 1;
  for (int v : vertices_within(st_.mesh, {source}, 2.0 * delta)) avoid[v] = 0;
  search_->set_avoid(&avoid);
  const CycleCandidate rerouted = search_->run(source, kRerouteFactor * shortest.value);
  ++searches_;
  const auto settled = static_cast<long long>(search_->last_settled());
  settled_ += settled;
  settled_alone_ += settled;  // one search on the calling thread
  reroute_settled_ += settled;
  if (rerouted.found) z = search_->extract(rerouted);
  reroutes_found_ += rerouted.found ? 1 : 0;
  search_->set_avoid(nullptr);
  add_crossing_family(z);
}

// A family of the cycles crossing `loop` oddly, with the loop's vertices as sources.
void ExactGreedy::add_crossing_family(const std::vector<Mesh::VertexHandle>& loop) {
  const int family = static_cast<int>(families_.size());
  families_.emplace_back();
  far_anchor_ = -1;  // the far-first order is formed again with the new family's sources
  families_.back().cochain = crossing_cochain(st_.mesh, loop);
  for (auto v : loop) {
    add_source(family, v.idx());
    const int s = families_[family].slot_of[v.idx()];
    if (s >= 0 && carried_[v.idx()] > slots_[s].bound.value) set_bound(s, SourceBound{carried_[v.idx()], false, -1, 0});
  }
}

// Back to the span family on a fresh homology (after a cut, or if no crossing cycle exists).
void ExactGreedy::leave_crossing_mode() {
  spec_ready_ = false;
  crossing_ = false;
  search_->set_cochain(nullptr);
  deactivate_all_slots();
  families_.resize(1);
  build_homology();
}

void ExactGreedy::add_source(int family, int v) {
  Family& fam = families_[family];
  if (fam.slot_of.size() < st_.mesh.n_vertices()) fam.slot_of.resize(st_.mesh.n_vertices(), -1);
  if (st_.mesh.is_boundary(Mesh::VertexHandle(v))) return;
  int& s = fam.slot_of[v];
  if (s < 0) {
    s = static_cast<int>(slots_.size());
    slots_.emplace_back();
    slots_.back().vertex = v;
    slots_.back().family = family;
  }
  Slot& slot = slots_[s];
  if (slot.active) return;
  slot.active = true;
  active_.push_back(s);
  set_bound(s, slot.bound);
}

void ExactGreedy::set_bound(int s, const SourceBound& b) {
  Slot& slot = slots_[s];
  const std::uint32_t version = slot.bound.version + 1;
  slot.bound = b;
  slot.bound.version = version;
  if (!slot.active || !std::isfinite(b.value)) return;  // inf: no cycle of the family through it
  queue_.push({b.value, s, version, b.exact});
  if (b.exact) exact_queue_.push({b.value, s, version, true});
}

// The smallest exact value still queued (an upper bound of the shortest loop), or inf.
double ExactGreedy::best_exact_value() {
  while (!exact_queue_.empty()) {
    const QueueEntry& e = exact_queue_.top();
    const Slot& slot = slots_[e.slot];
    if (slot.active && e.version == slot.bound.version) return e.key;
    exact_queue_.pop();
  }
  return kInf;
}

// An upper bound of the shortest loop still to cut: the smallest exact value queued and, with
// crossing families, loop A's length (A is a non-separating cycle of the current mesh, though no
// family holds it until Z's exists); inf if neither. *anchor (optional) receives the vertex
// the far-first order is measured from: the exact entry's source, else A's first vertex.
// Without A's length the crossing families start with no known loop: every source of A's family
// searched alone with doubling limits (first radius 10 mean edges) until one finds Z (real CT
// surface, last handle: about 180 searches, 0.7 M settled vertices).
double ExactGreedy::best_known(int* anchor) {
  const double exact = best_exact_value();
  const bool a_better = crossing_ && !loop_a_.empty() && loop_a_value_ < exact;
  if (anchor) *anchor = a_better ? loop_a_.front().idx() : std::isfinite(exact) ? slots_[exact_queue_.top().slot].vertex : -1;
  return a_better ? loop_a_value_ : exact;
}

// The pending sources of far_order_ that may lie within graph distance `best` of the anchor: a
// graph path is never shorter than the straight segment, so a source farther than `best` in space
// (with a margin for the rounding of the path's sum) is outside the ball and keeps +inf. The ball
// then stops at the farthest of these instead of settling every vertex within `best` (real CT,
// issue 26 session 23: 132 balls of 1.96 M vertices in all, of which 105 had every source near
// in space within the ball; their 1.32 M vertices needed 0.18 M).
std::vector<int> ExactGreedy::ball_targets(int anchor, double best) const {
  const Vec3& a = st_.mesh.point(Mesh::VertexHandle(anchor));
  const double reach = best * (1.0 + 1e-9) + 1e-12;
  std::vector<int> targets;
  for (const auto& entry : far_order_) {
    const int v = slots_[entry.second].vertex;
    if ((st_.mesh.point(Mesh::VertexHandle(v)) - a).sqrnorm() <= reach * reach) targets.push_back(v);
  }
  return targets;
}

// While sources with a bound below the best known loop (value U, source u) remain, any order of
// searching them keeps the result exact. Farthest from u first: a source at distance D from the
// loop finds a walk of about U + 2D and then covers every source within D of it, so far sources
// certify the near ones, which could otherwise only search to U each. Returns -1 when the plain
// smallest-bound order should be used.
int ExactGreedy::farthest_pending(double best) {
  int anchor = -1;
  best_known(&anchor);
  if (!std::isfinite(best) || anchor < 0) return -1;
  if (anchor != far_anchor_ || best != far_value_) {
    far_anchor_ = anchor;
    far_value_ = best;
    far_order_.clear();
    for (int s : active_) {
      const Slot& slot = slots_[s];
      if (slot.active && slot.bound.value < best && !slot.bound.exact) far_order_.push_back({kInf, s});
    }
    std::vector<double> dist;
    const std::vector<int> near =
        vertices_within_until(st_.mesh, {Mesh::VertexHandle(anchor)}, best, ball_targets(anchor, best), &dist);
    // Distances from the anchor in a per-vertex table kept at +inf between calls (only the
    // ball's entries are set and reset: no mesh-sized array per call).
    if (from_anchor_.size() < st_.mesh.n_vertices()) from_anchor_.resize(st_.mesh.n_vertices(), kInf);
    for (std::size_t i = 0; i < near.size(); ++i) from_anchor_[near[i]] = dist[i];
    for (auto& entry : far_order_) entry.first = from_anchor_[slots_[entry.second].vertex];
    for (int v : near) from_anchor_[v] = kInf;
    std::make_heap(far_order_.begin(), far_order_.end());
  }
  while (!far_order_.empty()) {
    std::pop_heap(far_order_.begin(), far_order_.end());
    const int s = far_order_.back().second;
    far_popped_distance_ = far_order_.back().first;
    far_order_.pop_back();
    const Slot& slot = slots_[s];
    if (!slot.active || slot.bound.exact || !(slot.bound.value < best)) continue;  // done meanwhile
    ++far_searches_;
    return s;
  }
  return -1;
}

// F(t) >= F(c) - 2 d(c, t) for every source t of c's family in `ball` (settled vertices of the
// search from c, at distance[i] from it).
void ExactGreedy::spread_bounds(int centre_slot, double bound, const std::vector<int>& ball,
                                const std::vector<double>& distance) {
  const int centre = slots_[centre_slot].vertex;
  const Family& fam = families_[slots_[centre_slot].family];
  for (std::size_t i = 0; i < ball.size(); ++i) {
    const int t = ball[i];
    if (t == centre || t >= static_cast<int>(fam.slot_of.size()) || fam.slot_of[t] < 0) continue;
    const int s = fam.slot_of[t];
    if (!slots_[s].active) continue;
    const double lower = bound - 2.0 * distance[i];
    if (!(lower > slots_[s].bound.value)) continue;  // also keeps dropped sources (inf) dropped
    set_bound(s, SourceBound{lower, false, centre, 0});
    ++bounds_spread_;
  }
}

// Span mode: every non-separating cycle of the new mesh meets the old sources or the new rings
// and caps.
void ExactGreedy::add_surgery_sources(const SurgeryResult& sr) {
  for (auto v : sr.left_ring) add_source(0, v.idx());
  for (auto v : sr.right_ring) add_source(0, v.idx());
  add_source(0, sr.left_cap.idx());
  add_source(0, sr.right_cap.idx());
}

// After a surgery (span mode): a closed walk through t shorter than twice t's distance to the
// new rings never reaches them, so it is a walk of the old mesh with the same class (only the
// span grew): F_new(t) >= min(F_old bound, 2 d(t, rings)). Bounds are lowered to that, nothing
// more; sources farther than half their bound from the rings keep it.
void ExactGreedy::lower_bounds_near(const SurgeryResult& sr) {
  std::vector<Mesh::VertexHandle> seeds = sr.left_ring;
  seeds.insert(seeds.end(), sr.right_ring.begin(), sr.right_ring.end());
  double reach = 0;
  for (int s : active_)
    if (slots_[s].active && std::isfinite(slots_[s].bound.value)) reach = std::max(reach, 0.5 * slots_[s].bound.value);
  std::vector<double> dist;
  const std::vector<int> near = vertices_within(st_.mesh, seeds, reach, &dist);
  const std::vector<int>& slot_of = families_[0].slot_of;
  for (std::size_t i = 0; i < near.size(); ++i) {
    const int t = near[i];
    if (t >= static_cast<int>(slot_of.size()) || slot_of[t] < 0 || !slots_[slot_of[t]].active) continue;
    const double cap = 2.0 * dist[i];
    if (!(cap < slots_[slot_of[t]].bound.value)) continue;
    set_bound(slot_of[t], SourceBound{cap, false, -1, 0});
    ++bounds_reset_;
  }
}

}  // namespace cf::detail
