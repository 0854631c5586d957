// Tag placement on a montage (qc_tags.h): a greedy search over a grid of box corners, with
// summed-area tables of the lumen outline, the "ink" a tag should not hide (body outlines, anchors,
// earlier leaders) and the boxes already placed, so that each candidate costs O(1).
#include "colonflat/report/qc_tags.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace cf {
namespace {

// Summed-area table of a w x h mask (row-major, row 0 at the top): box sums in O(1).
class MaskSums {
 public:
  MaskSums(int w, int h) : w_(w), h_(h), s_(std::size_t(w + 1) * (h + 1), 0) {}
  void build(const std::vector<unsigned char>& m) {
    for (int r = 0; r < h_; ++r) {
      long row = 0;
      for (int c = 0; c < w_; ++c) {
        row += m[std::size_t(r) * w_ + c] ? 1 : 0;
        s_[at(r + 1, c + 1)] = s_[at(r, c + 1)] + row;
      }
    }
  }
  // Set pixels in the box of corner (x, y), size bw x bh (inside the image).
  long box(int x, int y, int bw, int bh) const { return s_[at(y + bh, x + bw)] - s_[at(y, x + bw)] - s_[at(y + bh, x)] + s_[at(y, x)]; }

 private:
  std::size_t at(int r, int c) const { return std::size_t(r) * (w_ + 1) + c; }
  int w_, h_;
  std::vector<long> s_;
};

// Calls f(col, row) for every pixel of the 1-pixel line from (c0, r0) to (c1, r1), both ends included.
template <class F>
void line_pixels(int c0, int r0, int c1, int r1, F f) {
  const int n = std::max(std::abs(c1 - c0), std::abs(r1 - r0));
  for (int i = 0; i <= n; ++i) {
    const double t = n ? double(i) / n : 0.0;
    f(int(std::lround(c0 + t * (c1 - c0))), int(std::lround(r0 + t * (r1 - r0))));
  }
}

// The point of a tag's box nearest its anchor (the anchor itself when the box holds it).
std::pair<int, int> nearest_in_box(const QcTag& t) {
  return {std::clamp(t.col, t.x, t.x + t.w - 1), std::clamp(t.row, t.y, t.y + t.h - 1)};
}

class TagPlacer {
 public:
  TagPlacer(int w, int h, const std::vector<unsigned char>& lumen_edge, const std::vector<unsigned char>& body_edge,
            const std::vector<QcTagAnchor>& anchors, const QcTagOptions& o)
      : w_(w), h_(h), o_(o), ink_(body_edge), used_(std::size_t(w) * h, 0), lumen_(w, h), ink_sums_(w, h),
        used_sums_(w, h), anchor_sums_(w, h) {
    lumen_.build(lumen_edge);
    std::vector<unsigned char> near_anchor(std::size_t(w) * h, 0);
    for (const QcTagAnchor& a : anchors)
      for_near(a, [&](int c, int r) { near_anchor[std::size_t(r) * w + c] = 1; });
    anchor_sums_.build(near_anchor);
    ink_sums_.build(ink_);
    used_sums_.build(used_);
  }
  QcTag place(const QcTagAnchor& a);

 private:
  // Calls f(col, row) for the anchor's 3 x 3 neighbourhood inside the image.
  template <class F>
  void for_near(const QcTagAnchor& a, F f) const {
    for (int r = std::max(0, a.row - 1); r <= std::min(h_ - 1, a.row + 1); ++r)
      for (int c = std::max(0, a.col - 1); c <= std::min(w_ - 1, a.col + 1); ++c) f(c, r);
  }
  std::vector<int> corners(int extent, int size, int anchor) const;
  double cost(const QcTagAnchor& a, int x, int y, int bw, int bh) const;
  void take(const QcTag& t);

  int w_, h_;
  const QcTagOptions& o_;
  std::vector<unsigned char> ink_, used_;
  MaskSums lumen_, ink_sums_, used_sums_, anchor_sums_;
};

// Distance from the anchor to the box + penalty per pixel it hides: body outlines, earlier
// leaders, and other bodies' anchors (3 x 3 each; its own anchor it may cover); among boxes
// as near, the one centred best on the anchor (1e-3 per pixel off centre: < 1 pixel on any montage).
double TagPlacer::cost(const QcTagAnchor& a, int x, int y, int bw, int bh) const {
  const int dx = std::max({x - a.col, 0, a.col - (x + bw - 1)}), dy = std::max({y - a.row, 0, a.row - (y + bh - 1)});
  long own = 0;
  for_near(a, [&](int c, int r) { own += c >= x && c < x + bw && r >= y && r < y + bh; });
  const long hidden = ink_sums_.box(x, y, bw, bh) + std::max(0L, anchor_sums_.box(x, y, bw, bh) - own);
  const double off_centre = std::hypot(x + 0.5 * (bw - 1) - a.col, y + 0.5 * (bh - 1) - a.row);  // tie-break: centred
  return std::hypot(dx, dy) + o_.cover_penalty_px * double(hidden) + 1e-3 * off_centre;
}

// Corner positions along one axis: the step grid, the last position, and the three around the
// anchor (box centred on it, just after it, just before it).
std::vector<int> TagPlacer::corners(int extent, int size, int anchor) const {
  std::vector<int> v;
  for (int x = 0; x + size <= extent; x += std::max(1, o_.step_px)) v.push_back(x);
  v.push_back(extent - size);
  for (int x : {anchor - size / 2, anchor + 1, anchor - size}) v.push_back(std::clamp(x, 0, extent - size));
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// The best free box for one anchor: fewest lumen-outline pixels, then least cost (distance to the
// anchor + penalty per pixel hidden); ties go to the first corner in row-major order.
QcTag TagPlacer::place(const QcTagAnchor& a) {
  QcTag t;
  t.id = a.id, t.col = a.col, t.row = a.row;
  t.w = qc_tag_width(a.id, o_), t.h = o_.height_px;
  if (t.w > w_ || t.h > h_) return t;
  long best_lumen = std::numeric_limits<long>::max();
  double best_cost = std::numeric_limits<double>::infinity();
  const std::vector<int> xs = corners(w_, t.w, a.col), ys = corners(h_, t.h, a.row);
  for (int y : ys)
    for (int x : xs) {
      if (used_sums_.box(x, y, t.w, t.h) > 0) continue;
      const long lumen = lumen_.box(x, y, t.w, t.h);
      if (lumen > best_lumen) continue;
      const double c = cost(a, x, y, t.w, t.h);
      if (lumen < best_lumen || c < best_cost) best_lumen = lumen, best_cost = c, t.x = x, t.y = y, t.placed = true;
    }
  if (!t.placed) return t;
  t.lumen_covered = int(best_lumen);
  t.leader = a.col < t.x || a.col >= t.x + t.w || a.row < t.y || a.row >= t.y + t.h;
  take(t);
  return t;
}

// A placed tag: its box is taken, its leader becomes ink for the tags after it.
void TagPlacer::take(const QcTag& t) {
  for (int r = t.y; r < t.y + t.h; ++r) std::fill_n(used_.begin() + std::ptrdiff_t(r) * w_ + t.x, t.w, 1);
  used_sums_.build(used_);
  if (!t.leader) return;
  const auto [c1, r1] = nearest_in_box(t);
  line_pixels(t.col, t.row, c1, r1, [&](int c, int r) { ink_[std::size_t(r) * w_ + c] = 1; });
  ink_sums_.build(ink_);
}

}  // namespace

int qc_tag_width(int id, const QcTagOptions& o) {
  int digits = 1;
  for (int v = std::abs(id); v >= 10; v /= 10) ++digits;
  return o.pad_px + o.digit_px * digits;
}

std::vector<QcTag> place_qc_tags(int w, int h, const std::vector<unsigned char>& lumen_edge,
                                 const std::vector<unsigned char>& body_edge, const std::vector<QcTagAnchor>& anchors,
                                 const QcTagOptions& o) {
  std::vector<QcTag> tags;
  if (w <= 0 || h <= 0) return tags;
  TagPlacer placer(w, h, lumen_edge, body_edge, anchors, o);
  for (const QcTagAnchor& a : anchors) tags.push_back(placer.place(a));
  return tags;
}

void draw_qc_leaders(int w, int h, std::vector<unsigned char>& rgb, const std::vector<QcTag>& tags,
                     const std::vector<std::array<unsigned char, 3>>& colour_by_id) {
  for (const QcTag& t : tags) {
    if (!t.placed || !t.leader || t.id < 0 || std::size_t(t.id) >= colour_by_id.size()) continue;
    const auto [c1, r1] = nearest_in_box(t);
    line_pixels(t.col, t.row, c1, r1, [&](int c, int r) {
      if (c >= 0 && r >= 0 && c < w && r < h) std::copy_n(colour_by_id[std::size_t(t.id)].data(), 3, &rgb[3 * (std::size_t(r) * w + c)]);
    });
  }
}

}  // namespace cf
