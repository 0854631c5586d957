#include "colonflat/render/colon_image.h"

#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkRenderingFreeType);

#include <vtkCellArray.h>
#include <vtkCharArray.h>
#include <vtkDoubleArray.h>
#include <vtkImageCanvasSource2D.h>
#include <vtkImageData.h>
#include <vtkImageGaussianSmooth.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProbeFilter.h>
#include <vtkStaticCellLocator.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {
namespace {

// The image's margins (pixels): left/right, above the top band (title), between bands (labels),
// below the bottom band (ticks, scale bar, legend); and the narrowest image.
constexpr int kMargin = 30, kTop = 70, kGap = 64, kBottom = 90, kMinWidth = 400;

struct Band {
  int seg = 0;
  int w = 0, h = 0;   // pixels
  int col0 = 0;       // left column in the image
  int row0 = 0;       // bottom row in VTK image coordinates
  double c0 = 0;      // roll: y of the cut (mm)
};

// Picks the cut position of a segment: middle of the largest circular gap between markers.
double choose_roll(const FlatSegment& s, const std::vector<ImageMarker>& markers) {
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

// The triangles of one segment with y rolled into [c0, c0 + P), plus copies across the cut.
vtkSmartPointer<vtkPolyData> rolled_segment(const FlatMap& f, const FlatSegment& s, double c0,
                                            const std::vector<double>& si, const std::vector<double>& ratio) {
  const double P = s.period;
  std::map<std::pair<int, int>, vtkIdType> ids;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> nrm, pos, shp;
  nrm->SetName("n");
  nrm->SetNumberOfComponents(3);
  pos->SetName("p");
  pos->SetNumberOfComponents(3);
  shp->SetName("si");
  vtkNew<vtkDoubleArray> rat;
  rat->SetName("ratio");
  vtkNew<vtkCellArray> polys;
  auto vid = [&](int v, int k) {
    auto it = ids.find({v, k});
    if (it != ids.end()) return it->second;
    const vtkIdType id = pts->InsertNextPoint(f.uv[v][0], f.uv[v][1] + k * P, 0.0);
    nrm->InsertNextTuple(f.normal[v].data());
    pos->InsertNextTuple(f.position[v].data());
    shp->InsertNextValue(si.empty() ? 0.0 : si[v]);
    rat->InsertNextValue(ratio[v]);
    ids.emplace(std::make_pair(v, k), id);
    return id;
  };
  for (const auto& t : f.triangles) {
    if (f.segment[t[0]] != s.id) continue;
    const double cy = (f.uv[t[0]][1] + f.uv[t[1]][1] + f.uv[t[2]][1]) / 3;
    const int k = int(std::floor((cy - c0) / P));
    const double ymin = std::min({f.uv[t[0]][1], f.uv[t[1]][1], f.uv[t[2]][1]}) - k * P;
    const double ymax = std::max({f.uv[t[0]][1], f.uv[t[1]][1], f.uv[t[2]][1]}) - k * P;
    for (int extra : {0, -1, 1}) {
      if (extra == -1 && ymax < c0 + P) continue;  // crosses the top: copy one period down
      if (extra == 1 && ymin > c0) continue;       // crosses the bottom: copy one period up
      const int kk = -k + (extra == -1 ? -1 : extra == 1 ? 1 : 0);
      vtkIdType c[3] = {vid(t[0], kk), vid(t[1], kk), vid(t[2], kk)};
      polys->InsertNextCell(3, c);
    }
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  pd->GetPointData()->AddArray(nrm);
  pd->GetPointData()->AddArray(pos);
  pd->GetPointData()->AddArray(shp);
  pd->GetPointData()->AddArray(rat);
  return pd;
}

// Per flat vertex: the smallest 2D/3D area ratio of its triangles, at each segment's
// area-preserving scale (1 = true size; small = strongly compressed on the image).
std::vector<double> vertex_area_ratio(const FlatMap& f) {
  std::vector<double> a2(f.triangles.size()), a3(f.triangles.size());
  std::vector<double> seg2(f.segments.size(), 0.0), seg3(f.segments.size(), 0.0);
  for (std::size_t i = 0; i < f.triangles.size(); ++i) {
    const auto& t = f.triangles[i];
    const auto &q0 = f.uv[t[0]], &q1 = f.uv[t[1]], &q2 = f.uv[t[2]];
    a2[i] = 0.5 * ((q1[0] - q0[0]) * (q2[1] - q0[1]) - (q1[1] - q0[1]) * (q2[0] - q0[0]));
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) e1[k] = f.position[t[1]][k] - f.position[t[0]][k], e2[k] = f.position[t[2]][k] - f.position[t[0]][k];
    a3[i] = 0.5 * std::sqrt(std::pow(e1[1] * e2[2] - e1[2] * e2[1], 2) + std::pow(e1[2] * e2[0] - e1[0] * e2[2], 2) +
                            std::pow(e1[0] * e2[1] - e1[1] * e2[0], 2));
    seg2[f.segment[t[0]]] += std::abs(a2[i]);
    seg3[f.segment[t[0]]] += a3[i];
  }
  std::vector<double> r(f.uv.size(), 1e9);
  for (std::size_t i = 0; i < f.triangles.size(); ++i) {
    const int sg = f.segment[f.triangles[i][0]];
    const double scale = seg2[sg] > 0 ? seg3[sg] / seg2[sg] : 1.0;
    const double q = a3[i] > 1e-12 ? a2[i] * scale / a3[i] : 1.0;
    for (int v : f.triangles[i]) r[v] = std::min(r[v], q);
  }
  return r;
}

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

void colour_of_si(double si, double rgb[3]) {
  // cup/rut blue -> saddle pale -> ridge yellow -> cap red
  struct Stop { double s, r, g, b; };
  static const Stop stops[] = {{-1, 0.25, 0.35, 0.85}, {-0.5, 0.45, 0.6, 0.9}, {0, 0.92, 0.85, 0.8},
                               {0.5, 0.95, 0.8, 0.3}, {0.85, 0.95, 0.45, 0.2}, {1, 0.9, 0.1, 0.1}};
  si = std::clamp(si, -1.0, 1.0);
  for (int i = 0; i < 5; ++i)
    if (si <= stops[i + 1].s) {
      const double a = (si - stops[i].s) / (stops[i + 1].s - stops[i].s);
      rgb[0] = stops[i].r + a * (stops[i + 1].r - stops[i].r);
      rgb[1] = stops[i].g + a * (stops[i + 1].g - stops[i].g);
      rgb[2] = stops[i].b + a * (stops[i + 1].b - stops[i].b);
      return;
    }
  rgb[0] = stops[5].r, rgb[1] = stops[5].g, rgb[2] = stops[5].b;
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
std::vector<NotShownMark> not_shown_marks(const FlatMap& f) {
  std::vector<NotShownMark> marks;
  for (const FlatSegment& s : f.segments)
    for (const auto& cl : s.coverage.not_shown) {
      if (cl.area_mm2 < kNotShownMinArea) continue;
      double best = std::numeric_limits<double>::infinity();
      NotShownMark m;
      m.segment = s.id;
      m.area_mm2 = cl.area_mm2;
      for (std::size_t v = 0; v < f.position.size(); ++v) {
        if (f.segment[v] != s.id) continue;
        double d = 0;
        for (int k = 0; k < 3; ++k) d += (f.position[v][k] - cl.centroid_lps_mm[k]) * (f.position[v][k] - cl.centroid_lps_mm[k]);
        if (d < best) best = d, m.x = f.uv[v][0], m.y = f.uv[v][1];
      }
      if (best < std::numeric_limits<double>::infinity()) marks.push_back(m);
    }
  return marks;
}

struct Tick {
  int col = 0, row_bottom = 0, len = 0;  // canvas coordinates (row from the bottom)
  std::string text;
};

// Ticks below each band: every 1 cm (short), 5 cm (medium) and 10 cm (long, labelled in cm) of
// x = centreline distance from the band's x0 end plus the centreline length of earlier segments.
std::vector<Tick> axis_ticks(const FlatMap& f, const std::vector<Band>& bands, double px, int height) {
  (void)height;
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

void draw_text(vtkImageData* rgb, const std::string& text, int x, int y_top, int font_size, const double color[3],
               double bg_opacity) {
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  if (!tr) throw Error("no FreeType text renderer in this VTK build");
  vtkNew<vtkTextProperty> tp;
  tp->SetFontSize(font_size);
  tp->SetColor(color[0], color[1], color[2]);
  tp->SetFontFamilyToArial();
  tp->SetBold(1);
  if (bg_opacity > 0) {
    tp->SetBackgroundColor(0, 0, 0);
    tp->SetBackgroundOpacity(bg_opacity);
  }
  vtkNew<vtkImageData> t;
  int dims[2];
  if (!tr->RenderString(tp, text, t, dims, 72)) throw Error("cannot render text '" + text + "'");
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

ColonImage render_colon_image(const FlatMap& f, const std::vector<double>& si, std::vector<ImageMarker>& markers,
                              const ColonImageOptions& o) {
  if (o.color != "shading" && o.color != "curvature")
    throw UsageError("--color must be shading or curvature (got '" + o.color + "')");
  VtkMessageCapture msgs;
  ColonImage out;
  const ColonImageGeometry geo = colon_image_geometry(f, o.pixel_size, o.max_width);
  const double px = geo.pixel_size;
  const int margin = kMargin, width = geo.width, height = geo.height;
  out.pixel_size = px;
  const std::vector<double> vratio = vertex_area_ratio(f);
  std::vector<Band> bands;
  for (const ColonImageBand& g : geo.bands) {
    Band b;
    b.seg = g.segment;
    b.w = g.w;
    b.h = g.h;
    b.col0 = g.col0;
    b.row0 = g.row_bottom;
    b.c0 = choose_roll(f.segments[g.segment], markers);
    bands.push_back(b);
  }
  out.width = width;
  out.height = height;
  out.roll.assign(f.segments.size(), 0);
  ImagePtr img = ImagePtr::New();
  img->SetExtent(0, width - 1, 0, height - 1, 0, 0);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* pix = static_cast<unsigned char*>(img->GetScalarPointer());
  std::fill(pix, pix + std::size_t(width) * height * 3, static_cast<unsigned char>(28));
  for (const Band& b : bands) {
    const FlatSegment& s = f.segments[b.seg];
    out.roll[b.seg] = b.c0;
    auto pd = rolled_segment(f, s, b.c0, si, vratio);
    vtkNew<vtkImageData> grid;
    grid->SetDimensions(b.w, b.h, 1);
    grid->SetOrigin(s.x0 + 0.5 * px, b.c0 + 0.5 * px, 0);
    grid->SetSpacing(px, px, 1);
    vtkNew<vtkProbeFilter> probe;
    probe->SetInputData(grid);
    probe->SetSourceData(pd);
    vtkNew<vtkStaticCellLocator> loc;
    probe->SetCellLocatorPrototype(loc);
    probe->Update();
    vtkDataSet* res = probe->GetOutput();
    auto* valid = vtkCharArray::SafeDownCast(res->GetPointData()->GetArray(probe->GetValidPointMaskArrayName()));
    vtkDataArray* N = res->GetPointData()->GetArray("n");
    vtkDataArray* Pp = res->GetPointData()->GetArray("p");
    vtkDataArray* S = res->GetPointData()->GetArray("si");
    vtkDataArray* R = res->GetPointData()->GetArray("ratio");
    if (!valid || !N || !Pp || !S || !R) throw Error("rasterising the flat map failed: " + msgs.first_problem());
    const vtkIdType n = vtkIdType(b.w) * b.h;
    // view normal (into the lumen) and its large-scale smoothing
    vtkNew<vtkImageData> vn;
    vn->SetDimensions(b.w, b.h, 1);
    vn->AllocateScalars(VTK_DOUBLE, 3);
    auto* vnp = static_cast<double*>(vn->GetScalarPointer());
    for (vtkIdType i = 0; i < n; ++i) {
      double q[3];
      N->GetTuple(i, q);
      const double l = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      for (int k = 0; k < 3; ++k) vnp[3 * i + k] = valid->GetValue(i) && l > 0 ? -q[k] / l : 0.0;
    }
    vtkNew<vtkImageGaussianSmooth> smooth;
    smooth->SetInputData(vn);
    smooth->SetDimensionality(2);
    const double sd = std::max(1.0, o.smooth_normal / px);
    smooth->SetStandardDeviations(sd, sd, 0);
    smooth->SetRadiusFactors(2.5, 2.5, 0);
    smooth->Update();
    auto* mp = static_cast<double*>(smooth->GetOutput()->GetScalarPointer());
    for (int j = 0; j < b.h; ++j)
      for (int i = 0; i < b.w; ++i) {
        const vtkIdType id = vtkIdType(j) * b.w + i;
        unsigned char* d = pix + (std::size_t(b.row0 + j) * width + b.col0 + i) * 3;
        const bool stripe = ((i + j) / 4) % 2 == 0;  // diagonal hatching, 4 px stripes
        if (!valid->GetValue(id) && (i + 0.5) * px > s.length) continue;  // past the band's end (rounding)
        if (!valid->GetValue(id)) {  // wall not in the map: hatched dark red
          d[0] = stripe ? 120 : 40, d[1] = d[2] = stripe ? 20 : 10;
          ++out.missing_pixels;
          continue;
        }
        const double* v = vnp + 3 * id;
        double m[3] = {mp[3 * id], mp[3 * id + 1], mp[3 * id + 2]};
        // tangent along the colon from the 3D positions of neighbouring pixels
        double pa[3], pb[3];
        const vtkIdType ia = j * b.w + std::max(0, i - 1), ib = j * b.w + std::min(b.w - 1, i + 1);
        Pp->GetTuple(valid->GetValue(ia) ? ia : id, pa);
        Pp->GetTuple(valid->GetValue(ib) ? ib : id, pb);
        double t[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
        const double mn = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        const double tn = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        double L[3];
        for (int k = 0; k < 3; ++k) L[k] = (mn > 0 ? m[k] / mn : v[k]) + (tn > 0 ? -o.light_tilt * t[k] / tn : 0.0);
        const double ln = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
        const double diff = std::max(0.0, (v[0] * L[0] + v[1] * L[1] + v[2] * L[2]) / ln);
        const double shade = 0.22 + 0.78 * diff;
        const double spec = 0.18 * std::pow(diff, 24);
        double base[3] = {0.90, 0.58, 0.52};
        if (o.color == "curvature") {
          double c[3];
          colour_of_si(S->GetTuple1(id), c);
          for (int k = 0; k < 3; ++k) base[k] = 0.35 * base[k] + 0.65 * c[k];
        }
        const bool compressed = R->GetTuple1(id) < o.compressed_ratio;
        if (compressed) ++out.compressed_pixels;
        for (int k = 0; k < 3; ++k) {
          double val = 255.0 * (base[k] * shade + spec);
          if (compressed && stripe) val = 0.45 * val + 0.55 * 255.0 * (k == 2 ? 1.0 : k == 1 ? 0.9 : 0.2);
          d[k] = static_cast<unsigned char>(std::clamp(val, 0.0, 255.0));
        }
      }
  }
  // Overlays with VTK's canvas.
  vtkNew<vtkImageCanvasSource2D> canvas;
  canvas->SetScalarTypeToUnsignedChar();
  canvas->SetNumberOfScalarComponents(3);
  canvas->SetExtent(0, width - 1, 0, height - 1, 0, 0);
  canvas->DrawImage(0, 0, img);
  struct Label {
    std::string text;
    int x, y;
    double col[3];
    int size;
    double bg;
  };
  std::vector<Label> labels;
  for (auto& mk : markers) {
    const Band* bb = nullptr;
    for (const auto& b : bands)
      if (b.seg == mk.segment) bb = &b;
    if (!bb) continue;
    const FlatSegment& s = f.segments[mk.segment];
    double y = std::fmod(std::fmod(mk.y - bb->c0, s.period) + s.period, s.period);
    const double cx = bb->col0 + (mk.x - s.x0) / px, cy = bb->row0 + y / px;
    mk.px = cx;
    mk.py = height - 1 - cy;
    const double r = std::max(6.0, mk.radius_mm / px + 4);
    if (mk.known) canvas->SetDrawColor(60, 230, 90);
    else canvas->SetDrawColor(255, 230, 0);
    const int nseg = 36;
    for (int k = 0; k < nseg; ++k) {
      if (mk.known && k % 2) continue;
      const double a0 = 2 * M_PI * k / nseg, a1 = 2 * M_PI * (k + 1) / nseg;
      canvas->FillTube(int(cx + r * std::cos(a0)), int(cy + r * std::sin(a0)), int(cx + r * std::cos(a1)),
                       int(cy + r * std::sin(a1)), 1.3);
    }
    Label l{mk.label, int(cx + r * 0.75), int(height - 1 - (cy + r * 0.75)) - 16, {1, 0.9, 0}, 14, 0.55};
    if (mk.known) l.col[0] = 0.25, l.col[1] = 0.95, l.col[2] = 0.4, l.y = int(height - 1 - (cy - r * 0.75)) + 2;
    labels.push_back(l);
  }
  canvas->SetDrawColor(255, 60, 60);  // wall not shown: a red square ring, labelled with its area
  for (const NotShownMark& m : not_shown_marks(f)) {
    const Band* bb = nullptr;
    for (const auto& b : bands)
      if (b.seg == m.segment) bb = &b;
    if (!bb) continue;
    const FlatSegment& s = f.segments[m.segment];
    const double y = std::fmod(std::fmod(m.y - bb->c0, s.period) + s.period, s.period);
    const int cx = int(bb->col0 + (m.x - s.x0) / px), cy = int(bb->row0 + y / px), r = 9;
    canvas->FillBox(cx - r, cx + r, cy - r, cy - r + 1);
    canvas->FillBox(cx - r, cx + r, cy + r - 1, cy + r);
    canvas->FillBox(cx - r, cx - r + 1, cy - r, cy + r);
    canvas->FillBox(cx + r - 1, cx + r, cy - r, cy + r);
    labels.push_back({(m.area_mm2 < 1000 ? fmt0(m.area_mm2) + " mm2" : fmt0(m.area_mm2 / 100.0) + " cm2") + " not shown", cx + r + 2, height - 1 - cy - 6, {1, 0.45, 0.45}, 12, 0.55});
  }
  // scale bar (bottom left), in mm at the mean (area-preserving) scale
  const double bar_mm = nice_length(0.12 * (width - 2 * margin) * px);
  const int bar_px = int(std::lround(bar_mm / px));
  canvas->SetDrawColor(255, 255, 255);
  canvas->FillBox(margin, margin + bar_px, 28, 34);
  canvas->FillBox(margin, margin + 2, 22, 40);
  canvas->FillBox(margin + bar_px - 2, margin + bar_px, 22, 40);
  const std::vector<Tick> ticks = axis_ticks(f, bands, px, height);
  canvas->SetDrawColor(230, 230, 230);
  for (const Tick& t : ticks) canvas->FillBox(t.col, t.col + 1, t.row_bottom - t.len, t.row_bottom);
  canvas->Update();
  ImagePtr final_img = ImagePtr::New();
  final_img->DeepCopy(canvas->GetOutput());
  const double white[3] = {1, 1, 1}, grey[3] = {0.85, 0.85, 0.85};
  std::ostringstream sb;
  sb << bar_mm << " mm";
  draw_text(final_img, sb.str(), margin + bar_px + 10, height - 44, 16, white);
  draw_text(final_img, "(scale at the mean, area-preserving map scale; 1 px = " + [&] {
    std::ostringstream q;
    q.precision(2);
    q << px;
    return q.str();
  }() + " mm)", margin + bar_px + 80, height - 42, 12, grey);
  for (const Tick& t : ticks)
    if (!t.text.empty()) draw_text(final_img, t.text, t.col - 4 * int(t.text.size()), height - t.row_bottom + 2, 12, grey);
  const double end_col[3] = {1, 0.85, 0.35};
  for (const Band& b : bands) {
    const FlatSegment& s = f.segments[b.seg];
    const bool along = !s.map.empty() && s.map != "conformal";
    std::string t = "segment " + std::to_string(s.id + 1) + ": " + fmt0(s.length) + " mm long x " + fmt0(s.period) +
                    " mm around; " + s.x0_end + " (left) to " + s.x1_end + " (right); " +
                    (along ? "x axis: cm along the centreline from the " + s.x0_end
                           : "x axis: cm of the conformal map (not centreline length)");
    draw_text(final_img, t, b.col0, height - 1 - (b.row0 + b.h) - 24, 15, grey);
    const int top_row = height - 1 - (b.row0 + b.h) + 4;
    draw_text(final_img, s.x0_end, b.col0 + 4, top_row, 16, end_col, 0.6);
    draw_text(final_img, s.x1_end, b.col0 + b.w - 10 * int(s.x1_end.size()) - 8, top_row, 16, end_col, 0.6);
  }
  draw_text(final_img, "hatched blue: wall compressed below " + fmt2(o.compressed_ratio) +
                           " x its area; hatched red: wall not in the map; red squares: wall the image cannot show (its 3D area)", margin, height - 22, 12, grey);
  std::string title = o.title;
  if (title.empty()) {
    int nc = 0, nk = 0;
    for (const auto& m : markers) (m.known ? nk : nc)++;
    title = "ColonFlat: unrolled colon wall (" +
            (f.segments.empty() || f.segments[0].map.empty() ? std::string("conformal") : f.segments[0].map) + " map), " + std::to_string(nc) + " polyp candidate" +
            (nc == 1 ? "" : "s") + " (yellow)" + (nk ? ", " + std::to_string(nk) + " known polyps (green, dashed)" : "");
  }
  draw_text(final_img, title, margin, 12, 18, white);
  for (const auto& l : labels) draw_text(final_img, l.text, l.x, l.y, l.size, l.col, l.bg);
  out.image = final_img;
  return out;
}

}  // namespace cf
