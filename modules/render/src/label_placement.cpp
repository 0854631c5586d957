// The colon image's label placer (label_placement.h): greedy, first free spot in a fixed order.
#include "label_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace cf::detail {

bool boxes_intersect(const PixelBox& a, const PixelBox& b) { return overlap_area(a, b) > 0; }

int overlap_area(const PixelBox& a, const PixelBox& b) {
  const int w = std::min(a.x + a.w, b.x + b.w) - std::max(a.x, b.x);
  const int h = std::min(a.y + a.h, b.y + b.h) - std::max(a.y, b.y);
  return w > 0 && h > 0 ? w * h : 0;
}

LabelPlacer::LabelPlacer(int width, int height, LabelPlacerOptions opts)
    : width_(width), height_(height), opts_(opts) {}

void LabelPlacer::keep_clear(const PixelBox& box) { fixed_.push_back(box); }

int LabelPlacer::add_mark(int x, int y, int r) {
  marks_.push_back({x - r, y - r, 2 * r + 1, 2 * r + 1});
  return int(marks_.size()) - 1;
}

// The old place first, then touching the mark (right, left, above, below), then ring by ring
// further out: beside the mark one label height up and down (right, then left), above and below.
std::vector<LabelPlacer::Candidate> LabelPlacer::candidates(const LabelRequest& r) const {
  const int g = opts_.gap, cx = r.mark_x, cy = r.mark_y, rad = r.mark_r;
  const int right = cx + rad + g, left = cx - rad - g - r.w, centred = cx - r.w / 2, mid = cy - r.h / 2;
  const int up = cy - rad - g - r.h, down = cy + rad + g;
  std::vector<Candidate> c = {{{r.old_x, r.old_y, r.w, r.h}, false},
                              {{right, mid, r.w, r.h}, false},
                              {{left, mid, r.w, r.h}, false},
                              {{centred, up, r.w, r.h}, false},
                              {{centred, down, r.w, r.h}, false}};
  for (int k = 1; k <= opts_.max_rings; ++k) {
    const int d = k * (r.h + g + opts_.padding);
    for (const int x : {right, left})
      for (const int y : {mid - d, mid + d}) c.push_back({{x, y, r.w, r.h}, true});
    c.push_back({{centred, up - d, r.w, r.h}, true});
    c.push_back({{centred, down + d, r.w, r.h}, true});
  }
  return c;
}

bool LabelPlacer::inside(const PixelBox& b) const {
  return b.x >= 0 && b.y >= 0 && b.x + b.w <= width_ && b.y + b.h <= height_;
}

int LabelPlacer::covered(const PixelBox& b, int mark) const {
  const int p = opts_.padding;
  const PixelBox grown{b.x - p, b.y - p, b.w + 2 * p, b.h + 2 * p};
  int area = 0;
  for (const PixelBox& f : fixed_) area += overlap_area(grown, f);
  for (const PixelBox& l : labels_) area += overlap_area(grown, l);
  for (std::size_t m = 0; m < marks_.size(); ++m)
    if (int(m) != mark) area += overlap_area(grown, marks_[m]);
  return area;
}

// The leader runs from the mark's rim towards the box's pixel nearest the mark's centre.
LabelPlacement LabelPlacer::finish(const LabelRequest& r, const Candidate& c) const {
  LabelPlacement p;
  p.box = c.box;
  const int nx = std::clamp(r.mark_x, c.box.x, c.box.x + c.box.w - 1);
  const int ny = std::clamp(r.mark_y, c.box.y, c.box.y + c.box.h - 1);
  const double dx = nx - r.mark_x, dy = ny - r.mark_y, len = std::hypot(dx, dy);
  p.leader = c.leader && len > r.mark_r + opts_.gap;
  if (!p.leader) return p;
  const int sx = int(std::lround(r.mark_x + dx / len * r.mark_r)), sy = int(std::lround(r.mark_y + dy / len * r.mark_r));
  p.line[0] = std::clamp(sx, 0, width_ - 1), p.line[1] = std::clamp(sy, 0, height_ - 1);
  p.line[2] = nx, p.line[3] = ny;
  return p;
}

// Pixels of the leader (one per step along its longer axis, off its own label) over fixed text
// (drawn before the leaders: a leader would strike it through; the labels are drawn after them).
int LabelPlacer::crossed(const LabelPlacement& p) const {
  const int* l = p.line;
  const int n = std::max(std::abs(l[2] - l[0]), std::abs(l[3] - l[1]));
  int hits = 0;
  for (int k = 0; k <= n; ++k) {
    const double t = n ? double(k) / n : 0.0;
    const PixelBox dot{int(std::lround(l[0] + t * (l[2] - l[0]))), int(std::lround(l[1] + t * (l[3] - l[1]))), 1, 1};
    if (boxes_intersect(dot, p.box)) continue;
    for (const PixelBox& f : fixed_) hits += boxes_intersect(dot, f);
  }
  return hits;
}

// The first candidate inside the image whose box covers nothing and whose leader crosses no fixed
// text; failing that the first whose box covers nothing; failing that the one covering least.
LabelPlacement LabelPlacer::place(const LabelRequest& r, int mark) {
  const std::vector<Candidate> cands = candidates(r);
  int best = -1;
  std::pair<int, int> best_cost{std::numeric_limits<int>::max(), 0};  // (box cover, leader crossings)
  for (std::size_t i = 0; i < cands.size() && best_cost != std::pair<int, int>{0, 0}; ++i) {
    if (!inside(cands[i].box)) continue;
    const LabelPlacement p = finish(r, cands[i]);
    const std::pair<int, int> cost{covered(cands[i].box, mark), p.leader ? crossed(p) : 0};
    if (cost < best_cost) best = int(i), best_cost = cost;
  }
  Candidate chosen = best >= 0 ? cands[best] : cands[0];
  if (best < 0) {  // wider or taller than the image: its old place, pushed inside as far as it goes
    chosen.box.x = std::max(0, std::min(chosen.box.x, width_ - chosen.box.w));
    chosen.box.y = std::max(0, std::min(chosen.box.y, height_ - chosen.box.h));
  }
  LabelPlacement p = finish(r, chosen);
  p.crowded = best < 0 || best_cost.first > 0;
  crowded_ += p.crowded;
  moved_ += best != 0;
  labels_.push_back(p.box);
  return p;
}

}  // namespace cf::detail
