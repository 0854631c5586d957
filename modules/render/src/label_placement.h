#pragma once
// Internal to the render module: where the colon image's marker labels go (polyp candidates,
// "N mm2 not shown", "branch: / patch: segment N"). Each label is tried, in a fixed order, at
// its old place, then right, left, above and below its mark, then further out (stacked one
// label height at a time up and down beside the mark, and above / below it) with a thin leader
// line back to the mark; the first spot inside the image that covers no label placed before,
// no fixed text (captions, scale, legend, title) and no other mark is taken (greedy, in the
// order the labels are given: deterministic), a spot whose leader crosses no fixed text before
// one whose leader does. When no spot is free the label still goes
// where it covers the least (never dropped) and is counted as crowded.
// Pixel rows count from the image top here.
#include <vector>

namespace cf::detail {

// A rectangle of pixels: columns [x, x + w), rows [y, y + h) from the image top.
struct PixelBox {
  int x = 0, y = 0, w = 0, h = 0;
};
bool boxes_intersect(const PixelBox& a, const PixelBox& b);
int overlap_area(const PixelBox& a, const PixelBox& b);

// One label to place: its size, its old place and its mark (centre column / row, radius, px).
struct LabelRequest {
  int w = 0, h = 0;
  int old_x = 0, old_y = 0;  // top-left of the label's old place (beside the mark)
  int mark_x = 0, mark_y = 0, mark_r = 0;
};

struct LabelPlacement {
  PixelBox box;
  bool leader = false;       // drawn away from its mark: a line joins them
  int line[4] = {0, 0, 0, 0};  // leader from (line[0], line[1]) at the mark's rim to (line[2], line[3]) on the box
  bool crowded = false;      // no free spot: drawn where it covers the least
};

struct LabelPlacerOptions {
  int gap = 2;         // px between a mark's rim and its label
  int padding = 1;     // px kept clear around every placed label
  int max_rings = 12;  // how many label heights further out the stacked spots go
};

class LabelPlacer {
 public:
  LabelPlacer(int width, int height, LabelPlacerOptions opts = {});
  // Fixed text or shapes no label may cover.
  void keep_clear(const PixelBox& box);
  // A mark (its square around centre, radius r) other labels keep off; returns its id.
  int add_mark(int x, int y, int r);
  // Places one label of mark `mark` (an id from add_mark, or -1); it then blocks later labels.
  LabelPlacement place(const LabelRequest& r, int mark = -1);
  int crowded() const { return crowded_; }
  int moved() const { return moved_; }

 private:
  struct Candidate {
    PixelBox box;
    bool leader;
  };
  std::vector<Candidate> candidates(const LabelRequest& r) const;
  bool inside(const PixelBox& b) const;
  int covered(const PixelBox& b, int mark) const;  // pixels of b over obstacles, labels, other marks
  LabelPlacement finish(const LabelRequest& r, const Candidate& c) const;
  int crossed(const LabelPlacement& p) const;  // leader pixels over fixed text

  int width_, height_;
  LabelPlacerOptions opts_;
  std::vector<PixelBox> fixed_, marks_, labels_;
  int crowded_ = 0, moved_ = 0;
};

}  // namespace cf::detail
