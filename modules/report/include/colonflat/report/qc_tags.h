#pragma once
// Numbered tags for the Segmentation section's montages (docs/report.md, "Tags and legend"): each
// rejected body seen on a slice gets a short tag (its number) placed near it, never over another
// tag and, wherever the image has room, never over the lumen's outline; a tag moved off its body
// is joined to it by a leader line drawn into the image. The page draws the tags over the image
// at these positions (in image pixels, so they scale with it) and lists the bodies in a legend.
#include <array>
#include <vector>

namespace cf {

struct QcTagOptions {
  int height_px = 13;           // tag height, image pixels (10-px digits + border; a montage shows ~1 CSS px a pixel)
  int digit_px = 7;             // tag width per digit of the number, image pixels
  int pad_px = 5;               // tag width besides the digits (padding + border), image pixels
  int step_px = 2;              // placement grid: candidate corners this far apart, image pixels
  double cover_penalty_px = 4;  // cost of covering one pixel of a body outline or leader, in pixels of leader length
};

// A body seen on the slice: its number and the pixel the tag points at (one of its own pixels).
struct QcTagAnchor {
  int id = 0;
  int col = 0, row = 0;
};

// A tag's box (top-left x, y; w x h, image pixels). `placed` false: no free place on the image
// (the legend still lists the body). `leader`: the box does not hold the anchor, a line joins them.
struct QcTag {
  int id = 0;
  int col = 0, row = 0;  // the anchor
  int x = 0, y = 0, w = 0, h = 0;
  bool placed = false, leader = false;
  int lumen_covered = 0;  // lumen-outline pixels under the box (0 unless the image had no other room)
};

// The box width of tag `id`: pad_px + digit_px per decimal digit.
int qc_tag_width(int id, const QcTagOptions& o);

// Places one tag per anchor on a w x h image, anchors in the order given (the caller puts the
// bodies that need a near place first). `lumen_edge` and `body_edge` are w*h masks (row-major,
// row 0 at the top) of the lumen's and the bodies' outline pixels. A tag's place is the corner
// on the step_px grid (plus those centred on, just after and just before its anchor) that minimises the distance from the
// anchor to the box + cover_penalty_px per body-outline or earlier-leader pixel covered, among
// boxes inside the image that overlap no placed tag and cover no lumen outline; only if there is
// none, boxes over the lumen outline are allowed (fewest such pixels first).
// Post: placed tags are pairwise disjoint and inside the image; deterministic.
std::vector<QcTag> place_qc_tags(int w, int h, const std::vector<unsigned char>& lumen_edge,
                                 const std::vector<unsigned char>& body_edge, const std::vector<QcTagAnchor>& anchors,
                                 const QcTagOptions& o = {});

// Draws the leader of every placed tag with `leader` into an RGB image (3 bytes a pixel, row 0 at
// the top): a 1-pixel line from the anchor to the nearest point of the box, in `colour_by_id[id]`.
void draw_qc_leaders(int w, int h, std::vector<unsigned char>& rgb, const std::vector<QcTag>& tags,
                     const std::vector<std::array<unsigned char, 3>>& colour_by_id);

}  // namespace cf
