// Untangling a band's map: the faces a conformal map folds over (negative cotangent weights on
// obtuse triangles, slivers) are re-embedded with uniform (Tutte) weights on a region around them.
#include <algorithm>
#include <cmath>

#include "face_blocks.h"
#include "flatten_internal.h"

namespace cf::flat_detail {
namespace {

// The vertices of one untangling, the faces they touch, and which of them may move.
class Untangler {
 public:
  Untangler(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb, const std::vector<char>& fixed,
            const std::vector<char>& degenerate)
      : s_(s), vf_(vf), emb_(emb), fixed_(fixed), degenerate_(degenerate), in_(s.p.size(), 0) {}

  std::size_t run() {
    seed();
    if (region_.empty()) return 0;
    for (int round = 0; round < 4; ++round) {  // grow 0, 1, 2, 4 rings; the boundary stays
      for (int ring = 0; ring < (1 << round) && round > 0; ++ring) grow();
      const std::vector<char> free_vertex = movable(false);
      if (!solve(free_vertex, free_vertex)) return region_.size();
    }
    // Still folded: a fold that touches the boundary needs the boundary to give way. On the folds
    // and two rings around them (the vertices beyond hold the region in place), end-loop vertices
    // slide along their end (x kept, y free) and rim vertices of cut-off branches move.
    const std::size_t moved = region_.size();
    region_.clear();
    std::fill(in_.begin(), in_.end(), 0);
    seed();
    for (int ring = 0; ring < 2; ++ring) grow();
    solve(movable(true), movable_along_y());
    return moved;
  }

 private:
  bool folded(int f) const { return !degenerate_[f] && too_small_in_map(emb_.area2(s_, f), face_area_3d(s_, f)); }

  void add(int v) {
    if (!in_[v]) in_[v] = 1, region_.push_back(v);
  }

  // The vertices of the folded faces (in face order; which faces are folded is asked in blocks of
  // faces on the worker threads).
  void seed() {
    std::vector<char> fold(s_.t.size());
    for_each_block(s_.t.size(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t f = begin; f < end; ++f) fold[f] = folded(int(f));
    });
    for (std::size_t f = 0; f < s_.t.size(); ++f)
      if (fold[f])
        for (int v : s_.t[f]) add(v);
  }

  void grow() {
    const std::size_t n0 = region_.size();
    for (std::size_t k = 0; k < n0; ++k)
      for (int f : vf_[region_[k]])
        for (int v : s_.t[f]) add(v);
  }

  // x may move: interior vertices of the region, and with `rims` its boundary vertices that are
  // not on one of the band's two ends (the lines x = min and x = max of the boundary).
  std::vector<char> movable(bool rims) const {
    double x_lo = INFINITY, x_hi = -INFINITY;
    if (rims)
      for (std::size_t v = 0; v < s_.p.size(); ++v)
        if (fixed_[v]) x_lo = std::min(x_lo, emb_.pos[v].x()), x_hi = std::max(x_hi, emb_.pos[v].x());
    std::vector<char> free_vertex(s_.p.size(), 0);
    for (int v : region_) {
      const double x = emb_.pos[v].x();
      const bool on_end = x <= x_lo + 1e-9 * (x_hi - x_lo) || x >= x_hi - 1e-9 * (x_hi - x_lo);
      free_vertex[v] = !fixed_[v] || (rims && !on_end);
    }
    return free_vertex;
  }

  // y may move: every vertex of the region (ends slide along themselves).
  std::vector<char> movable_along_y() const {
    std::vector<char> free_vertex(s_.p.size(), 0);
    for (int v : region_) free_vertex[v] = 1;
    return free_vertex;
  }

  // Tutte solve of x over `free_x` and of y over `free_y` (one system when they are the same);
  // true while folds remain in the region.
  bool solve(const std::vector<char>& free_x, const std::vector<char>& free_y) {
    std::vector<int> faces;
    std::vector<char> seen(s_.t.size(), 0);
    for (int v : region_)
      if (free_x[v] || free_y[v])
        for (int f : vf_[v])
          if (!seen[f]) seen[f] = 1, faces.push_back(f);
    const std::vector<std::array<double, 3>> uniform(faces.size(), {1.0, 1.0, 1.0});
    const std::vector<std::array<V2, 3>> zero(faces.size(), {V2::Zero(), V2::Zero(), V2::Zero()});
    const bool same = free_x == free_y;
    RegionSystem sx, sy;
    if (!sx.build(s_, free_x, faces, uniform) || (!same && !sy.build(s_, free_y, faces, uniform))) return false;
    const std::vector<V2> px = sx.solve(s_, emb_, zero), py = same ? px : sy.solve(s_, emb_, zero);
    for (int v : region_) emb_.pos[v] = V2(px[v].x(), py[v].y());
    return std::any_of(faces.begin(), faces.end(), [&](int f) { return folded(f); });
  }

  const Surface& s_;
  const std::vector<std::vector<int>>& vf_;
  Embedding& emb_;
  const std::vector<char>& fixed_;
  const std::vector<char>& degenerate_;
  std::vector<char> in_;
  std::vector<int> region_;
};

}  // namespace

std::size_t untangle(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                     const std::vector<char>& fixed, const std::vector<char>& degenerate) {
  return Untangler(s, vf, emb, fixed, degenerate).run();
}

}  // namespace cf::flat_detail
