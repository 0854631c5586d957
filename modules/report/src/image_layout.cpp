#include "colonflat/report/image_layout.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace cf {
namespace {

double wrap(double v, double period) { return std::fmod(std::fmod(v, period) + period, period); }

}  // namespace

ColonImageLayout::ColonImageLayout(const FlatMap& flat, double pixel_size, int max_width) : flat_(flat) {
  const ColonImageGeometry geometry = colon_image_geometry(flat, pixel_size, max_width);
  pixel_size_ = geometry.pixel_size;
  width_ = geometry.width;
  height_ = geometry.height;
  for (const ColonImageBand& g : geometry.bands)
    bands_.push_back({g, flat.segments[g.segment].y0});  // render's roll when a band has no marker
}

const ImageBand* ColonImageLayout::band_of(int segment) const {
  for (const auto& b : bands_)
    if (b.segment == segment) return &b;
  return nullptr;
}

void ColonImageLayout::set_rolls_from_candidates(const nlohmann::json& candidates) {
  if (!candidates.is_array()) return;
  for (const auto& c : candidates) {
    if (!c.contains("flat_mm") || !c.contains("pixel") || !c.contains("segment")) continue;
    const int seg = c["segment"].get<int>();
    auto* b = const_cast<ImageBand*>(band_of(seg));
    if (!b) continue;
    const double y = c["flat_mm"][1].get<double>();
    const double row_up = height_ - 1 - c["pixel"][1].get<double>() - b->row_bottom;  // rows above the band bottom
    b->roll = y - row_up * pixel_size_;
  }
}

std::array<double, 2> ColonImageLayout::to_pixel(int segment, double x, double y) const {
  const ImageBand* b = band_of(segment);
  if (!b) return {-1, -1};
  const FlatSegment& s = flat_.segments[segment];
  const double col = b->col0 + (x - s.x0) / pixel_size_;
  const double up = b->row_bottom + wrap(y - b->roll, s.period) / pixel_size_;
  return {col, height_ - 1 - up};
}

std::string ColonImageLayout::check(int image_width, int image_height, const nlohmann::json& candidates) const {
  std::ostringstream problem;
  if (image_width != width_ || image_height != height_)
    problem << "colon.png is " << image_width << " x " << image_height << " px, the flat map's layout gives " << width_
            << " x " << height_ << " px";
  if (!candidates.is_array()) return problem.str();
  for (const auto& c : candidates) {
    if (!c.contains("flat_mm") || !c.contains("pixel") || !c.contains("segment")) continue;
    const auto p = to_pixel(c["segment"].get<int>(), c["flat_mm"][0].get<double>(), c["flat_mm"][1].get<double>());
    const double dx = p[0] - c["pixel"][0].get<double>(), dy = p[1] - c["pixel"][1].get<double>();
    if (std::hypot(dx, dy) > 2.0) {
      problem << (problem.tellp() > 0 ? "; " : "") << "candidate " << c.value("id", 0) << " is drawn "
              << std::hypot(dx, dy) << " px away from where the layout puts it";
      break;
    }
  }
  return problem.str();
}

LookupGrid build_lookup_grid(const FlatMap& flat, const ColonImageLayout& layout, int step_px) {
  LookupGrid g;
  g.step_px = std::max(1, step_px);
  g.cols = (layout.width() + g.step_px - 1) / g.step_px;
  g.rows = (layout.height() + g.step_px - 1) / g.step_px;
  g.vertex.assign(std::size_t(g.cols) * g.rows, -1);
  std::vector<double> best(g.vertex.size(), std::numeric_limits<double>::infinity());
  for (std::size_t v = 0; v < flat.uv.size(); ++v) {
    const auto p = layout.to_pixel(flat.segment[v], flat.uv[v][0], flat.uv[v][1]);
    const int c = int(std::floor(p[0] / g.step_px)), r = int(std::floor(p[1] / g.step_px));
    if (c < 0 || r < 0 || c >= g.cols || r >= g.rows) continue;
    const double d = std::hypot(p[0] - (c + 0.5) * g.step_px, p[1] - (r + 0.5) * g.step_px);
    const std::size_t cell = std::size_t(r) * g.cols + c;
    if (d < best[cell]) best[cell] = d, g.vertex[cell] = int(v);
  }
  return g;
}

}  // namespace cf
