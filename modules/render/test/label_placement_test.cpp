// The colon image's label placer (label_placement.h) on tiny synthetic layouts.
#include <gtest/gtest.h>

#include <vtkImageData.h>

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "colonflat/render/colon_image.h"
#include "../src/label_placement.h"

namespace cf::detail {
namespace {

// A neck-mark label as the colon image made it: 12 pt text w x h, old place right of the mark
// (radius 10), its top 6 px above the mark's centre.
LabelRequest neck_label(int cx, int cy, int w = 110, int h = 15) { return {w, h, cx + 12, cy - 6, cx, cy, 10}; }

bool inside(const PixelBox& b, int width, int height) {
  return b.x >= 0 && b.y >= 0 && b.x + b.w <= width && b.y + b.h <= height;
}

int intersecting_pairs(const std::vector<PixelBox>& boxes) {
  int n = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t j = i + 1; j < boxes.size(); ++j) n += boxes_intersect(boxes[i], boxes[j]);
  return n;
}

// Adds each request's mark, then places the labels in order.
std::vector<LabelPlacement> place_row(LabelPlacer& placer, const std::vector<LabelRequest>& row) {
  std::vector<int> marks;
  for (const LabelRequest& r : row) marks.push_back(placer.add_mark(r.mark_x, r.mark_y, r.mark_r));
  std::vector<LabelPlacement> out;
  for (std::size_t i = 0; i < row.size(); ++i) out.push_back(placer.place(row[i], marks[i]));
  return out;
}

std::vector<LabelRequest> neck_row() {
  std::vector<LabelRequest> row;
  for (int k = 0; k < 5; ++k) row.push_back(neck_label(150 + 5 * k, 100));
  return row;
}

// Five neck marks 5 px apart in a row: their labels' old places overlap (every pair); placed, no
// two label boxes intersect, each box and each leader line lies inside the 400 x 200 image, every
// leader ends on its own label's box, and none is left crowded.
TEST(RenderLabelPlacement, LabelsOfMarksFivePixelsApartDoNotOverlap) {
  const int width = 400, height = 200;
  const std::vector<LabelRequest> row = neck_row();
  std::vector<PixelBox> old;
  for (const LabelRequest& r : row) old.push_back({r.old_x, r.old_y, r.w, r.h});
  ASSERT_EQ(intersecting_pairs(old), 10);
  LabelPlacer placer(width, height);
  const std::vector<LabelPlacement> placed = place_row(placer, row);
  std::vector<PixelBox> boxes;
  for (const LabelPlacement& p : placed) {
    boxes.push_back(p.box);
    EXPECT_TRUE(inside(p.box, width, height)) << p.box.x << "," << p.box.y;
    EXPECT_FALSE(p.crowded);
    if (!p.leader) continue;
    for (int e = 0; e < 4; e += 2) EXPECT_TRUE(inside({p.line[e], p.line[e + 1], 1, 1}, width, height));
    EXPECT_TRUE(inside({p.line[2] - p.box.x, p.line[3] - p.box.y, 1, 1}, p.box.w, p.box.h));
  }
  EXPECT_EQ(intersecting_pairs(boxes), 0);
  EXPECT_EQ(placer.crowded(), 0);
  EXPECT_GE(placer.moved(), 4);  // only the first may keep its old place
}

// A lone mark's label keeps its old place (right of the mark), with no leader.
TEST(RenderLabelPlacement, LoneMarkKeepsItsOldPlace) {
  LabelPlacer placer(400, 200);
  const LabelRequest r = neck_label(60, 80);
  const LabelPlacement p = placer.place(r, placer.add_mark(r.mark_x, r.mark_y, r.mark_r));
  EXPECT_EQ(p.box.x, 72);
  EXPECT_EQ(p.box.y, 74);
  EXPECT_FALSE(p.leader);
  EXPECT_FALSE(p.crowded);
  EXPECT_EQ(placer.moved(), 0);
}

// The same layout placed twice gives the same boxes and leaders.
TEST(RenderLabelPlacement, PlacementIsDeterministic) {
  LabelPlacer a(400, 200), b(400, 200);
  const std::vector<LabelPlacement> pa = place_row(a, neck_row()), pb = place_row(b, neck_row());
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa[i].box.x, pb[i].box.x);
    EXPECT_EQ(pa[i].box.y, pb[i].box.y);
    EXPECT_EQ(pa[i].leader, pb[i].leader);
    for (int e = 0; e < 4; ++e) EXPECT_EQ(pa[i].line[e], pb[i].line[e]);
  }
}

// A mark by the image's right edge: its old place would run off the image, so the label goes
// left of the mark, inside the image.
TEST(RenderLabelPlacement, LabelStaysInsideTheImage) {
  LabelPlacer placer(400, 200);
  const LabelRequest r = neck_label(380, 100);
  const LabelPlacement p = placer.place(r, placer.add_mark(r.mark_x, r.mark_y, r.mark_r));
  EXPECT_TRUE(inside(p.box, 400, 200));
  EXPECT_LT(p.box.x + p.box.w, 380 - 10);
  EXPECT_FALSE(p.crowded);
}

// Fixed text (a caption) over a label's old place: the label moves off it.
TEST(RenderLabelPlacement, LabelKeepsOffFixedText) {
  LabelPlacer placer(400, 200);
  placer.keep_clear({60, 70, 200, 20});
  const LabelRequest r = neck_label(50, 80);
  const LabelPlacement p = placer.place(r, placer.add_mark(r.mark_x, r.mark_y, r.mark_r));
  EXPECT_FALSE(boxes_intersect(p.box, {60, 70, 200, 20}));
  EXPECT_FALSE(p.crowded);
  EXPECT_EQ(placer.moved(), 1);
}

// Fixed text on the old place and on the spots right, left, above and below the mark, and a small
// fixed box on the leader of the first spot further out (up right, whose box is free): the label
// goes to the next spot (down right), whose box and leader (checked pixel by pixel) touch no fixed text.
TEST(RenderLabelPlacement, LeaderKeepsOffFixedText) {
  LabelPlacer placer(400, 300);
  const LabelRequest r = neck_label(200, 100);
  const std::vector<PixelBox> fixed = {{212, 93, 110, 16}, {78, 93, 110, 16}, {150, 73, 40, 15},
                                       {150, 112, 40, 15}, {204, 88, 6, 6}};
  for (const PixelBox& f : fixed) placer.keep_clear(f);
  const LabelPlacement p = placer.place(r, placer.add_mark(r.mark_x, r.mark_y, r.mark_r));
  ASSERT_TRUE(p.leader);
  EXPECT_FALSE(p.crowded);
  EXPECT_EQ(p.box.x, 212);
  EXPECT_GT(p.box.y, 100);
  const int* l = p.line;
  const int n = std::max(1, std::max(std::abs(l[2] - l[0]), std::abs(l[3] - l[1])));
  for (int k = 0; k <= n; ++k) {
    const PixelBox dot{l[0] + (l[2] - l[0]) * k / n, l[1] + (l[3] - l[1]) * k / n, 1, 1};
    for (const PixelBox& f : fixed) EXPECT_FALSE(boxes_intersect(dot, f)) << dot.x << "," << dot.y;
  }
  for (const PixelBox& f : fixed) EXPECT_FALSE(boxes_intersect(p.box, f));
}

// Too many labels for a 140 x 40 image: every label is still placed inside it (none dropped),
// and those with no free spot are counted as crowded.
TEST(RenderLabelPlacement, CrowdedLabelsAreDrawnAndCounted) {
  LabelPlacer placer(140, 40);
  std::vector<LabelRequest> row;
  for (int k = 0; k < 6; ++k) row.push_back(neck_label(20 + 5 * k, 20, 100, 15));
  const std::vector<LabelPlacement> placed = place_row(placer, row);
  ASSERT_EQ(placed.size(), 6u);
  int crowded = 0;
  for (const LabelPlacement& p : placed) {
    EXPECT_TRUE(inside(p.box, 140, 40));
    crowded += p.crowded;
  }
  EXPECT_GT(crowded, 0);
  EXPECT_EQ(placer.crowded(), crowded);
}

// text_size measures exactly the box draw_text fills, with and without a background (which pads it).
TEST(RenderLabelPlacement, TextSizeIsTheDrawnTextsSize) {
  ImagePtr img = ImagePtr::New();
  img->SetExtent(0, 299, 0, 59, 0, 0);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  const double col[3] = {1, 1, 1};
  for (const double bg : {0.0, 0.55}) {
    const std::array<int, 2> drawn = draw_text(img, "branch: segment 23", 5, 5, 12, col, bg);
    const std::array<int, 2> measured = text_size("branch: segment 23", 12, bg);
    EXPECT_EQ(drawn[0], measured[0]);
    EXPECT_EQ(drawn[1], measured[1]);
    EXPECT_GT(measured[0], measured[1]);
  }
}

}  // namespace
}  // namespace cf::detail
