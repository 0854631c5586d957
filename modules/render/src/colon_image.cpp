#include "colonflat/render/colon_image.h"

#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkRenderingFreeType);

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "colonflat/core/error.h"
#include "colon_image_steps.h"

namespace cf {
namespace {

// The image's margins (pixels): left/right, above the top band (title), between bands (labels),
// below the bottom band (ticks, scale bar, legend); and the narrowest image.
constexpr int kMargin = 30, kTop = 70, kGap = 64, kBottom = 90, kMinWidth = 400;

// Picks the cut position of a segment: middle of the largest circular gap between markers.
double choose_roll(const FlatSegment& s, const std::vector<ImageMarker>& markers) {
  if (s.map == "disk") return s.y0;  // a disk band (flatten's disk_map.h) does not wrap around: never rolled
  std::vector<double> ys;
  for (const auto& m : markers)
    if (m.segment == s.id) ys.push_back(std::fmod(std::fmod(m.y - s.y0, s.period) + s.period, s.period));
  if (ys.empty()) return s.y0;
  std::sort(ys.begin(), ys.end());
  double best_gap = -1, best = 0;
  for (std::size_t i = 0; i < ys.size(); ++i) {
    const double a = ys[i], b = i + 1 < ys.size() ? ys[i + 1] : ys[0] + s.period;
    if (b - a > best_gap) best_gap = b - a, best = 0.5 * (a + b);
  }
  return s.y0 + std::fmod(best, s.period);
}

}  // namespace

std::mutex& freetype_mutex() {
  static std::mutex m;
  return m;
}

namespace {

// Bold Arial of `font_size` in `color` on a black background of `bg_opacity` (0: none).
void set_text_property(vtkTextProperty* tp, int font_size, const double color[3], double bg_opacity) {
  tp->SetFontSize(font_size);
  tp->SetColor(color[0], color[1], color[2]);
  tp->SetFontFamilyToArial();
  tp->SetBold(1);
  if (bg_opacity > 0) {
    tp->SetBackgroundColor(0, 0, 0);
    tp->SetBackgroundOpacity(bg_opacity);
  }
}

// The text rendered by FreeType into `t` (RGBA); returns its size in pixels. Pre: freetype_mutex() held.
std::array<int, 2> render_text(vtkImageData* t, const std::string& text, int font_size, const double color[3],
                               double bg_opacity) {
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  if (!tr) throw Error("no FreeType text renderer in this VTK build");
  vtkNew<vtkTextProperty> tp;
  set_text_property(tp, font_size, color, bg_opacity);
  int dims[2];
  if (!tr->RenderString(tp, text, t, dims, 72)) throw Error("cannot render text '" + text + "'");
  return {dims[0], dims[1]};
}

}  // namespace

// Measured with FreeType's bounding box (no glyphs rendered): the extent RenderString fills.
std::array<int, 2> text_size(const std::string& text, int font_size, double bg_opacity) {
  const std::lock_guard<std::mutex> lock(freetype_mutex());
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  if (!tr) throw Error("no FreeType text renderer in this VTK build");
  vtkNew<vtkTextProperty> tp;
  const double white[3] = {1, 1, 1};
  set_text_property(tp, font_size, white, bg_opacity);
  int bbox[4];
  if (!tr->GetBoundingBox(tp, text, bbox, 72)) throw Error("cannot measure text '" + text + "'");
  return {bbox[1] - bbox[0] + 1, bbox[3] - bbox[2] + 1};
}

std::array<int, 2> draw_text(vtkImageData* rgb, const std::string& text, int x, int y_top, int font_size,
                             const double color[3], double bg_opacity) {
  const std::lock_guard<std::mutex> lock(freetype_mutex());
  vtkNew<vtkImageData> t;
  const std::array<int, 2> dims = render_text(t, text, font_size, color, bg_opacity);
  int te[6], ie[6];
  t->GetExtent(te);
  rgb->GetExtent(ie);
  const int H = ie[3] - ie[2] + 1;
  auto* src = static_cast<unsigned char*>(t->GetScalarPointer());
  auto* dst = static_cast<unsigned char*>(rgb->GetScalarPointer());
  const int tw = te[1] - te[0] + 1;
  const int nc = t->GetNumberOfScalarComponents();
  const int W = ie[1] - ie[0] + 1;
  for (int j = 0; j < dims[1]; ++j)
    for (int i = 0; i < dims[0]; ++i) {
      const int X = x + i, Yrow = H - 1 - (y_top + (dims[1] - 1 - j));
      if (X < 0 || X >= W || Yrow < 0 || Yrow >= H) continue;
      const unsigned char* s = src + (std::size_t(j) * tw + i) * nc;
      const double a = nc == 4 ? s[3] / 255.0 : 1.0;
      unsigned char* d = dst + (std::size_t(Yrow) * W + X) * 3;
      for (int k = 0; k < 3; ++k) d[k] = static_cast<unsigned char>(std::lround((1 - a) * d[k] + a * s[k]));
    }
  return dims;
}

ColonImageGeometry colon_image_geometry(const FlatMap& flat, double pixel_size, int max_width) {
  ColonImageGeometry g;
  double max_length = 0;
  for (const auto& s : flat.segments) max_length = std::max(max_length, s.length);
  g.pixel_size = max_length / pixel_size > max_width ? max_length / max_width : pixel_size;
  int rows = kBottom, width = kMinWidth;
  for (int i = int(flat.segments.size()) - 1; i >= 0; --i) {
    const FlatSegment& s = flat.segments[i];
    ColonImageBand b;
    b.segment = i;
    b.w = std::max(1, int(std::ceil(s.length / g.pixel_size)));
    b.h = std::max(1, int(std::ceil(s.period / g.pixel_size)));
    b.col0 = kMargin;
    b.row_bottom = rows;
    rows += b.h + kGap;
    width = std::max(width, b.w + 2 * kMargin);
    g.bands.push_back(b);
  }
  g.width = width;
  g.height = rows - kGap + kTop;
  return g;
}

namespace detail {

ColonImagePainter::ColonImagePainter(const FlatMap& flat, const std::vector<double>& shape_index,
                                     std::vector<ImageMarker>& markers, const ColonImageOptions& opts)
    : flat_(flat), shape_index_(shape_index), markers_(markers), opts_(opts) {}

ColonImage ColonImagePainter::run() {
  lay_out_bands();
  fill_background();
  for (const Band& band : bands_) paint_band(band);
  compose_overlays();
  write_scale_text();
  write_band_captions();
  write_legend_and_title();
  write_labels();
  out_.image = image_;
  return out_;
}

// The bands where colon_image_geometry puts them, each rolled away from its markers.
void ColonImagePainter::lay_out_bands() {
  const ColonImageGeometry geo = colon_image_geometry(flat_, opts_.pixel_size, opts_.max_width);
  px_ = geo.pixel_size;
  width_ = geo.width;
  height_ = geo.height;
  margin_ = kMargin;
  out_.pixel_size = px_;
  out_.width = width_;
  out_.height = height_;
  out_.roll.assign(flat_.segments.size(), 0);
  vertex_ratio_ = vertex_area_ratio(flat_);
  for (const ColonImageBand& g : geo.bands) {
    Band b;
    b.seg = g.segment;
    b.w = g.w;
    b.h = g.h;
    b.col0 = g.col0;
    b.row0 = g.row_bottom;
    b.c0 = choose_roll(flat_.segments[g.segment], markers_);
    bands_.push_back(b);
  }
}

// An RGB image of the final size, dark grey (28) everywhere.
void ColonImagePainter::fill_background() {
  image_ = ImagePtr::New();
  image_->SetExtent(0, width_ - 1, 0, height_ - 1, 0, 0);
  image_->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  pixels_ = static_cast<unsigned char*>(image_->GetScalarPointer());
  std::fill(pixels_, pixels_ + std::size_t(width_) * height_ * 3, static_cast<unsigned char>(28));
}

const Band* ColonImagePainter::band_of(int segment) const {
  const Band* found = nullptr;
  for (const auto& b : bands_)
    if (b.seg == segment) found = &b;
  return found;
}

double ColonImagePainter::rolled_y(const Band& band, double y) const {
  const FlatSegment& s = flat_.segments[band.seg];
  return std::fmod(std::fmod(y - band.c0, s.period) + s.period, s.period);
}

std::array<double, 2> ColonImagePainter::pixel_of(const Band& band, double x, double y) const {
  const FlatSegment& s = flat_.segments[band.seg];
  return {band.col0 + (x - s.x0) / px_, band.row0 + rolled_y(band, y) / px_};
}

}  // namespace detail

ColonImage render_colon_image(const FlatMap& f, const std::vector<double>& si, std::vector<ImageMarker>& markers,
                              const ColonImageOptions& o) {
  if (o.color != "shading" && o.color != "curvature")
    throw UsageError("--color must be shading or curvature (got '" + o.color + "')");
  return detail::ColonImagePainter(f, si, markers, o).run();
}

}  // namespace cf
