#pragma once
// Where the flat map lies in colon.png (the render stage's image), and the coarse pixel -> flat
// vertex lookup the report page uses for hover read-outs and clicks.
//
// The render stage stacks one band per segment (last segment lowest), x along the colon from the
// band's left edge, y around it starting at a per-segment roll (the cut), at `pixel_size` mm per
// pixel. ColonImageLayout takes the bands from render's colon_image_geometry() and the rolls from the
// candidates' (flat position, pixel) pairs written by render; check() compares the result with the
// image's real size and every candidate's pixel.
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/flatten/flatten.h"
#include "colonflat/render/colon_image.h"

namespace cf {

// A band of colon.png (render's geometry: segment, col0, row_bottom, w, h) and its roll.
struct ImageBand : ColonImageBand {
  double roll = 0;  // mm: flat y shown at the band's bottom edge
};

class ColonImageLayout {
 public:
  // `pixel_size` and `max_width` as given to the render stage (ColonImageOptions).
  ColonImageLayout(const FlatMap& flat, double pixel_size, int max_width = 12000);
  // Rolls from render's candidate list ({segment, flat_mm [x, y], pixel [col, row]} each).
  void set_rolls_from_candidates(const nlohmann::json& candidates);
  // Pixel (column, row from the top) of flat point (x, y) of `segment`.
  std::array<double, 2> to_pixel(int segment, double x, double y) const;
  // "" when the layout matches the image size and the candidates' pixels (within 2 px), else
  // what differs.
  std::string check(int image_width, int image_height, const nlohmann::json& candidates) const;

  int width() const { return width_; }
  int height() const { return height_; }
  double pixel_size() const { return pixel_size_; }
  const std::vector<ImageBand>& bands() const { return bands_; }

 private:
  const ImageBand* band_of(int segment) const;
  const FlatMap& flat_;
  double pixel_size_ = 0.5;
  int width_ = 0, height_ = 0;
  std::vector<ImageBand> bands_;
};

// A coarse grid over the image: cell (c, r) covers pixels [c*step, (c+1)*step) x [r*step, ...);
// `vertex` holds the flat vertex nearest to the cell centre among those inside the cell, or -1.
struct LookupGrid {
  int step_px = 8;
  int cols = 0, rows = 0;
  std::vector<int> vertex;  // cols * rows, row-major from the top
};
LookupGrid build_lookup_grid(const FlatMap& flat, const ColonImageLayout& layout, int step_px);

}  // namespace cf
