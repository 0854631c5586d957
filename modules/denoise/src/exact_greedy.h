#pragma once
// Internal to the denoise module: the greedy loop of the exact method (docs/denoise.md, "How it
// is fast"). Implemented in exact_method.cpp (the greedy steps) and exact_sources.cpp (sources,
// families and bounds).
#include <cstdint>
#include <memory>
#include <queue>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/loop_search.h"
#include "denoise_internal.h"
#include "exact_shortcut.h"
#include "search_worker.h"

namespace cf::detail {

// What is known of F(s) for one source slot (a vertex in one family): the shortest closed walk
// through the vertex in the family's cycles (the shortest fundamental cycle of its
// shortest-path tree in the family). exact: F == value, else F >= value.
struct SourceBound {
  double value = 0;
  bool exact = false;
  int centre = -1;  // vertex whose search gave it (-1: none, or lowered after a surgery)
  std::uint32_t version = 0;
};

struct QueueEntry {
  double key;
  int slot;
  std::uint32_t version;
  bool exact;
  // Min-heap order: smaller key first; at equal keys exact values before lower bounds.
  bool operator>(const QueueEntry& e) const { return key != e.key ? key > e.key : (!exact && e.exact); }
};

// A family of cycles searched from its own source set, which every cycle of the family meets.
//  - Span family (index 0, no cochain): classes outside the span of the cut classes; sources =
//    the pruned cut graph plus every ring and cap since.
//  - Crossing families (closed surface with total genus 1 left, policy shortest): once a loop A
//    is known, the cycles crossing A an odd number of times (sources: A's vertices), and, once
//    the first of those, Z, is found, the cycles crossing Z oddly (sources: Z's vertices). On a
//    genus-1 surface the classes are a = [A], z = [Z] and a + z, with a.z = 1: each crosses A
//    or Z oddly, so the minimum over both families is the shortest non-separating cycle. The
//    point: a long handle's loop is short only in Z's family, whose sources cross it, and A's
//    family holds the cycles through the handle, which are long, so one search certifies a
//    long stretch of A; the pruned cut graph may instead run along the long loop, where every
//    source needs its own search to the loop's length.
struct Family {
  std::vector<std::uint8_t> cochain;  // crossing_cochain() of the family's loop; empty: span family
  std::vector<int> slot_of;           // vertex -> slot, -1 if not a source of this family
};

struct Slot {
  int vertex = -1;
  int family = 0;
  bool active = false;
  SourceBound bound;
  double own_limit = 0;  // limit of its last own search (the next one at least doubles it)
  double group_radius = -1;  // mm: radius of the next group search around it (-1: the default)
};

class ExactGreedy {
 public:
  ExactGreedy(DenoiseState& st, const DenoiseOptions& o, double mean_edge);
  std::string run(int needed, const DenoiseProgress& progress);
  void write_stats(nlohmann::json& stats) const;

 private:
  // exact_sources.cpp
  void build_homology();
  void carry_bounds(const std::vector<std::pair<int, SourceBound>>& old);
  void deactivate_all_slots();
  void maybe_rebuild(int cuts, int total_genus);
  void enter_crossing_mode();
  void add_crossing_family(const std::vector<Mesh::VertexHandle>& loop);
  void add_transversal_family(const CycleCandidate& shortest);
  void leave_crossing_mode();
  void add_source(int family, int v);
  void set_bound(int slot, const SourceBound& b);
  double best_exact_value();
  double best_known(int* anchor = nullptr);
  int farthest_pending(double best);
  std::vector<int> ball_targets(int anchor, double best) const;
  void spread_bounds(int centre_slot, double bound, const std::vector<int>& ball, const std::vector<double>& distance);
  void add_surgery_sources(const SurgeryResult& sr);
  void lower_bounds_near(const SurgeryResult& sr);
  // exact_groups.cpp
  struct GroupRun {
    int seed = -1;
    double radius = 0, limit = 0;
    std::vector<int> members, roots, root_parent;  // slots; their vertices; tree halfedges
    CycleCandidate result;
    // What finish_group() needs of the search, kept so that the search object can run the next
    // group of a batch: the vertices it settled, the family's sources among them with their
    // distances from the group, and the roots whose trees hold the cycle's two ends.
    std::size_t settled = 0;
    std::vector<int> ball;
    std::vector<double> ball_distance;
    int root_u = -1, root_v = -1;
  };
  std::vector<int> collect_group(int seed, double best, double radius, std::uint32_t taken,
                                 std::vector<int>* root_parent);
  GroupRun prepare_group(int seed, double best, std::uint32_t taken);
  void search_group(int seed, double best);
  std::size_t batch_size() const;
  void run_group(GroupRun& g, FundamentalCycleSearch& search) const;
  void run_groups(std::vector<GroupRun>& runs);
  // Threads for `tasks` independent searches: min(worker threads, tasks), 1 without a worker;
  // makes the search objects lanes 1.. use. lane_search(t): lane t's (lane 0: search_).
  int search_lanes(std::size_t tasks);
  FundamentalCycleSearch& lane_search(int t) { return t == 0 ? *search_ : *searches_extra_[std::size_t(t) - 1]; }
  void finish_group(const GroupRun& g, double best);
  int next_seed(const std::vector<GroupRun>& batch, double best, std::uint32_t taken);
  bool near_group(int seed, const GroupRun& g) const;
  // exact_speculation.cpp: while a batch holds one group, the group the next batch will most
  // likely search is searched beside it on the helper thread, and taken only if the next batch
  // forms exactly that group (same seed, roots, tree, radius and limit on the same mesh): the same
  // searches and results as without it, for any thread count.
  bool can_speculate() const;
  GroupRun guess_next_group(const GroupRun& alone, double best);
  void run_alone_with_guess(GroupRun& alone, double best);
  bool take_speculation(GroupRun& g);
  GroupRun spec_;            // the group searched ahead, valid while spec_ready_
  bool spec_ready_ = false;  // cleared by every step that may change what the next batch forms
  long long spec_runs_ = 0, spec_hits_ = 0;
  static constexpr std::size_t kMaxSkipped = 64;  // far-first entries set aside per batch, at most
  static constexpr double kGroupRadius = 0.5;  // first group radius, times the best known loop
  // Groups are searched in batches of kBatchLanes lanes of about kBatchWork settled vertices
  // each (from the last batch's mean), at most kMaxBatch groups per lane: one hand-over to a
  // thread costs about as much as a small search. The lanes are a fixed number, not the thread
  // count, so that the searches are the same for any thread count; the threads share the lanes'
  // groups. kBatchLanes = 2: the batches the former `--threads 2` formed (measured in sessions
  // 6-8: same loops, no loss on the 300-handle sphere), now formed for any thread count; up to
  // 16 groups per batch when the groups are small.
  static constexpr std::size_t kBatchWork = 2000;
  static constexpr std::size_t kMaxBatch = 8;
  static constexpr std::size_t kBatchLanes = 2;
  // exact_fallback.cpp
  SurgeryResult cut_cleanly(const std::vector<Mesh::VertexHandle>& loop, const std::vector<std::uint64_t>& reduced,
                            int iteration, std::vector<std::uint64_t>* cut_class,
                            std::vector<Mesh::VertexHandle>* cut_loop = nullptr);
  std::vector<Mesh::VertexHandle> crossing_loop(const std::vector<Mesh::VertexHandle>& loop, double limit);
  std::vector<Mesh::VertexHandle> shortest_from_spread(const std::vector<Mesh::VertexHandle>& sources, double limit,
                                                       const FundamentalCycleSearch::Accept* accept,
                                                       const std::vector<std::uint8_t>* cochain,
                                                       const std::vector<std::uint8_t>* avoid,
                                                       std::size_t max_sources = kFallbackSources);
  SurgeryResult cut_recorded(const std::vector<Mesh::VertexHandle>& loop, int iteration,
                             CapAttempt attempt = CapAttempt::kFull);
  void revert_cut(const SurgeryResult& sr);
  std::vector<Mesh::VertexHandle> same_class_loop(const std::vector<Mesh::VertexHandle>& loop,
                                                  const std::vector<std::uint64_t>& reduced, double tube);
  static constexpr std::size_t kFallbackSources = 24;
  // Tube radii of the same-class fallback tried first, in mean edge lengths (issue 26, session
  // 16): a loop round a window in a thin wall zigzags between the wall's two faces along the rim
  // and every disk of it passes through the rim; the wall it crosses lies within 0-3 mm (about
  // 4 edges) of the loop. A loop of the same class outside a tube of 2, then 4 edges runs on one
  // face a ring or two off the rim (or round a slit, beside earlier caps lying across it), and
  // its caps rise from that face. The tubes of L/8 and L/4 come after them.
  static constexpr double kNearTubeEdges[] = {2.0, 4.0};
  static constexpr double kRerouteFactor = 2.0;  // Z's reroute searched to 2 |Z| (docs/denoise.md)
  static constexpr double kBestFactor = 2.0;  // search limit once a loop of value U is known: 2U (4U measured worse)
  // exact_shortcut.cpp ("shortcut first", exact_shortcut.h)
  bool shortcut_gate(const std::vector<Mesh::VertexHandle>& pick);
  SurgeryResult shortcut_first(const SurgeryResult& done, int iteration, const std::vector<Mesh::VertexHandle>& pick,
                               std::vector<Mesh::VertexHandle>* loop, std::vector<std::uint64_t>* cut_class);
  std::vector<Mesh::VertexHandle> across_path(const ShortcutTest& t, double length);
  std::vector<Mesh::VertexHandle> loop_across(const std::vector<Mesh::VertexHandle>& path, double limit, double spacing);
  std::vector<int> shortcut_ids(const std::vector<Mesh::VertexHandle>& loop) const;
  bool lengthens(const ShortcutTest& t) const;
  bool keeps_shortcut(const std::vector<Mesh::VertexHandle>& loop);  // its cut lengthens d
  // Sources of loop_across() along the path every this many times the pick's length: the loop
  // found through the nearest source is at most that much longer than the loop across (an eighth:
  // ~11 mm for a 90 mm girth), and the path of a grown real mask (1-2 m) gets ~100-200 sources.
  static constexpr double kShortcutSpacing = 0.125;
  std::unique_ptr<ShortcutPaths> shortcut_;  // built at the first wide handle pick
  // The loop being cut replaces a wide pick: a loop cut_cleanly() tries instead of it (caps) must
  // lengthen d as well (the same class modulo the cuts holds the bypassed girth).
  bool shortcut_guard_ = false;
  int shortcut_tests_ = 0, shortcut_replaced_ = 0;
  double shortcut_s_ = 0;
  // exact_method.cpp
  double search_limit(int slot);
  CycleCandidate search_from(int slot, double limit);
  bool stop_before(const QueueEntry& top, std::string* reason) const;
  void cut(int slot, const CycleCandidate& c, int iteration);
  int total_genus_left() const;
  void update_crossing_wanted();
  void debug_cut(int iteration, double surgery_s);

  DenoiseState& st_;
  const DenoiseOptions& opts_;
  const double first_radius_;  // mm: limit of a source's first search
  bool want_type_ = false;
  LoopType wanted_ = LoopType::kHandle;
  FundamentalCycleSearch::Accept accept_;
  HomologyBasis homology_;
  Z2Span span_;
  // The searches' walks read the mesh's adjacency from here (built with search_, refreshed by
  // cut_recorded() and revert_cut(), the only changes of the mesh while searches exist).
  VertexAdjacency adjacency_;
  std::unique_ptr<FundamentalCycleSearch> search_;
  std::vector<std::unique_ptr<FundamentalCycleSearch>> searches_extra_;  // helper thread t's is [t - 1]
  SearchWorker* worker_ = nullptr;  // DenoiseState::worker (null with one thread)
  std::size_t last_group_settled_ = 0;  // mean settled vertices per group search of the last batch
  bool crossing_wanted_ = false;  // closed, total genus 1, policy shortest: use crossing families
  int closed_ = 0;               // mesh without boundary: 1, with: -1, unknown: 0
  bool crossing_ = false;         // crossing families in use (span family inactive)
  std::vector<Mesh::VertexHandle> loop_a_;  // A
  double loop_a_value_ = 0;
  std::vector<double> carried_;   // per vertex: lower bound of F(v) when the span family was left
  std::vector<Family> families_;
  std::vector<Slot> slots_;
  std::vector<int> active_;  // active slots (may hold deactivated ones until the next build)
  std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>> queue_;
  std::priority_queue<QueueEntry, std::vector<QueueEntry>, std::greater<QueueEntry>> exact_queue_;
  long long searches_ = 0, settled_ = 0, bounds_spread_ = 0, bounds_reset_ = 0;
  int builds_ = 0, crossing_modes_ = 0, cuts_at_build_ = 0, genus_at_build_ = 0;
  // Searches from entering the crossing families to finding Z (the largest over the switches).
  long long searches_at_crossing_ = 0, crossing_searches_to_z_ = 0;
  long long reroute_settled_ = 0, reroutes_found_ = 0;  // Z's reroute searches (add_transversal_family)
  // Sources to certify against the best known loop, farthest from its source first.
  int far_anchor_ = -1;  // vertex the far-first order was measured from (-1: none)
  double far_value_ = 0;
  std::vector<std::pair<double, int>> far_order_;  // (distance from the anchor, slot), a max-heap
  std::vector<double> distances_;  // scratch: distances of the last single search's settled vertices
  std::vector<std::pair<double, int>> far_skipped_;  // popped while forming a batch, pushed back after it
  double far_popped_distance_ = 0;                  // key of the entry farthest_pending() returned last
  std::vector<double> from_anchor_;                // per vertex: scratch for farthest_pending(), +inf between calls
  long long far_searches_ = 0;
  long long group_searches_ = 0, group_members_ = 0, group_exact_ = 0, parallel_pairs_ = 0;
  long long mixed_batches_ = 0;  // batches holding groups of two crossing families
  std::vector<std::uint32_t> group_mark_;  // per vertex: group_stamp_ when in the group being collected
  std::uint32_t group_stamp_ = 0;
  int alternatives_ = 0;           // loops replaced by another of the same class (caps)
  int crossing_alternatives_ = 0;  // loops replaced by a loop crossing them (the handle's other loop)
  long long settled_at_build_ = 0;
  // A rebuild once the searches since the last build settled this many times the vertex count
  // (about two builds' worth of CPU: a build costs about as much as settling 1.3 n vertices;
  // counted in work, not seconds, so that the result does not depend on the machine's load).
  static constexpr double kRebuildWork = 2.5;
  // ... and per cut since the last build at least this many times the vertex count (a quarter
  // of a build's cost: below it the searches are local and a fresh cut graph does not help).
  static constexpr double kRebuildWorkPerCut = 0.25;
  // A late rebuild once the genus left is at most the genus at the last build over this: the cut
  // graph then has at least 4 times the loops the surface still needs (2g each), spread over the
  // whole surface, each of whose sources must be certified against every long loop to come; a
  // build costs about 1.3 vertex counts of settling. Real CT (genus 91, 1.07 M vertices): builds
  // at genus 91, 22, 5, 2 (the last by the work rule); 19.2 M settled vertices, 28.4 M without.
  static constexpr double kLateRebuildRatio = 4.0;
  double largest_limit_ = 0;
  double last_cut_value_ = 0;  // mm: the last loop cut (its certified value)
  long long bounds_carried_ = 0;
  // Levels of carry_bounds(): the last loop's length times kCarryStep^k, k < kCarryLevels.
  static constexpr int kCarryLevels = 4;
  static constexpr double kCarryStep = 1.5;
  Stopwatch debug_clock_;  // COLONFLAT_DENOISE_DEBUG: since the last cut
  double debug_search_ = 0, fallback_s_ = 0, debug_cpu_ = 0;
  long long debug_searches_ = 0, debug_settled_ = 0, fallback_settled_ = 0;
  // Settled vertices of searches that ran with no other beside them (search_from(), batches of
  // one group): the work a second thread cannot share today.
  long long settled_alone_ = 0, debug_alone_ = 0;
  // Per batch searched on more than one thread: the settled vertices of its busiest lane.
  long long settled_longest_lane_ = 0, debug_longest_lane_ = 0;
};

}  // namespace cf::detail
