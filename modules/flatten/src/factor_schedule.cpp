// Rows of a sparse factor split over threads along the elimination tree (see factor_schedule.h).
#include "factor_schedule.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace cf::flat_detail {

std::vector<int> elimination_tree(int n, const int* colptr, const int* rowind) {
  std::vector<int> parent(std::size_t(n), -1), ancestor(std::size_t(n), -1);
  for (int k = 0; k < n; ++k)
    for (int p = colptr[k]; p < colptr[k + 1]; ++p)
      for (int i = rowind[p]; i >= 0 && i < k;) {  // climb from i to its root, compressing the path to k
        const int next = ancestor[std::size_t(i)];
        ancestor[std::size_t(i)] = k;
        if (next < 0) {
          parent[std::size_t(i)] = k;
          break;
        }
        i = next;
      }
  return parent;
}

namespace {

// Calls update(k, j, held) for every entry L(k, j), j < k, of the factor of the upper triangle given
// (colptr, rowind) with elimination tree `parent`, rows k ascending: the up-looking kernel's update of
// row k with column j, which holds `held` entries below its diagonal at that point (rows j < i < k).
template <class Update>
void for_each_row_update(int n, const int* colptr, const int* rowind, const std::vector<int>& parent, Update update) {
  std::vector<int> mark(std::size_t(n), -1), held(std::size_t(n), 0);  // held: entries of column j so far
  for (int k = 0; k < n; ++k) {
    mark[std::size_t(k)] = k;
    for (int p = colptr[k]; p < colptr[k + 1]; ++p)
      for (int i = rowind[p]; i >= 0 && i < k && mark[std::size_t(i)] != k; i = parent[std::size_t(i)]) {
        mark[std::size_t(i)] = k;  // L(k, i) != 0
        update(k, i, held[std::size_t(i)]++);
      }
  }
}

}  // namespace

std::vector<double> row_work(int n, const int* colptr, const int* rowind, const std::vector<int>& parent) {
  std::vector<double> work(std::size_t(n), 1.0);  // the diagonal
  // an update with column j's entries so far, then one more
  for_each_row_update(n, colptr, rowind, parent, [&work](int k, int, int held) { work[std::size_t(k)] += 1.0 + held; });
  return work;
}

RestWork split_rest_work(int n, const int* colptr, const int* rowind, const std::vector<int>& parent,
                         const std::vector<int>& rest) {
  std::vector<char> in_rest(std::size_t(n), 0);
  for (int k : rest) in_rest[std::size_t(k)] = 1;
  RestWork out;
  out.own = double(rest.size());  // the diagonals
  for_each_row_update(n, colptr, rowind, parent, [&](int k, int j, int held) {
    if (in_rest[std::size_t(k)]) (in_rest[std::size_t(j)] ? out.own : out.from_parts) += 1.0 + held;
  });
  return out;
}

namespace {

// The elimination tree with child lists (ascending) and the work of every subtree.
struct Tree {
  std::vector<int> start, child, roots;  // children of k: child[start[k] .. start[k + 1])
  std::vector<double> subtree;
};

Tree build_tree(const std::vector<int>& parent, const std::vector<double>& work) {
  const std::size_t n = parent.size();
  Tree t;
  t.start.assign(n + 1, 0);
  for (std::size_t k = 0; k < n; ++k)
    if (parent[k] >= 0) ++t.start[std::size_t(parent[k]) + 1];
  for (std::size_t k = 0; k < n; ++k) t.start[k + 1] += t.start[k];
  t.child.resize(std::size_t(t.start[n]));
  std::vector<int> fill(t.start.begin(), t.start.end() - 1);
  t.subtree = work;
  for (std::size_t k = 0; k < n; ++k) {  // children come before their parent: k's subtree is complete here
    if (parent[k] < 0) {
      t.roots.push_back(int(k));
      continue;
    }
    const std::size_t p = std::size_t(parent[k]);
    t.child[std::size_t(fill[p]++)] = int(k);
    t.subtree[p] += t.subtree[k];
  }
  return t;
}

// Heaviest subtree first, ties by row index.
struct Heavier {
  const Tree* t;
  bool operator()(int a, int b) const {
    const double wa = t->subtree[std::size_t(a)], wb = t->subtree[std::size_t(b)];
    return wa != wb ? wa > wb : a < b;
  }
};

// The subtrees dealt largest first, each to the lightest part (ties: the lowest part); returns the
// largest part's work and, when asked, each subtree's part (in the order of `roots` sorted).
double deal(const Tree& t, std::vector<int>& roots, int parts, std::vector<int>* owner = nullptr) {
  std::sort(roots.begin(), roots.end(), Heavier{&t});
  using Load = std::pair<double, int>;
  std::priority_queue<Load, std::vector<Load>, std::greater<Load>> lightest;
  for (int p = 0; p < parts; ++p) lightest.push({0.0, p});
  double largest = 0;
  if (owner) owner->clear();
  for (int r : roots) {
    Load l = lightest.top();
    lightest.pop();
    l.first += t.subtree[std::size_t(r)];
    largest = std::max(largest, l.first);
    if (owner) owner->push_back(l.second);
    lightest.push(l);
  }
  return largest;
}

// Splitting stops when the heaviest subtree is below this share of one part's ideal work (the
// dealing is then within it of the best), after kMaxSplits splits, or with more than
// kMaxSubtreesPerPart subtrees per part (each step deals them all again).
constexpr double kFineEnough = 0.05;
constexpr int kMaxSplits = 20000, kMaxSubtreesPerPart = 64;

// The subtrees dealt and the rows moved to the rest after `splits` splits of the heaviest subtree.
struct Split {
  std::vector<int> heap, rest;  // heap: the subtrees (a max-heap by Heavier's order reversed)
  double rest_work = 0;
};

void split_heaviest(const Tree& t, const std::vector<double>& work, Split& s) {
  const auto lighter = [&t](int a, int b) { return Heavier{&t}(b, a); };
  std::pop_heap(s.heap.begin(), s.heap.end(), lighter);
  const int k = s.heap.back();
  s.heap.pop_back();
  s.rest.push_back(k);
  s.rest_work += work[std::size_t(k)];
  for (int c = t.start[std::size_t(k)]; c < t.start[std::size_t(k) + 1]; ++c) {
    s.heap.push_back(t.child[std::size_t(c)]);
    std::push_heap(s.heap.begin(), s.heap.end(), lighter);
  }
}

// How many splits give the smallest largest part + rest.
int best_split_count(const Tree& t, const std::vector<double>& work, double total, int parts) {
  const auto lighter = [&t](int a, int b) { return Heavier{&t}(b, a); };
  Split s{t.roots, {}, 0.0};
  std::make_heap(s.heap.begin(), s.heap.end(), lighter);
  double best = std::numeric_limits<double>::infinity();
  int best_count = 0;
  for (int count = 0;; ++count) {
    std::vector<int> roots = s.heap;
    const double makespan = deal(t, roots, parts) + s.rest_work;
    if (makespan < best) best = makespan, best_count = count;
    if (s.heap.empty() || count >= kMaxSplits || s.heap.size() > std::size_t(kMaxSubtreesPerPart * parts)) break;
    if (t.subtree[std::size_t(s.heap.front())] * parts < kFineEnough * total) break;
    split_heaviest(t, work, s);
  }
  return best_count;
}

}  // namespace

RowSchedule schedule_rows(const std::vector<int>& parent, const std::vector<double>& work, int parts) {
  RowSchedule out;
  parts = std::max(1, parts);
  const Tree t = build_tree(parent, work);
  for (double w : work) out.total_work += w;
  const int splits = best_split_count(t, work, out.total_work, parts);
  const auto lighter = [&t](int a, int b) { return Heavier{&t}(b, a); };
  Split s{t.roots, {}, 0.0};
  std::make_heap(s.heap.begin(), s.heap.end(), lighter);
  for (int i = 0; i < splits; ++i) split_heaviest(t, work, s);
  std::vector<int> roots = s.heap, owner;
  deal(t, roots, parts, &owner);
  out.parts.assign(std::size_t(parts), {});
  std::vector<double> part_work(std::size_t(parts), 0.0);
  for (std::size_t r = 0; r < roots.size(); ++r) {  // each subtree's rows into its part
    std::vector<int>& rows = out.parts[std::size_t(owner[r])];
    part_work[std::size_t(owner[r])] += t.subtree[std::size_t(roots[r])];
    std::vector<int> stack{roots[r]};
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      rows.push_back(k);
      for (int c = t.start[std::size_t(k)]; c < t.start[std::size_t(k) + 1]; ++c) stack.push_back(t.child[std::size_t(c)]);
    }
  }
  for (std::vector<int>& rows : out.parts) std::sort(rows.begin(), rows.end());
  out.rest = std::move(s.rest);
  std::sort(out.rest.begin(), out.rest.end());
  out.rest_work = s.rest_work;
  out.largest_part = *std::max_element(part_work.begin(), part_work.end());
  return out;
}

namespace {

// The rows of `rows` (ascending, closed under ancestors) as a tree of their own: each row's parent
// by its index in `rows`, -1 for a root.
std::vector<int> restricted_tree(const std::vector<int>& parent, const std::vector<int>& rows) {
  std::vector<int> sub(rows.size(), -1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int p = parent[std::size_t(rows[i])];
    if (p >= 0) sub[i] = int(std::lower_bound(rows.begin(), rows.end(), p) - rows.begin());
  }
  return sub;
}

}  // namespace

std::vector<RowSchedule> schedule_phases(const std::vector<int>& parent, const std::vector<double>& work, int parts) {
  std::vector<RowSchedule> phases{schedule_rows(parent, work, parts)};
  while (int(phases.size()) < kMaxPhases && !phases.back().rest.empty()) {
    const std::vector<int> rows = phases.back().rest;
    std::vector<double> sub_work(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) sub_work[i] = work[std::size_t(rows[i])];
    RowSchedule next = schedule_rows(restricted_tree(parent, rows), sub_work, parts);
    if (next.largest_part + next.rest_work > (1.0 - kPhaseMinGain) * next.total_work) break;
    for (std::vector<int>& part : next.parts)
      for (int& k : part) k = rows[std::size_t(k)];  // local -> global: ascending stays ascending
    for (int& k : next.rest) k = rows[std::size_t(k)];
    phases.back().rest.clear();
    phases.push_back(std::move(next));
  }
  return phases;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double thread_wait_seconds() {
  std::FILE* f = std::fopen("/proc/thread-self/schedstat", "r");
  if (!f) return 0.0;
  unsigned long long run = 0, wait = 0;
  const int got = std::fscanf(f, "%llu %llu", &run, &wait);
  std::fclose(f);
  return got == 2 ? 1e-9 * double(wait) : 0.0;
}

void print_factor_debug(int parts, int threads, std::size_t n, const std::vector<RowSchedule>& phases, const std::vector<double>& cpu,
                        double rest_cpu, double seconds, bool early, const FactorWall& wall, const RestWork& rest) {
  double largest = 0, longest = 0;
  for (const RowSchedule& phase : phases) largest += phase.largest_part / phases.front().total_work;
  for (std::size_t i = std::size_t(parts); i < cpu.size(); ++i) longest += cpu[i];
  std::fprintf(stderr, "flatten debug factorisation in %d parts on %d threads: %zu unknowns, %zu phases%s, largest parts %.3f, rest %.3f "
               "of the estimated work (%.3g); CPU s: parts %.2f / %.2f (longest per phase %.2f), rest %.2f; %.2f s (wall: transpose "
               "%.2f, numeric L %.2f, parts %.2f, rest %.2f, free %.2f; parts waited for a core %.2f / %.2f s); the rest's work: %.3f of "
               "the estimated work from the parts' columns, %.3f its own\n", parts, threads, n, phases.size(),
               early ? " (scheduled beside the analysis)" : "", largest, phases.back().rest_work / phases.front().total_work, phases.back().rest_work,
               cpu.size() > 0 ? cpu[0] : 0.0, cpu.size() > 1 ? cpu[1] : 0.0, longest, rest_cpu, seconds, wall.transpose,
               wall.numeric, wall.parts, wall.rest, wall.free,
               wall.wait.size() > 0 ? wall.wait[0] : 0.0, wall.wait.size() > 1 ? wall.wait[1] : 0.0,
               rest.from_parts / phases.front().total_work, rest.own / phases.front().total_work);
}

}  // namespace cf::flat_detail
