// render_colon_image, steps 4-5: overlays drawn with VTK's canvas (markers, not-shown rings, scale
// bar, axis ticks), then the text drawn with FreeType (scale, tick labels, band captions, legend,
// title), then the marker labels, each placed off the text and the labels before it
// (label_placement.h), with a leader line when away from its mark.
#include <vtkImageCanvasSource2D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "colonflat/core/error.h"
#include "colon_image_steps.h"

namespace cf::detail {

vtkStandardNewMacro(OverlayCanvas);

void OverlayCanvas::draw_on(vtkImageData* image) {
  if (image->GetScalarType() != VTK_UNSIGNED_CHAR || image->GetNumberOfScalarComponents() != 3)
    throw Error("overlay canvas: needs an RGB unsigned char image");
  ImageData->ShallowCopy(image);  // shares the scalar array: drawing writes into `image`
  image->GetExtent(WholeExtent);
}

// The tube's pixels lie within radius of the segment, so inside its bounding box grown by
// radius + 1 (clipped to the image, as VTK clips the segment); there the box canvas, with the
// image's coordinates, makes the same distance tests as a canvas over the whole image.
void OverlayCanvas::fill_tube(int a0, int a1, int b0, int b1, double radius) {
  int e[6];
  ImageData->GetExtent(e);
  const int grow = int(std::ceil(radius)) + 1;
  const int x0 = std::max(e[0], std::min(a0, b0) - grow), x1 = std::min(e[1], std::max(a0, b0) + grow);
  const int y0 = std::max(e[2], std::min(a1, b1) - grow), y1 = std::min(e[3], std::max(a1, b1) + grow);
  if (x0 > x1 || y0 > y1) return;
  ImagePtr sub = ImagePtr::New();
  sub->SetExtent(x0, x1, y0, y1, 0, 0);
  sub->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  const int row = 3 * (x1 - x0 + 1);
  auto at = [](vtkImageData* im, int x, int y) { return static_cast<unsigned char*>(im->GetScalarPointer(x, y, 0)); };
  for (int y = y0; y <= y1; ++y) std::copy_n(at(ImageData, x0, y), row, at(sub, x0, y));
  vtkNew<OverlayCanvas> box;
  box->draw_on(sub);
  box->SetDrawColor(GetDrawColor());
  box->FillTube(a0, a1, b0, b1, radius);
  for (int y = y0; y <= y1; ++y) std::copy_n(at(sub, x0, y), row, at(ImageData, x0, y));
}

namespace {

std::string fmt2(double v) {
  std::ostringstream t;
  t.precision(2);
  t << v;
  return t.str();
}

std::string fmt0(double v) {
  std::ostringstream t;
  t.setf(std::ios::fixed);
  t.precision(0);
  t << v;
  return t.str();
}

double nice_length(double target) {
  const double c[] = {5, 10, 20, 25, 50, 100, 200, 250, 500, 1000};
  double best = c[0];
  for (double v : c)
    if (std::abs(std::log(v / target)) < std::abs(std::log(best / target))) best = v;
  return best;
}

// Band x (mm) of a centreline distance (mm from the band's x0 end): the segment's table when
// present (area-balanced map: x follows the wall area, not exactly the centreline), else x itself.
double x_of_centreline(const FlatSegment& s, double d) {
  const auto& t = s.centreline_x;
  if (t.size() < 2) return d;
  if (d <= t.front()[0]) return t.front()[1];
  if (d >= t.back()[0]) return t.back()[1];
  std::size_t i = 1;
  while (t[i][0] < d) ++i;
  const double a = (d - t[i - 1][0]) / std::max(1e-12, t[i][0] - t[i - 1][0]);
  return t[i - 1][1] + a * (t[i][1] - t[i - 1][1]);
}

// Where the wall the map does not show (flatten's coverage clusters, >= kNotShownMinArea) lies on
// the image: at the mapped vertex nearest to each cluster's LPS centroid (on its rim when the
// cluster is missing from the map, inside it when it is only compressed). The cluster's own pixels
// are too few to see, so the image rings them instead.
constexpr double kNotShownMinArea = 25.0;  // mm^2 of 3D wall
struct NotShownMark {
  int segment = 0;
  double x = 0, y = 0;  // flat layout position (mm)
  double area_mm2 = 0;
};
// The flat layout position of segment `segment`'s vertex nearest to `lps` (false: none in it).
bool nearest_flat_position(const FlatMap& f, int segment, const std::array<double, 3>& lps, double& x, double& y) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < f.position.size(); ++v) {
    if (f.segment[v] != segment) continue;
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (f.position[v][k] - lps[k]) * (f.position[v][k] - lps[k]);
    if (d < best) best = d, x = f.uv[v][0], y = f.uv[v][1];
  }
  return best < std::numeric_limits<double>::infinity();
}

std::vector<NotShownMark> not_shown_marks(const FlatMap& f) {
  std::vector<NotShownMark> marks;
  for (const FlatSegment& s : f.segments)
    for (const auto& cl : s.coverage.not_shown) {
      if (cl.area_mm2 < kNotShownMinArea) continue;
      NotShownMark m;
      m.segment = s.id;
      m.area_mm2 = cl.area_mm2;
      if (nearest_flat_position(f, s.id, cl.centroid_lps_mm, m.x, m.y)) marks.push_back(m);
    }
  return marks;
}

// Where each side branch (a pouch shown as a band of its own) leaves its parent band: at the
// parent's mapped vertex nearest to the branch's neck centre.
struct NeckMark {
  int segment = 0, branch = 0;
  double x = 0, y = 0;  // flat layout position (mm)
  std::string label;    // neck_label() of the branch's band
};
std::vector<NeckMark> neck_marks(const FlatMap& f) {
  std::vector<NeckMark> marks;
  for (const FlatSegment& b : f.segments) {
    NeckMark m{b.parent, b.id, 0, 0, neck_label(b)};
    if (b.kind == "branch" && b.parent >= 0 && nearest_flat_position(f, b.parent, b.attach_lps, m.x, m.y))
      marks.push_back(m);
  }
  return marks;
}

// Ticks below each band: every 1 cm (short), 5 cm (medium) and 10 cm (long, labelled in cm) of
// x = centreline distance from the band's x0 end plus the centreline length of earlier segments.
std::vector<Tick> axis_ticks(const FlatMap& f, const std::vector<Band>& bands, double px) {
  std::vector<Tick> ticks;
  for (const Band& b : bands) {
    const FlatSegment& s = f.segments[b.seg];
    const double off = s.centreline_offset;
    const double step = 10.0 / px < 4 ? 50.0 : 10.0;  // mm; 1 cm ticks only when they are >= 4 px apart
    const double len = s.centreline_length > 0 ? s.centreline_length : s.length;
    for (double mm = std::ceil(off / step) * step; mm <= off + len + 1e-9; mm += step) {
      Tick t;
      t.col = b.col0 + int(std::lround(x_of_centreline(s, mm - off) / px));
      t.row_bottom = b.row0 - 1;
      const long cm = std::lround(mm / 10);
      t.len = cm % 10 == 0 ? 12 : cm % 5 == 0 ? 8 : 4;
      if (cm % 10 == 0) t.text = std::to_string(cm);
      ticks.push_back(t);
    }
  }
  return ticks;
}

}  // namespace

// The shapes drawn by VTK's canvas straight onto the shaded bands: the canvas's image shares the
// bands' pixels (OverlayCanvas), so nothing is copied. (DrawImage copied every pixel into the
// canvas through VTK's generic per-pixel path, then the canvas's output was copied again: about
// 0.15 s CPU on the real CT's 4641 x 1652 px image, and 46 MB of fresh pages.)
void ColonImagePainter::compose_overlays() {
  vtkNew<OverlayCanvas> canvas;
  canvas->draw_on(image_);
  draw_markers(canvas);
  draw_not_shown_rings(canvas);
  draw_branch_necks(canvas);
  draw_scale_bar(canvas);
  draw_ticks(canvas);
  pixels_ = nullptr;
}

void ColonImagePainter::draw_markers(OverlayCanvas* canvas) {
  for (auto& mk : markers_)
    if (const Band* band = band_of(mk.segment)) draw_marker(canvas, mk, *band);
}

// A circle (dashed green for a known polyp, yellow for a candidate) with its label beside it; the
// marker's pixel position is recorded.
void ColonImagePainter::draw_marker(OverlayCanvas* canvas, ImageMarker& mk, const Band& band) {
  const auto [cx, cy] = pixel_of(band, mk.x, mk.y);
  mk.px = cx;
  mk.py = height_ - 1 - cy;
  const double r = std::max(6.0, mk.radius_mm / px_ + 4);
  if (mk.known) canvas->SetDrawColor(60, 230, 90);
  else canvas->SetDrawColor(255, 230, 0);
  const int nseg = 36;
  for (int k = 0; k < nseg; ++k) {
    if (mk.known && k % 2) continue;
    const double a0 = 2 * M_PI * k / nseg, a1 = 2 * M_PI * (k + 1) / nseg;
    canvas->fill_tube(int(cx + r * std::cos(a0)), int(cy + r * std::sin(a0)), int(cx + r * std::cos(a1)),
                      int(cy + r * std::sin(a1)), 1.3);
  }
  Label l{mk.label, int(cx + r * 0.75), int(height_ - 1 - (cy + r * 0.75)) - 16, {1, 0.9, 0}, 14, 0.55,
          int(cx), height_ - 1 - int(cy), int(std::ceil(r))};
  if (mk.known) l.col[0] = 0.25, l.col[1] = 0.95, l.col[2] = 0.4, l.y = int(height_ - 1 - (cy - r * 0.75)) + 2;
  labels_.push_back(l);
}

// Wall not shown: a red square ring at its place, labelled with its 3D area.
void ColonImagePainter::draw_not_shown_rings(OverlayCanvas* canvas) {
  canvas->SetDrawColor(255, 60, 60);
  for (const NotShownMark& m : not_shown_marks(flat_)) {
    const Band* band = band_of(m.segment);
    if (!band) continue;
    const auto pixel = pixel_of(*band, m.x, m.y);
    const int cx = int(pixel[0]), cy = int(pixel[1]), r = 9;
    canvas->FillBox(cx - r, cx + r, cy - r, cy - r + 1);
    canvas->FillBox(cx - r, cx + r, cy + r - 1, cy + r);
    canvas->FillBox(cx - r, cx - r + 1, cy - r, cy + r);
    canvas->FillBox(cx + r - 1, cx + r, cy - r, cy + r);
    const std::string area = m.area_mm2 < 1000 ? fmt0(m.area_mm2) + " mm2" : fmt0(m.area_mm2 / 100.0) + " cm2";
    labels_.push_back({area + " not shown", cx + r + 2, height_ - 1 - cy - 6, {1, 0.45, 0.45}, 12, 0.55, cx,
                       height_ - 1 - cy, r});
  }
}

// A side branch's neck on its parent band: a cyan diamond labelled with the branch's band.
void ColonImagePainter::draw_branch_necks(OverlayCanvas* canvas) {
  canvas->SetDrawColor(80, 220, 255);
  for (const NeckMark& m : neck_marks(flat_)) {
    const Band* band = band_of(m.segment);
    if (!band) continue;
    const auto pixel = pixel_of(*band, m.x, m.y);
    const int cx = int(pixel[0]), cy = int(pixel[1]), r = 10;
    const int corner[5][2] = {{cx, cy - r}, {cx + r, cy}, {cx, cy + r}, {cx - r, cy}, {cx, cy - r}};
    for (int k = 0; k < 4; ++k) canvas->fill_tube(corner[k][0], corner[k][1], corner[k + 1][0], corner[k + 1][1], 1.3);
    labels_.push_back({m.label, cx + r + 2, height_ - 1 - cy - 6, {0.45, 0.9, 1}, 12, 0.55, cx, height_ - 1 - cy, r});
  }
}

// Scale bar (bottom left), in mm at the mean (area-preserving) scale.
void ColonImagePainter::draw_scale_bar(OverlayCanvas* canvas) {
  const int margin = margin_;
  bar_mm_ = nice_length(0.12 * (width_ - 2 * margin) * px_);
  bar_px_ = int(std::lround(bar_mm_ / px_));
  canvas->SetDrawColor(255, 255, 255);
  canvas->FillBox(margin, margin + bar_px_, 28, 34);
  canvas->FillBox(margin, margin + 2, 22, 40);
  canvas->FillBox(margin + bar_px_ - 2, margin + bar_px_, 22, 40);
  text_boxes_.push_back({margin, height_ - 1 - 40, bar_px_ + 1, 19});  // labels keep off the bar too
}

void ColonImagePainter::draw_ticks(OverlayCanvas* canvas) {
  ticks_ = axis_ticks(flat_, bands_, px_);
  canvas->SetDrawColor(230, 230, 230);
  for (const Tick& t : ticks_) canvas->FillBox(t.col, t.col + 1, t.row_bottom - t.len, t.row_bottom);
}

// The scale bar's length and pixel size, and the cm labels under the long ticks.
void ColonImagePainter::write_scale_text() {
  const double white[3] = {1, 1, 1}, grey[3] = {0.85, 0.85, 0.85};
  const int margin = margin_;
  std::ostringstream sb;
  sb << bar_mm_ << " mm";
  write_text(sb.str(), margin + bar_px_ + 10, height_ - 44, 16, white);
  std::ostringstream q;
  q.precision(2);
  q << px_;
  write_text("(scale at the mean, area-preserving map scale; 1 px = " + q.str() + " mm)",
            margin + bar_px_ + 80, height_ - 42, 12, grey);
  for (const Tick& t : ticks_)
    if (!t.text.empty()) write_text(t.text, t.col - 4 * int(t.text.size()), height_ - t.row_bottom + 2, 12, grey);
}

// Above each band: what it shows and its x axis; its two ends named at its corners.
void ColonImagePainter::write_band_captions() {
  const double grey[3] = {0.85, 0.85, 0.85}, end_col[3] = {1, 0.85, 0.35};
  for (const Band& b : bands_) {
    const FlatSegment& s = flat_.segments[b.seg];
    const bool along = !s.map.empty() && s.map != "conformal" && s.map != "disk";
    const std::string t = band_caption(s) +
                          (along             ? "x axis: cm along the centreline from the " + s.x0_end
                           : s.map == "disk" ? "x axis: cm of the disk's own map (rim to rim, not centreline length)"
                                             : "x axis: cm of the conformal map (not centreline length)");
    write_text(t, b.col0, height_ - 1 - (b.row0 + b.h) - 24, 15, grey);
    const int top_row = height_ - 1 - (b.row0 + b.h) + 4;
    write_text(s.x0_end, b.col0 + 4, top_row, 16, end_col, 0.6);
    if (b.w > 10 * int(s.x0_end.size() + s.x1_end.size()) + 24)  // both names fit side by side
      write_text(s.x1_end, b.col0 + b.w - 10 * int(s.x1_end.size()) - 8, top_row, 16, end_col, 0.6);
  }
}

// The hatching legend (bottom) and the title (top).
void ColonImagePainter::write_legend_and_title() {
  const double white[3] = {1, 1, 1}, grey[3] = {0.85, 0.85, 0.85};
  const int margin = margin_;
  write_text("hatched blue: wall compressed below " + fmt2(opts_.compressed_ratio) +
                        " x its area; hatched red: wall not in the map; red squares: wall the image cannot show (its 3D area)",
            margin, height_ - 22, 12, grey);
  write_text(opts_.title.empty() ? automatic_title() : opts_.title, margin, 12, 18, white);
}

void ColonImagePainter::write_text(const std::string& text, int x, int y, int size, const double col[3], double bg) {
  const std::array<int, 2> wh = draw_text(image_, text, x, y, size, col, bg);
  text_boxes_.push_back({x, y, wh[0], wh[1]});
}

// The marker, ring and neck labels over everything, in the order they were made (polyp markers,
// not-shown rings, necks), each where LabelPlacer finds it a free spot; the leaders first, so no
// leader crosses a label's text.
void ColonImagePainter::write_labels() {
  LabelPlacer placer(width_, height_);
  for (const PixelBox& b : text_boxes_) placer.keep_clear(b);
  std::vector<int> mark;
  for (const Label& l : labels_) mark.push_back(placer.add_mark(l.mark_x, l.mark_y, l.mark_r));
  std::vector<LabelPlacement> placed;
  for (std::size_t i = 0; i < labels_.size(); ++i) {
    const Label& l = labels_[i];
    const std::array<int, 2> wh = text_size(l.text, l.size, l.bg);
    placed.push_back(placer.place({wh[0], wh[1], l.x, l.y, l.mark_x, l.mark_y, l.mark_r}, mark[i]));
  }
  vtkNew<OverlayCanvas> canvas;
  canvas->draw_on(image_);
  for (std::size_t i = 0; i < labels_.size(); ++i) {
    if (!placed[i].leader) continue;
    const int* p = placed[i].line;
    const double* c = labels_[i].col;
    canvas->SetDrawColor(255 * c[0], 255 * c[1], 255 * c[2]);
    canvas->fill_tube(p[0], height_ - 1 - p[1], p[2], height_ - 1 - p[3], 0.8);
  }
  for (std::size_t i = 0; i < labels_.size(); ++i) {
    const PixelBox& b = placed[i].box;
    draw_text(image_, labels_[i].text, b.x, b.y, labels_[i].size, labels_[i].col, labels_[i].bg);
    if (placed[i].crowded)
      out_.crowded_labels.push_back(labels_[i].text + " at (" + std::to_string(b.x) + ", " + std::to_string(b.y) + ")");
  }
  out_.labels_moved = placer.moved();
  out_.labels_crowded = placer.crowded();
}

std::string ColonImagePainter::automatic_title() const {
  int nc = 0, nk = 0;
  for (const auto& m : markers_) (m.known ? nk : nc)++;
  const std::string map =
      flat_.segments.empty() || flat_.segments[0].map.empty() ? std::string("conformal") : flat_.segments[0].map;
  return "ColonFlat: unrolled colon wall (" + map + " map), " + std::to_string(nc) + " polyp candidate" +
         (nc == 1 ? "" : "s") + " (yellow)" + (nk ? ", " + std::to_string(nk) + " known polyps (green, dashed)" : "");
}

}  // namespace cf::detail

namespace cf {

std::string band_caption(const FlatSegment& s) {
  using detail::fmt0;
  std::string t = "segment " + std::to_string(s.id + 1) + ": ";
  if (s.kind == "branch" && s.holds == "wall")
    t += "wall patch (hidden in the map of) segment " + std::to_string(s.parent + 1) + " at " +
         fmt0(s.attach_mm / 10) + " cm, rim " + fmt0(s.neck_mm) + " mm around; ";
  else if (s.kind == "branch")
    t += std::string(s.holds == "tissue" ? "tissue strand (cut bridge) off" : "side branch (pouch) of") + " segment " +
         std::to_string(s.parent + 1) + " at " + fmt0(s.attach_mm / 10) + " cm, neck " + fmt0(s.neck_mm) +
         " mm around; ";
  if (s.map == "disk")  // flatten's disk map: no ends, no wrap; its box is the bounding box of the disk's outline
    return t + "mapped as a disk in a " + fmt0(s.length) + " x " + fmt0(s.period) + " mm box, its rim the outline; ";
  return t + fmt0(s.length) + " mm long x " + fmt0(s.period) + " mm around; " + s.x0_end + " (left) to " + s.x1_end +
         " (right); ";
}

std::string neck_label(const FlatSegment& s) {
  return std::string(s.holds == "wall" ? "patch" : "branch") + ": segment " + std::to_string(s.id + 1);
}

}  // namespace cf
