#pragma once
// Internal to the render module: render_colon_image() as named steps. One ColonImagePainter per
// call; each method is one step, in the order run() calls them:
//   colon_image.cpp          lay out the bands (geometry + roll), fill the background;
//   colon_image_raster.cpp   per band: roll the segment's triangles, rasterise them on the pixel grid,
//                            smooth the view normals, shade or hatch every pixel;
//   colon_image_overlay.cpp  markers, not-shown rings, scale bar and ticks (VTK canvas), then the
//                            text (scale, tick labels, band captions, legend, title), then the
//                            marker labels placed off that text and each other (label_placement.h).
// Pixel rows count from the image bottom (VTK) unless a name says "from the top".
#include <array>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "colonflat/core/triangle_raster.h"
#include "colonflat/render/colon_image.h"
#include "label_placement.h"

#include <vtkImageCanvasSource2D.h>

namespace cf::detail {

// VTK's canvas drawing onto an existing RGB unsigned char image in place.
// Pre: draw_on(image) before any drawing; image outlives the drawing. Post: every Fill* / Draw*
// call changes `image`'s own pixels (the canvas's image shares its scalar array); the canvas's
// pipeline output is never used.
class OverlayCanvas : public vtkImageCanvasSource2D {
 public:
  static OverlayCanvas* New();
  vtkTypeMacro(OverlayCanvas, vtkImageCanvasSource2D);
  void draw_on(vtkImageData* image);
  // FillTube's pixels, found on a canvas over the tube's bounding box only (VTK's FillTube tests
  // every pixel of the image: 7.7 M per tube on the real CT's colon image).
  void fill_tube(int a0, int a1, int b0, int b1, double radius);
};

// One segment's band with the roll chosen for it.
struct Band {
  int seg = 0;
  int w = 0, h = 0;  // pixels
  int col0 = 0;      // left column in the image
  int row0 = 0;      // bottom row in VTK image coordinates
  double c0 = 0;     // roll: y of the cut (mm)
};

// A tick below a band (canvas coordinates, row from the bottom); labelled ticks carry text.
struct Tick {
  int col = 0, row_bottom = 0, len = 0;
  std::string text;
};

// A text drawn last, over everything (marker ids, not-shown areas, branch necks), beside its mark;
// write_labels() moves it off the other labels and text (label_placement.h).
struct Label {
  std::string text;
  int x, y;  // top-left of its old place, row from the top
  double col[3];
  int size;
  double bg;
  int mark_x = 0, mark_y = 0, mark_r = 0;  // its mark: centre (row from the top) and radius, px
};

// A band's rolled triangles sampled at its pixel centres (pixel id = row * w + column): the
// flat map's per-vertex values interpolated linearly inside the triangle covering the centre.
struct ProbedBand {
  std::vector<char> valid;             // 1 where a triangle covers the pixel centre
  std::vector<double> normal;          // 3 per pixel: outward 3D normal (not unit)
  std::vector<double> position;        // 3 per pixel: LPS mm
  std::vector<double> shape_index;
  std::vector<double> ratio;           // 2D/3D area ratio (vertex_area_ratio)
};

// The wall seen at one pixel: unit view normal, large-scale normal, tangent along the colon.
// A copy of a segment's triangle t that rolled_segment() keeps, moved by `periods` periods.
struct RolledTriangle {
  int t;
  int periods;
};

struct PixelGeometry {
  const double* view;  // unit normal into the lumen
  double mean[3];      // smoothed view normal (not unit)
  double tangent[3];   // 3D difference of the neighbouring pixels along x
};

// Per flat vertex: the smallest 2D/3D area ratio of its triangles at its segment's
// area-preserving scale (1 = true size; small = strongly compressed on the image).
std::vector<double> vertex_area_ratio(const FlatMap& flat);

// Shape index -> RGB (cup blue, saddle pale, ridge yellow, cap red).
void colour_of_shape_index(double si, double rgb[3]);

class ColonImagePainter {
 public:
  ColonImagePainter(const FlatMap& flat, const std::vector<double>& shape_index, std::vector<ImageMarker>& markers,
                    const ColonImageOptions& opts);
  ColonImage run();

 private:
  // Layout (colon_image.cpp).
  void lay_out_bands();
  void fill_background();
  const Band* band_of(int segment) const;
  double rolled_y(const Band& band, double y) const;  // y - roll, wrapped into [0, period)
  // Image column and row (from the bottom, not rounded) of the flat point (x, y) of `band`'s segment.
  std::array<double, 2> pixel_of(const Band& band, double x, double y) const;
  // Rasterising and shading (colon_image_raster.cpp).
  void paint_band(const Band& band);
  std::vector<RolledTriangle> rolled_segment(const FlatSegment& segment, double c0) const;
  ProbedBand probe_band(const Band& band, const std::vector<RolledTriangle>& rolled) const;
  void interpolate_hit(const RasterHit& hit, const std::vector<RolledTriangle>& rolled, ProbedBand& probed,
                       std::size_t pixel) const;
  ImagePtr view_normals(const Band& band, const ProbedBand& probed) const;
  ImagePtr smoothed_normals(vtkImageData* view) const;
  PixelGeometry pixel_geometry(const Band& band, const ProbedBand& probed, const double* view, const double* mean,
                               int column, int row) const;
  // Both return whether the pixel counts as compressed / missing (paint_band sums them).
  bool shade_pixel(const PixelGeometry& g, double shape_index, double ratio, bool stripe, unsigned char* rgb) const;
  static void hatch_missing(bool stripe, unsigned char* rgb);
  void paint_rows(const Band& b, const ProbedBand& probed, const double* view, const double* mean, int j0, int j1,
                  std::size_t counts[2]) const;
  // Overlays (colon_image_overlay.cpp).
  void draw_markers(OverlayCanvas* canvas);
  void draw_marker(OverlayCanvas* canvas, ImageMarker& marker, const Band& band);
  void draw_not_shown_rings(OverlayCanvas* canvas);
  void draw_branch_necks(OverlayCanvas* canvas);
  void draw_scale_bar(OverlayCanvas* canvas);
  void draw_ticks(OverlayCanvas* canvas);
  void compose_overlays();
  void write_scale_text();
  void write_band_captions();
  void write_legend_and_title();
  void write_labels();
  // draw_text, the text's box kept for write_labels (row from the top).
  void write_text(const std::string& text, int x, int y, int size, const double col[3], double bg = 0.0);
  std::string automatic_title() const;

  const FlatMap& flat_;
  const std::vector<double>& shape_index_;
  std::vector<ImageMarker>& markers_;
  const ColonImageOptions& opts_;
  ColonImage out_;
  double px_ = 0;  // mm per pixel
  int width_ = 0, height_ = 0;
  int margin_ = 0;  // left margin of the bands and of the scale bar, legend and title (px)
  std::vector<double> vertex_ratio_;
  std::vector<Band> bands_;
  ImagePtr image_;  // the shaded bands, then the final image with overlays and text
  unsigned char* pixels_ = nullptr;
  std::vector<Tick> ticks_;
  std::vector<Label> labels_;
  std::vector<PixelBox> text_boxes_;  // the scale, tick, caption, legend and title text (labels keep off)
  double bar_mm_ = 0;
  int bar_px_ = 0;
};

}  // namespace cf::detail
