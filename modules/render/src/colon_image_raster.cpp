// render_colon_image, steps 2-3: each band's triangles rasterised at the pixel centres and every
// pixel shaded from its 3D normal (or hatched where the wall is missing or compressed).
#include <vtkImageData.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/triangle_raster.h"
#include "colonflat/render/image_smooth.h"
#include "colon_image_steps.h"

namespace cf::detail {

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

void colour_of_shape_index(double si, double rgb[3]) {
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

// One band: rasterise, smooth the view normals, then shade (or hatch) each pixel into the image,
// rows split over the threads (each pixel depends only on the probed band, so any count gives the
// same image).
void ColonImagePainter::paint_band(const Band& b) {
  const FlatSegment& s = flat_.segments[b.seg];
  out_.roll[b.seg] = b.c0;
  const ProbedBand probed = probe_band(b, rolled_segment(s, b.c0));
  ImagePtr view = view_normals(b, probed);
  ImagePtr mean = smoothed_normals(view);
  const auto* vnp = static_cast<const double*>(view->GetScalarPointer());
  const auto* mp = static_cast<const double*>(mean->GetScalarPointer());
  const int chunks = std::max(1, std::min(thread_count(), b.h));
  std::vector<std::array<std::size_t, 2>> counts(chunks, {0, 0});
  parallel_for(std::size_t(chunks), [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      paint_rows(b, probed, vnp, mp, int(b.h * c / chunks), int(b.h * (c + 1) / chunks), counts[c].data());
  });
  for (const auto& c : counts) out_.compressed_pixels += c[0], out_.missing_pixels += c[1];
}

// Rows [j0, j1) of a band; counts[0] += compressed pixels, counts[1] += missing pixels.
void ColonImagePainter::paint_rows(const Band& b, const ProbedBand& probed, const double* view, const double* mean,
                                   int j0, int j1, std::size_t counts[2]) const {
  const FlatSegment& s = flat_.segments[b.seg];
  for (int j = j0; j < j1; ++j)
    for (int i = 0; i < b.w; ++i) {
      const vtkIdType id = vtkIdType(j) * b.w + i;
      unsigned char* d = pixels_ + (std::size_t(b.row0 + j) * width_ + b.col0 + i) * 3;
      const bool stripe = ((i + j) / 4) % 2 == 0;  // diagonal hatching, 4 px stripes
      const bool past_edge = (i + 0.5) * px_ > s.length || (j + 0.5) * px_ > s.period;  // the last column / row (rounding)
      if (!probed.valid[id] && (past_edge || s.map == "disk")) continue;  // a disk band's box outside the disk: no wall
      if (!probed.valid[id]) {
        hatch_missing(stripe, d);
        ++counts[1];
        continue;
      }
      const PixelGeometry g = pixel_geometry(b, probed, view, mean, i, j);
      counts[0] += shade_pixel(g, probed.shape_index[id], probed.ratio[id], stripe, d);
    }
}

// The triangles of one segment with y rolled into [c0, c0 + P), plus copies across the cut.
std::vector<RolledTriangle> ColonImagePainter::rolled_segment(const FlatSegment& s, double c0) const {
  const FlatMap& f = flat_;
  const double P = s.period;
  std::vector<RolledTriangle> rolled;
  for (std::size_t ti = 0; ti < f.triangles.size(); ++ti) {
    const auto& t = f.triangles[ti];
    if (f.segment[t[0]] != s.id) continue;
    const double cy = (f.uv[t[0]][1] + f.uv[t[1]][1] + f.uv[t[2]][1]) / 3;
    const int k = int(std::floor((cy - c0) / P));
    const double ymin = std::min({f.uv[t[0]][1], f.uv[t[1]][1], f.uv[t[2]][1]}) - k * P;
    const double ymax = std::max({f.uv[t[0]][1], f.uv[t[1]][1], f.uv[t[2]][1]}) - k * P;
    for (int extra : {0, -1, 1}) {
      if (extra == -1 && ymax < c0 + P) continue;  // crosses the top: copy one period down
      if (extra == 1 && ymin > c0) continue;       // crosses the bottom: copy one period up
      rolled.push_back({int(ti), extra - k});
    }
  }
  return rolled;
}

// The rolled triangles sampled at the band's pixel centres: the flat map's normal, position,
// shape index and area ratio interpolated linearly in the covering triangle (core rasteriser).
ProbedBand ColonImagePainter::probe_band(const Band& b, const std::vector<RolledTriangle>& rolled) const {
  const FlatMap& f = flat_;
  const FlatSegment& s = f.segments[b.seg];
  const RasterGrid grid{s.x0 + 0.5 * px_, b.c0 + 0.5 * px_, px_, b.w, b.h};
  const std::vector<RasterHit> hits = rasterise_triangles(grid, rolled.size(), [&](std::size_t r) {
    const auto& t = f.triangles[rolled[r].t];
    const double shift = rolled[r].periods * s.period;
    return std::array<std::array<double, 2>, 3>{{{f.uv[t[0]][0], f.uv[t[0]][1] + shift},
                                                 {f.uv[t[1]][0], f.uv[t[1]][1] + shift},
                                                 {f.uv[t[2]][0], f.uv[t[2]][1] + shift}}};
  });
  ProbedBand r;
  const std::size_t n = hits.size();
  r.valid.assign(n, 0);
  r.normal.assign(3 * n, 0.0);
  r.position.assign(3 * n, 0.0);
  r.shape_index.assign(n, 0.0);
  r.ratio.assign(n, 0.0);
  parallel_for(n, [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) interpolate_hit(hits[i], rolled, r, i);
  });
  return r;
}

// Pixel i of `r` from its raster hit: the corner values weighted by the centre's barycentrics.
void ColonImagePainter::interpolate_hit(const RasterHit& h, const std::vector<RolledTriangle>& rolled, ProbedBand& r,
                                        std::size_t i) const {
  if (h.triangle < 0) return;
  const auto& t = flat_.triangles[rolled[h.triangle].t];
  r.valid[i] = 1;
  for (int c = 0; c < 3; ++c) {
    const int v = t[c];
    const double w = h.weight[c];
    for (int k = 0; k < 3; ++k) {
      r.normal[3 * i + k] += w * flat_.normal[v][k];
      r.position[3 * i + k] += w * flat_.position[v][k];
    }
    r.shape_index[i] += w * (shape_index_.empty() ? 0.0 : shape_index_[v]);
    r.ratio[i] += w * vertex_ratio_[v];
  }
}

// Unit normal into the lumen per pixel (0 where no wall), as a 3-component double image.
ImagePtr ColonImagePainter::view_normals(const Band& b, const ProbedBand& probed) const {
  ImagePtr vn = ImagePtr::New();
  vn->SetDimensions(b.w, b.h, 1);
  vn->AllocateScalars(VTK_DOUBLE, 3);
  auto* vnp = static_cast<double*>(vn->GetScalarPointer());
  const vtkIdType n = vtkIdType(b.w) * b.h;
  for (vtkIdType i = 0; i < n; ++i) {
    const double* q = &probed.normal[3 * i];
    const double l = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    for (int k = 0; k < 3; ++k) vnp[3 * i + k] = probed.valid[i] && l > 0 ? -q[k] / l : 0.0;
  }
  return vn;
}

// The large-scale wall normal: view normals Gaussian-smoothed with sigma smooth_normal (mm), on a
// coarser grid where sigma spans many pixels (smooth_large_scale).
ImagePtr ColonImagePainter::smoothed_normals(vtkImageData* view) const {
  return smooth_large_scale(view, std::max(1.0, opts_.smooth_normal / px_));
}

// The tangent along the colon from the 3D positions of the neighbouring pixels (the pixel itself
// where a neighbour has no wall).
PixelGeometry ColonImagePainter::pixel_geometry(const Band& b, const ProbedBand& probed, const double* view,
                                                const double* mean, int i, int j) const {
  const vtkIdType id = vtkIdType(j) * b.w + i;
  PixelGeometry g;
  g.view = view + 3 * id;
  for (int k = 0; k < 3; ++k) g.mean[k] = mean[3 * id + k];
  const vtkIdType ia = j * b.w + std::max(0, i - 1), ib = j * b.w + std::min(b.w - 1, i + 1);
  const double* pa = &probed.position[3 * (probed.valid[ia] ? ia : id)];
  const double* pb = &probed.position[3 * (probed.valid[ib] ? ib : id)];
  for (int k = 0; k < 3; ++k) g.tangent[k] = pb[k] - pa[k];
  return g;
}

// Diffuse + specular shading against a light tilted from the large-scale normal towards the colon
// axis; curvature colouring and blue hatching (compressed wall) on top.
bool ColonImagePainter::shade_pixel(const PixelGeometry& g, double shape_index, double ratio, bool stripe,
                                    unsigned char* d) const {
  const double* v = g.view;
  const double* m = g.mean;
  const double* t = g.tangent;
  const double mn = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const double tn = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  double L[3];
  for (int k = 0; k < 3; ++k) L[k] = (mn > 0 ? m[k] / mn : v[k]) + (tn > 0 ? -opts_.light_tilt * t[k] / tn : 0.0);
  const double ln = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
  const double diff = std::max(0.0, (v[0] * L[0] + v[1] * L[1] + v[2] * L[2]) / ln);
  const double shade = 0.22 + 0.78 * diff;
  const double spec = 0.18 * std::pow(diff, 24);
  double base[3] = {0.90, 0.58, 0.52};
  if (opts_.color == "curvature") {
    double c[3];
    colour_of_shape_index(shape_index, c);
    for (int k = 0; k < 3; ++k) base[k] = 0.35 * base[k] + 0.65 * c[k];
  }
  const bool compressed = ratio < opts_.compressed_ratio;
  for (int k = 0; k < 3; ++k) {
    double val = 255.0 * (base[k] * shade + spec);
    if (compressed && stripe) val = 0.45 * val + 0.55 * 255.0 * (k == 2 ? 1.0 : k == 1 ? 0.9 : 0.2);
    d[k] = static_cast<unsigned char>(std::clamp(val, 0.0, 255.0));
  }
  return compressed;
}

// Wall not in the map: hatched dark red.
void ColonImagePainter::hatch_missing(bool stripe, unsigned char* d) {
  d[0] = stripe ? 120 : 40, d[1] = d[2] = stripe ? 20 : 10;
}

}  // namespace cf::detail
