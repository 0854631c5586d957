#include "colonflat/register/side_by_side.h"

#include <vtkImageCanvasSource2D.h>
#include <vtkImageData.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "colonflat/render/colon_image.h"

namespace cf {
namespace {

constexpr double kTwoPi = 6.283185307179586;
constexpr int kLeft = 90, kRight = 30, kTitle = 40, kGap = 70, kAxis = 60;

struct Layout {
  double pixel = 1;
  int width = 0, height = 0, band = 0, band_cols = 0;
  int supine_top = kTitle, prone_top = 0;
  int column(double s) const { return kLeft + int(std::lround(s / pixel)); }
  int row(int top, double theta) const { return top + int(std::lround(theta / kTwoPi * band)) % band; }
};

Layout make_layout(const ColonRegistration& reg, const SideBySideOptions& o) {
  Layout l;
  const double length = reg.supine_coordinates().profile.length_mm();
  l.pixel = std::max(o.pixel_mm, length / std::max(100, o.max_width - kLeft - kRight));
  l.band_cols = int(std::ceil(length / l.pixel));
  l.band = std::clamp(int(std::lround(kTwoPi * reg.supine_coordinates().mean_radius_mm / l.pixel)), 60, 400);
  l.prone_top = l.supine_top + l.band + kGap;
  l.width = kLeft + l.band_cols + kRight;
  l.height = l.prone_top + l.band + kAxis;
  return l;
}

// Grey level of a wall vertex seen from the lumen, lit from the centre line and slightly along +s.
double shade(const ColonScan& scan, const ScanCoordinates& c, int v) {
  const LengthProfile& p = c.profile;
  const int k = p.bin_of(c.s[size_t(v)]);
  const Eigen::Vector3d& t = p.tangent[size_t(k)];
  Eigen::Vector3d inward = p.centre[size_t(k)] - scan.lps[size_t(v)];
  inward -= inward.dot(t) * t;
  const Eigen::Vector3d light = (inward.normalized() + 0.8 * t).normalized();
  const Eigen::Vector3d& n = scan.normal[size_t(v)];
  if (n.squaredNorm() < 0.5) return 0.8;
  return 0.25 + 0.75 * std::max(0.0, -n.dot(light));
}

constexpr double kWall[3] = {235, 170, 150}, kUnaligned[3] = {170, 90, 230};

// Per image column: the alignment has support there (the supine bin is within
// max_unsupported_mm of a supported bin, support.h).
std::vector<char> aligned_columns(const ColonRegistration& reg, const Layout& l) {
  std::vector<char> out(size_t(l.band_cols), 1);
  for (int col = 0; col < l.band_cols; ++col)
    out[size_t(col)] = reg.support_gap_mm(true, (col + 0.5) * l.pixel) <= reg.options().max_unsupported_mm;
  return out;
}

void paint_bands(const ColonRegistration& reg, const Layout& l, vtkImageData* img) {
  auto* px = static_cast<unsigned char*>(img->GetScalarPointer());
  const auto& cs = reg.supine_coordinates();
  const auto& cp = reg.prone_coordinates();
  const double tolerance = 2 * l.pixel + 3;
  const std::vector<char> aligned = aligned_columns(reg, l);
  for (int col = 0; col < l.band_cols; ++col)
    for (int r = 0; r < l.band; ++r) {
      const double s = (col + 0.5) * l.pixel, theta = (r + 0.5) * kTwoPi / l.band;
      double s2, t2;
      reg.map_coordinates(Direction::kSupineToProne, s, theta, s2, t2);
      const int vs = reg.vertex_at(true, s, theta), vp = reg.vertex_at(false, s2, t2);
      const double gs = vs >= 0 && std::abs(cs.s[size_t(vs)] - s) < tolerance ? shade(reg.supine(), cs, vs) : -1;
      const double gp = vp >= 0 && std::abs(cp.s[size_t(vp)] - s2) < tolerance ? shade(reg.prone(), cp, vp) : -1;
      // Where the alignment has no support: wall tinted violet with diagonal stripes, in both bands.
      const bool hatch = !aligned[size_t(col)] && (col + r) % 14 < 4;
      for (int band = 0; band < 2; ++band) {
        const double g = band == 0 ? gs : gp;
        const int row = (band == 0 ? l.supine_top : l.prone_top) + r;
        unsigned char* d = px + (size_t(l.height - 1 - row) * size_t(l.width) + size_t(kLeft + col)) * 3;
        const double* rgb = aligned[size_t(col)] ? kWall : kUnaligned;
        for (int c = 0; c < 3; ++c)
          d[c] = hatch ? (unsigned char)kUnaligned[c] : g < 0 ? 70 : (unsigned char)std::lround(std::clamp(g, 0.0, 1.0) * rgb[c]);
      }
    }
}

struct Marker {
  int x, row, radius, id;
  bool supine;
  std::string label;
};

void ring(vtkImageCanvasSource2D* canvas, const Layout& l, const Marker& m) {
  const int y = l.height - 1 - m.row;
  for (int k = 0; k < 24; ++k) {
    const double a0 = kTwoPi * k / 24, a1 = kTwoPi * (k + 1) / 24;
    canvas->FillTube(int(m.x + m.radius * std::cos(a0)), int(y + m.radius * std::sin(a0)),
                     int(m.x + m.radius * std::cos(a1)), int(y + m.radius * std::sin(a1)), 1.2);
  }
}

// Each candidate of both scans at its place on the supine length axis (prone ones mapped over): the
// place it was matched at (candidate_place()).
std::vector<Marker> place_markers(const ColonRegistration& reg, const Layout& l) {
  std::vector<Marker> marks;
  auto place = [&](const ScanCandidate& c, bool supine) {
    auto [s, theta] = reg.candidate_place(c.id, supine ? Direction::kSupineToProne : Direction::kProneToSupine);
    if (std::isnan(s)) return;
    if (!supine) reg.map_coordinates(Direction::kProneToSupine, s, theta, s, theta);
    const int radius = std::max(4, int(std::lround(0.5 * c.size_mm / l.pixel)) + 3);
    marks.push_back({l.column(s), l.row(supine ? l.supine_top : l.prone_top, theta), radius, c.id, supine,
                     (supine ? "S" : "P") + std::to_string(c.id)});
  };
  for (const auto& c : reg.supine().candidates) place(c, true);
  for (const auto& c : reg.prone().candidates) place(c, false);
  return marks;
}

// Green links between paired candidates, green rings on paired ones, orange on the others, and the
// 100 mm ticks of the length axis.
void draw_matches(vtkImageCanvasSource2D* canvas, const ColonRegistration& reg, const Layout& l,
                  const std::vector<Marker>& marks) {
  auto find = [&](int id, bool supine) -> const Marker* {
    for (const auto& m : marks)
      if (m.supine == supine && m.id == id) return &m;
    return nullptr;
  };
  canvas->SetDrawColor(60, 230, 90);
  for (const auto& p : reg.matching().pairs) {
    const Marker *a = find(p.supine_id, true), *b = find(p.prone_id, false);
    if (a && b) canvas->FillTube(a->x, l.height - 1 - a->row, b->x, l.height - 1 - b->row, 1.0);
  }
  for (const auto& m : marks) {
    bool paired = false;
    for (const auto& p : reg.matching().pairs) paired |= (m.supine ? p.supine_id : p.prone_id) == m.id;
    if (paired) canvas->SetDrawColor(60, 230, 90);
    else canvas->SetDrawColor(255, 150, 0);
    ring(canvas, l, m);
  }
  canvas->SetDrawColor(255, 255, 255);
  for (int s = 0; s <= int(l.band_cols * l.pixel); s += 100)
    canvas->FillBox(l.column(s), l.column(s) + 1, kAxis - 22, kAxis - 12);
}

// Title, band names, axis numbers and caption, marker labels and the legend.
void write_text(vtkImageData* out, const ColonRegistration& reg, const Layout& l, const std::vector<Marker>& marks) {
  const double white[3] = {1, 1, 1}, orange[3] = {1, 0.6, 0};
  draw_text(out, "Supine / prone on one length axis", kLeft, 10, 15, white);
  draw_text(out, "supine", 8, l.supine_top + l.band / 2 - 8, 15, white);
  draw_text(out, "prone", 8, l.prone_top + l.band / 2 - 8, 15, white);
  for (int s = 0; s <= int(l.band_cols * l.pixel); s += 100)
    draw_text(out, std::to_string(s), l.column(s) - 8, l.height - kAxis + 14, 12, white);
  draw_text(out, "mm along the colon (supine axis); rows: angle around it, anterior at the top of each band", kLeft,
            l.height - 24, 12, white);
  for (const auto& m : marks) draw_text(out, m.label, m.x + m.radius + 2, m.row - m.radius - 10, 12, white);
  std::ostringstream legend;
  legend << reg.matching().pairs.size() << " matched pairs (green), " << reg.matching().supine_only.size()
         << " supine-only and " << reg.matching().prone_only.size() << " prone-only candidates (orange)";
  draw_text(out, legend.str(), kLeft, l.prone_top - kGap / 2 - 8, 13, orange);
  const auto& gaps = reg.support().unsupported;
  if (!gaps.empty()) {
    const double violet[3] = {0.75, 0.5, 1.0};
    std::ostringstream text;
    text << "violet, striped: not aligned (no wall of the other scan there, or the colons too far apart): ";
    for (size_t k = 0; k < gaps.size() && k < 6; ++k)
      text << (k ? ", " : "") << std::lround(gaps[k].first) << "-" << std::lround(gaps[k].second) << " mm";
    if (gaps.size() > 6) text << " ...";
    draw_text(out, text.str(), kLeft, l.prone_top - kGap / 2 + 10, 12, violet);
  }
}

}  // namespace

SideBySideMarks side_by_side_marks(const ColonRegistration& reg, const SideBySideOptions& opts) {
  const Layout l = make_layout(reg, opts);
  SideBySideMarks out{l.width, l.height, {}};
  for (const Marker& m : place_markers(reg, l)) out.marks.push_back({m.id, m.supine, m.x, m.row, m.radius});
  return out;
}

vtkSmartPointer<vtkImageData> render_side_by_side(const ColonRegistration& reg, const SideBySideOptions& o) {
  const Layout l = make_layout(reg, o);
  vtkNew<vtkImageData> bands;
  bands->SetExtent(0, l.width - 1, 0, l.height - 1, 0, 0);
  bands->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  std::fill_n(static_cast<unsigned char*>(bands->GetScalarPointer()), size_t(l.width) * l.height * 3, (unsigned char)25);
  paint_bands(reg, l, bands);
  vtkNew<vtkImageCanvasSource2D> canvas;
  canvas->SetScalarTypeToUnsignedChar();
  canvas->SetNumberOfScalarComponents(3);
  canvas->SetExtent(0, l.width - 1, 0, l.height - 1, 0, 0);
  canvas->DrawImage(0, 0, bands);
  const std::vector<Marker> marks = place_markers(reg, l);
  draw_matches(canvas, reg, l, marks);
  canvas->Update();
  auto out = vtkSmartPointer<vtkImageData>::New();
  out->DeepCopy(canvas->GetOutput());
  write_text(out, reg, l, marks);
  return out;
}

}  // namespace cf
