// LinkGrid (segment_linkgrid.h): the coarse cells of the linking step, contacts across the gap and
// the local shape of a body in its own geodesic neighbourhood (26-neighbour Dijkstra inside it).
#include "segment_linkgrid.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <tuple>
#include <unordered_map>

namespace cf::segment_detail {

LinkGrid::LinkGrid(const Dims& fine, double cell_mm) {
  std::size_t n[3];
  double sp[3];
  for (int a = 0; a < 3; ++a) {
    f_[a] = std::max(1, int(std::lround(cell_mm / fine.sp[a])));
    n[a] = (fine.n[a] + std::size_t(f_[a]) - 1) / std::size_t(f_[a]);
    sp[a] = fine.sp[a] * f_[a];
  }
  d_ = make_dims(n, sp);
  seg_.assign(d_.total, 0);
  cand_.assign(d_.total, 0);
}

Eigen::Vector3d LinkGrid::mm(std::size_t cell) const {
  std::size_t c[3];
  d_.coords(cell, c[0], c[1], c[2]);
  return {double(c[0]) * d_.sp[0], double(c[1]) * d_.sp[1], double(c[2]) * d_.sp[2]};
}

// Breadth-first growth from every segment cell through the gap (not through eligible candidates):
// each eligible candidate cell reached records the segment cell it was reached from.
void LinkGrid::grow(std::vector<std::uint32_t>& source, std::vector<Contact>& found, const std::vector<unsigned char>& eligible,
                    double gap_mm) const {
  const double hmin = std::min({d_.sp[0], d_.sp[1], d_.sp[2]});
  const double reach = gap_mm + 0.5 * std::sqrt(d_.sp[0] * d_.sp[0] + d_.sp[1] * d_.sp[1] + d_.sp[2] * d_.sp[2]);
  const int max_steps = int(std::ceil(reach / hmin)) + 1;
  std::vector<std::size_t> front, next;
  for (std::size_t c = 0; c < d_.total; ++c) {
    if (!seg_[c]) continue;
    source[c] = std::uint32_t(c);
    front.push_back(c);
    if (cand_[c] && eligible[cand_[c]]) found.push_back({cand_[c], seg_[c], c, c, 0.0});
  }
  for (int step = 1; step <= max_steps && !front.empty(); ++step) {
    next.clear();
    for (std::size_t q : front)
      for_face_neighbours(d_, q, [&](std::size_t r) {
        if (source[r] != UINT32_MAX) return;
        source[r] = source[q];
        const std::uint32_t l = cand_[r];
        if (l && eligible[l]) {
          const double gap = (mm(r) - mm(source[r])).norm();
          if (gap <= reach) found.push_back({l, seg_[source[r]], r, source[r], gap});
          return;  // not through a candidate
        }
        next.push_back(r);
      });
    front.swap(next);
  }
}

std::vector<Contact> LinkGrid::contacts(const std::vector<unsigned char>& eligible, double gap_mm, std::size_t max_per_pair,
                                        double separation_mm) const {
  std::vector<std::uint32_t> source(d_.total, UINT32_MAX);
  std::vector<Contact> found;
  grow(source, found, eligible, gap_mm);
  std::sort(found.begin(), found.end(), [](const Contact& a, const Contact& b) {
    return std::tie(a.candidate, a.segment, a.gap_mm, a.from) < std::tie(b.candidate, b.segment, b.gap_mm, b.from);
  });
  std::vector<Contact> out;
  for (std::size_t g0 = 0; g0 < found.size();) {
    std::size_t g1 = g0;
    while (g1 < found.size() && found[g1].candidate == found[g0].candidate && found[g1].segment == found[g0].segment) ++g1;
    const std::size_t first = out.size();
    for (std::size_t i = g0; i < g1 && out.size() - first < max_per_pair; ++i) {
      bool apart = true;
      for (std::size_t j = first; j < out.size() && apart; ++j)
        apart = (mm(found[i].from) - mm(out[j].from)).norm() >= separation_mm;
      if (apart) out.push_back(found[i]);
    }
    g0 = g1;
  }
  return out;
}

LocalShape LinkGrid::segment_shape(std::uint32_t id, std::size_t start, double radius_mm) const {
  return shape(seg_, id, start, radius_mm);
}
LocalShape LinkGrid::candidate_shape(std::uint32_t id, std::size_t start, double radius_mm) const {
  return shape(cand_, id, start, radius_mm);
}

// Cells of body `id` within `radius_mm` of path inside the body from `start` (Dijkstra over the 26
// neighbours), with their path lengths, in the order settled.
std::vector<std::pair<std::size_t, double>> LinkGrid::geodesic(const std::vector<std::uint32_t>& labels, std::uint32_t id,
                                                               std::size_t start, double radius_mm) const {
  struct Step {
    long offset;
    int di[3];
    double len;
  };
  std::vector<Step> steps;
  for (int k = -1; k <= 1; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i)
        if (i || j || k)
          steps.push_back({long(i) * long(d_.stride[0]) + long(j) * long(d_.stride[1]) + long(k) * long(d_.stride[2]),
                           {i, j, k}, std::sqrt(std::pow(i * d_.sp[0], 2) + std::pow(j * d_.sp[1], 2) + std::pow(k * d_.sp[2], 2))});
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  std::unordered_map<std::size_t, double> dist;
  dist.reserve(8192);
  dist[start] = 0;
  queue.push({0.0, start});
  std::vector<std::pair<std::size_t, double>> settled;
  while (!queue.empty()) {
    const auto [g, c] = queue.top();
    queue.pop();
    if (g > dist[c]) continue;
    settled.emplace_back(c, g);
    std::size_t x[3];
    d_.coords(c, x[0], x[1], x[2]);
    for (const Step& s : steps) {
      bool inside = true;
      for (int a = 0; a < 3 && inside; ++a) inside = !(s.di[a] < 0 && x[a] == 0) && !(s.di[a] > 0 && x[a] + 1 == d_.n[a]);
      if (!inside) continue;
      const std::size_t r = std::size_t(long(c) + s.offset);
      const double ng = g + s.len;
      if (labels[r] != id || ng > radius_mm) continue;
      auto it = dist.find(r);
      if (it != dist.end() && it->second <= ng) continue;
      dist[r] = ng;
      queue.push({ng, r});
    }
  }
  return settled;
}

// The front at radius_mm: its cells, centroid and the number of 26-connected pieces holding at
// least 15 % of its cells (and 3 cells).
Front LinkGrid::front(const std::vector<std::pair<std::size_t, double>>& settled, std::size_t start, double radius_mm,
                      double width_mm) const {
  Front f;
  f.radius_mm = radius_mm;
  std::unordered_map<std::size_t, int> piece;  // cell -> piece id (-1: not yet visited)
  const Eigen::Vector3d origin = mm(start);
  for (const auto& [c, g] : settled)
    if (g >= radius_mm - width_mm && g < radius_mm) {
      piece[c] = -1;
      f.centroid += mm(c) - origin;
    }
  f.cells = piece.size();
  if (f.cells == 0) return f;
  f.centroid /= double(f.cells);
  const std::size_t min_piece = std::max<std::size_t>(3, std::size_t(std::ceil(0.15 * double(f.cells))));
  int next_id = 0;
  for (auto& entry : piece) {
    if (entry.second >= 0) continue;
    std::vector<std::size_t> stack = {entry.first};
    entry.second = next_id;
    std::size_t size = 0;
    while (!stack.empty()) {
      const std::size_t c = stack.back();
      stack.pop_back();
      ++size;
      std::size_t x[3];
      d_.coords(c, x[0], x[1], x[2]);
      for (int k = -1; k <= 1; ++k)
        for (int j = -1; j <= 1; ++j)
          for (int i = -1; i <= 1; ++i) {
            const long xi = long(x[0]) + i, yj = long(x[1]) + j, zk = long(x[2]) + k;
            if (xi < 0 || yj < 0 || zk < 0 || xi >= long(d_.n[0]) || yj >= long(d_.n[1]) || zk >= long(d_.n[2])) continue;
            auto it = piece.find(d_.idx(std::size_t(xi), std::size_t(yj), std::size_t(zk)));
            if (it == piece.end() || it->second >= 0) continue;
            it->second = next_id;
            stack.push_back(it->first);
          }
    }
    f.pieces += size >= min_piece;
    ++next_id;
  }
  return f;
}

// Fronts at radius/3, 2 radius/3 and radius (each two cells wide) of the body seen from `start`.
LocalShape LinkGrid::shape(const std::vector<std::uint32_t>& labels, std::uint32_t id, std::size_t start, double radius_mm) const {
  const auto settled = geodesic(labels, id, start, radius_mm);
  LocalShape out;
  out.cells = settled.size();
  for (const auto& entry : settled) {
    out.reach_mm = std::max(out.reach_mm, entry.second);
    out.region.push_back(entry);
  }
  std::sort(out.region.begin(), out.region.end());
  const double width = front_width_mm();
  for (int t = 1; t <= 3; ++t) {
    const double r = radius_mm * t / 3.0;
    if (out.reach_mm < r - 0.5 * width) break;
    out.fronts.push_back(front(settled, start, r, width));
  }
  if (out.fronts.empty() && out.reach_mm >= 2 * width) out.fronts.push_back(front(settled, start, out.reach_mm + 1e-6, width));
  return out;
}

void LinkGrid::absorb(std::uint32_t candidate, std::uint32_t segment) {
  for (std::size_t c = 0; c < d_.total; ++c)
    if (cand_[c] == candidate) seg_[c] = segment, cand_[c] = 0;
}

}  // namespace cf::segment_detail
