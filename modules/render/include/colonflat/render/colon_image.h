#pragma once
// The 2D colon-wall image ("virtual dissection"): the flat map rasterised (pixel centres located in their triangles) at
// `pixel_size` mm, one band per segment, x along the colon (end A left), y around it. Each pixel
// is shaded from the 3D normal against a light tilted from the local large-scale wall normal
// (Gaussian-smoothed normal image) towards the colon axis, so folds and polyps stand out in
// relief. Optional colouring by shape index. Overlays: polyp candidates outlined with id and
// size, known polyps (dashed), segment labels with the anatomical ends (rectum / cecum or
// end A / B) at both ends of each band, x-axis ticks in cm along the centreline from the rectal
// end, hatching where the wall is strongly compressed (blue) or missing from the map (red), and
// a scale bar in mm (valid at the mean, area-preserving scale). Each band is rolled around the colon so that
// its cut runs as far as possible from every marker.
#include <array>
#include <mutex>
#include <string>
#include <vector>

#include "colonflat/flatten/flatten.h"
#include "colonflat/render/artifacts.h"

namespace cf {

struct ColonImageOptions {
  double pixel_size = 0.5;         // mm per pixel
  std::string color = "shading";   // "shading" or "curvature"
  double smooth_normal = 8.0;      // mm, sigma of the large-scale normal
  double light_tilt = 0.7;         // tangent component of the light (relief strength)
  int max_width = 12000;           // pixels; pixel_size grows if the colon would be wider
  std::string title;               // top line (empty: automatic)
  double compressed_ratio = 0.1;   // hatch the wall where the 2D/3D area ratio is below this
};

struct ImageMarker {
  int id = 0;
  int segment = 0;
  double x = 0, y = 0;     // flat layout position (mm)
  double radius_mm = 4;    // circle radius in the flat map (mm)
  std::string label;       // e.g. "P1 8 mm"
  bool known = false;      // known (ground-truth) polyp: dashed green; else candidate: yellow
  // filled by render_colon_image: pixel position (column, row from the top)
  double px = 0, py = 0;
};

struct ColonImage {
  ImagePtr image;           // RGB unsigned char
  double pixel_size = 0;    // mm per pixel actually used
  int width = 0, height = 0;
  std::vector<double> roll; // per segment: y offset of the cut (mm, in [y0, y0 + period))
  std::size_t missing_pixels = 0;     // band pixels with no wall (hatched red)
  std::size_t compressed_pixels = 0;  // wall pixels below compressed_ratio (hatched blue)
  int labels_moved = 0;    // marker labels not at their old place (beside the mark) to keep off other text
  int labels_crowded = 0;  // marker labels with no free spot: drawn over other text or marks where they cover least
  std::vector<std::string> crowded_labels;  // their text and place, "TEXT at (column, row from the top)"
};

// Where each segment's band lies in the image: one band per segment, stacked from the image bottom
// (last segment lowest), x along the colon from the band's left edge. The one place that sets the
// image's margins and size; the review report uses it to map pixels back to the flat map.
struct ColonImageBand {
  int segment = 0;
  int col0 = 0;        // left column of the band
  int row_bottom = 0;  // bottom row of the band, counted from the image bottom (VTK rows)
  int w = 0, h = 0;    // band size in pixels
};
struct ColonImageGeometry {
  double pixel_size = 0;  // mm per pixel actually used (grows when the colon exceeds max_width)
  int width = 0, height = 0;
  std::vector<ColonImageBand> bands;  // bottom band first
};
ColonImageGeometry colon_image_geometry(const FlatMap& flat, double pixel_size, int max_width);

// The caption above a segment's band, up to its x-axis note: "segment N: " (1-based), for a side
// branch what it is, "side branch (pouch) of segment P" (holds lumen) or "tissue strand (cut
// bridge) off segment P" (holds tissue: a crushed strand stump), its neck's place (cm) and length
// (mm), then the band's size (mm) and its left / right ends, ending in "; ".
std::string band_caption(const FlatSegment& s);
// The label of a side band's mark on its parent band: "patch: segment N" for a patch of wall the
// parent's map hid (holds "wall"), else "branch: segment N" (a pouch or a tissue strand's neck).
std::string neck_label(const FlatSegment& s);

// `shape_index`: per flat vertex (for color = "curvature"); may be empty.
ColonImage render_colon_image(const FlatMap& flat, const std::vector<double>& shape_index,
                              std::vector<ImageMarker>& markers, const ColonImageOptions& opts);

// VTK's FreeType text rendering (vtkTextRenderer, vtkFreeTypeTools and its font cache) is one
// process-wide instance and not thread-safe; the snapshots are rendered on a second thread while
// the colon image draws its labels. Only draw_text and text_size use FreeType (a snapshot's caption is drawn
// with it onto the grabbed image, its scene has no text actor), and they hold this lock.
std::mutex& freetype_mutex();

// Draws `text` into an RGB image at column x, row-from-top y (top-left corner), with FreeType
// (under freetype_mutex()); returns the text's width and height in pixels (clipped or not).
std::array<int, 2> draw_text(vtkImageData* rgb, const std::string& text, int x, int y_from_top, int font_size,
                             const double color[3], double background_opacity = 0.0);
// The width and height in pixels draw_text gives `text` at `font_size` (the same font, bold Arial;
// a background pads the text by 2 px on each side).
std::array<int, 2> text_size(const std::string& text, int font_size, double background_opacity = 0.0);

}  // namespace cf
