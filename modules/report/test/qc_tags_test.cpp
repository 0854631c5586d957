// Placement of the Segmentation montages' numbered tags (qc_tags.h) on small images built here:
// tags never overlap, stay inside the image, keep off the lumen's outline while there is room,
// sit on their body when nothing is in the way and get a leader line when moved.
#include <gtest/gtest.h>

#include <cmath>

#include "colonflat/report/qc_tags.h"

namespace cf {
namespace {

bool disjoint(const QcTag& a, const QcTag& b) {
  return a.x + a.w <= b.x || b.x + b.w <= a.x || a.y + a.h <= b.y || b.y + b.h <= a.y;
}

// Pixels of `mask` (w wide) under a tag's box.
int covered(const std::vector<unsigned char>& mask, int w, const QcTag& t) {
  int n = 0;
  for (int r = t.y; r < t.y + t.h; ++r)
    for (int c = t.x; c < t.x + t.w; ++c) n += mask[std::size_t(r) * w + c] != 0;
  return n;
}

// The outline of a disk of radius `rad` at (cc, cr) drawn into a w x h mask.
void ring(std::vector<unsigned char>& mask, int w, int h, double cc, double cr, double rad) {
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      if (std::abs(std::hypot(c - cc, r - cr) - rad) < 0.6) mask[std::size_t(r) * w + c] = 1;
}

// 30 bodies crowded into a 24 x 24 pixel patch beside a lumen ring on a 200 x 160 image: every
// tag is placed inside the image, no two overlap, none covers a lumen-outline pixel, and a tag
// whose box does not hold its anchor has a leader.
TEST(ReportQcTags, CrowdedTagsDoNotOverlapAndKeepOffTheLumen) {
  const int w = 200, h = 160;
  std::vector<unsigned char> lumen(std::size_t(w) * h, 0), bodies(std::size_t(w) * h, 0);
  ring(lumen, w, h, 60, 80, 30);
  std::vector<QcTagAnchor> anchors;
  for (int i = 0; i < 30; ++i) anchors.push_back({i + 1, 95 + (i * 7) % 24, 70 + (i * 11) % 24});
  const std::vector<QcTag> tags = place_qc_tags(w, h, lumen, bodies, anchors);
  ASSERT_EQ(tags.size(), anchors.size());
  for (std::size_t i = 0; i < tags.size(); ++i) {
    const QcTag& t = tags[i];
    ASSERT_TRUE(t.placed) << t.id;
    EXPECT_EQ(t.id, anchors[i].id);
    EXPECT_EQ(t.w, qc_tag_width(t.id, {}));
    EXPECT_TRUE(t.x >= 0 && t.y >= 0 && t.x + t.w <= w && t.y + t.h <= h) << t.id;
    EXPECT_EQ(covered(lumen, w, t), 0) << t.id;
    EXPECT_EQ(t.lumen_covered, 0) << t.id;
    const bool holds = t.col >= t.x && t.col < t.x + t.w && t.row >= t.y && t.row < t.y + t.h;
    EXPECT_EQ(t.leader, !holds) << t.id;
    for (std::size_t j = 0; j < i; ++j) EXPECT_TRUE(disjoint(t, tags[j])) << t.id << " overlaps " << tags[j].id;
  }
}

// A body crossed by the lumen's outline (a horizontal outline through its anchor row): its tag is
// moved off the outline and joined by a leader; a lone body with nothing around holds its tag.
TEST(ReportQcTags, TagLeavesTheLumenOutlineWithALeaderAndSitsOnAFreeBody) {
  const int w = 120, h = 90;
  std::vector<unsigned char> lumen(std::size_t(w) * h, 0), bodies(std::size_t(w) * h, 0);
  for (int c = 0; c < 60; ++c) lumen[std::size_t(30) * w + c] = 1;
  const std::vector<QcTag> tags = place_qc_tags(w, h, lumen, bodies, {{1, 30, 30}, {2, 90, 60}});
  ASSERT_EQ(tags.size(), 2u);
  ASSERT_TRUE(tags[0].placed && tags[1].placed);
  EXPECT_EQ(covered(lumen, w, tags[0]), 0);
  EXPECT_TRUE(tags[0].leader);
  EXPECT_LE(std::min(std::abs(tags[0].y - 31), std::abs(tags[0].y + tags[0].h - 30)), 1) << "not next to the outline";
  EXPECT_FALSE(tags[1].leader);
  EXPECT_NEAR(tags[1].x + 0.5 * tags[1].w, 90, 1.0);
  EXPECT_NEAR(tags[1].y + 0.5 * tags[1].h, 60, 1.0);
}

// A tag avoids another body's outline when a free place is as near: an anchor inside a small
// body outline (8 px wide) gets its tag beside the body, not over its outline; and a second
// body's anchor is not hidden by the first's tag.
TEST(ReportQcTags, TagsKeepOffBodyOutlinesAndOtherAnchors) {
  const int w = 100, h = 100;
  std::vector<unsigned char> lumen(std::size_t(w) * h, 0), bodies(std::size_t(w) * h, 0);
  ring(bodies, w, h, 50, 50, 4);
  const std::vector<QcTag> tags = place_qc_tags(w, h, lumen, bodies, {{1, 50, 50}, {2, 50, 58}});
  ASSERT_EQ(tags.size(), 2u);
  EXPECT_EQ(covered(bodies, w, tags[0]), 0);
  EXPECT_TRUE(tags[0].leader);
  const QcTag& t = tags[0];
  EXPECT_FALSE(58 >= t.y - 1 && 58 <= t.y + t.h && 50 >= t.x - 1 && 50 <= t.x + t.w) << "covers body 2's anchor";
  EXPECT_TRUE(disjoint(tags[0], tags[1]));
}

// More tags than the image holds: those that fit are placed, disjoint; a tag is reported unplaced
// (the legend still lists it) only when no box of its size is free anywhere, never stacked.
TEST(ReportQcTags, FullImageLeavesTagsUnplacedNotStacked) {
  const int w = 30, h = 26;
  std::vector<unsigned char> none(std::size_t(w) * h, 0);
  std::vector<QcTagAnchor> anchors;
  for (int i = 0; i < 12; ++i) anchors.push_back({i + 1, 15, 13});
  const std::vector<QcTag> tags = place_qc_tags(w, h, none, none, anchors);
  int placed = 0;
  for (std::size_t i = 0; i < tags.size(); ++i) {
    placed += tags[i].placed;
    for (std::size_t j = 0; j < i; ++j)
      if (tags[i].placed && tags[j].placed) EXPECT_TRUE(disjoint(tags[i], tags[j]));
  }
  EXPECT_GE(placed, 1);
  EXPECT_LT(placed, 12);
  for (const QcTag& t : tags) {
    if (t.placed) continue;
    for (int y = 0; y + t.h <= h; ++y)
      for (int x = 0; x + t.w <= w; ++x) {
        QcTag box = t;
        box.x = x, box.y = y;
        bool free = true;
        for (const QcTag& p : tags) free = free && (!p.placed || disjoint(box, p));
        EXPECT_FALSE(free) << "tag " << t.id << " left unplaced with room at " << x << "," << y;
      }
  }
}

// The lumen outline is covered only when nothing else is free (a full-image grid of outline
// pixels): the tag is placed, reports the pixels it covers, and they are the fewest possible.
TEST(ReportQcTags, LumenIsCoveredOnlyWhenNoFreePlaceExists) {
  const int w = 40, h = 30;
  std::vector<unsigned char> lumen(std::size_t(w) * h, 0), none(std::size_t(w) * h, 0);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; c += 12) lumen[std::size_t(r) * w + c] = 1;  // vertical outlines 12 px apart
  const std::vector<QcTag> tags = place_qc_tags(w, h, lumen, none, {{1, 20, 15}});
  ASSERT_TRUE(tags[0].placed);
  EXPECT_EQ(tags[0].lumen_covered, covered(lumen, w, tags[0]));
  EXPECT_EQ(tags[0].lumen_covered, 13);  // a 12-px-wide box always crosses one outline column (13 rows)
}

// Leaders are drawn from the anchor to the box's nearest pixel in the body's colour; a tag on its
// anchor draws nothing.
TEST(ReportQcTags, LeaderJoinsAnchorToBoxInTheBodysColour) {
  const int w = 40, h = 30;
  std::vector<unsigned char> rgb(std::size_t(w) * h * 3, 0);
  QcTag moved;
  moved.id = 1, moved.col = 5, moved.row = 5, moved.x = 20, moved.y = 5, moved.w = 12, moved.h = 13, moved.placed = true, moved.leader = true;
  QcTag on = moved;
  on.id = 2, on.col = 25, on.row = 25, on.leader = false;
  draw_qc_leaders(w, h, rgb, {moved, on}, {{0, 0, 0}, {255, 160, 0}, {0, 200, 255}});
  int orange = 0, cyan = 0;
  for (std::size_t p = 0; p < rgb.size() / 3; ++p) orange += rgb[3 * p] == 255 && rgb[3 * p + 1] == 160, cyan += rgb[3 * p + 2] == 255;
  EXPECT_EQ(orange, 16);  // columns 5..20 of row 5
  EXPECT_EQ(cyan, 0);
  EXPECT_EQ(rgb[3 * (5 * w + 20)], 255);
  EXPECT_EQ(rgb[3 * (5 * w + 21)], 0);
}

}  // namespace
}  // namespace cf
