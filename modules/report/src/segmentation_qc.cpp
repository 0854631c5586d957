// The report's Segmentation section: scan the lumen (volume, box, where it lies along each axis),
// find the bodies segment rejected (from each decision's position: the gas or tagged-fluid voxels
// outside the lumen connected to the nearest such voxel), choose slices through the bodies and the
// lumen, draw the montages (CT in the lung window, lumen outline green, rejected bodies tinted and
// outlined in their reason's colour, a numbered tag at each (qc_tags.h)) and list the kept and
// rejected bodies (the legend: number, reason, volume, slices where seen).
#include "colonflat/report/segmentation_qc.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iterator>
#include <string>
#include <type_traits>

#include "colonflat/core/threads.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/qc_tags.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr std::array<unsigned char, 3> kLumenRgb = {40, 230, 90};
// One colour per rejection reason, in the order reasons first appear (cycled beyond 8); none is
// near the lumen's green, each stands out on the grey CT.
constexpr std::array<unsigned char, 3> kReasonRgb[8] = {{255, 50, 30},  {255, 160, 0},   {230, 60, 230}, {0, 200, 255},
                                                        {255, 235, 60}, {120, 110, 255}, {255, 130, 170}, {190, 130, 60}};

// The colour of the reason with index `reason` (kReasonRgb cycled).
const std::array<unsigned char, 3>& reason_rgb(std::size_t reason) { return kReasonRgb[reason % std::size(kReasonRgb)]; }

std::string css_rgb(const std::array<unsigned char, 3>& c) {
  return "rgb(" + std::to_string(c[0]) + "," + std::to_string(c[1]) + "," + std::to_string(c[2]) + ")";
}

// A montage being drawn: pixels, lumen mask, body number per pixel (0 none), outline masks.
struct SliceCanvas {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb, lum, lumen_edge, body_edge;
  std::vector<int> body;
};

struct QcBody {
  int id = 0;
  nlohmann::json decision;
  std::vector<std::size_t> voxels;  // sorted
  int cls = -1;                     // 0 gas, 1 tagged fluid
  int reason = 0;                   // index of its reason among the bodies' reasons (its colour)
  bool truncated = false, too_large = false;
};

// Each body's "seen": the slices whose montage shows it ({plane, slice (1-based), axis, position_mm}).
void add_seen(nlohmann::json& section) {
  for (const char* plane : {"coronal", "axial", "sagittal"}) {
    int n = 0;
    for (const auto& im : section["planes"][plane]) {
      ++n;
      for (const auto& t : im["tags"]) {
        auto& b = section["bodies"][t["id"].get<std::size_t>() - 1];
        b["seen"].push_back({{"plane", plane}, {"slice", n}, {"axis", im["axis"]}, {"position_mm", im["position_mm"]}});
      }
    }
  }
}

class SegmentationQc {
 public:
  // `ct`: CtImage, or CompactCtImage (the run's CT in 16 bits: the same HU, the same pixels drawn).
  template <class Image>
  SegmentationQc(const Image* ct, const MaskImage* lumen, const nlohmann::json& result, const SegmentationQcOptions& o)
      : ct_(ct), lumen_(lumen), result_(result), o_(o), m_(lumen->GetBufferPointer()),
        sample_([ct](Plane p, double at, double u0, double v0, int w, int h, double pix) { return sample_plane(ct, p, at, u0, v0, w, h, pix); }) {
    if constexpr (std::is_same_v<typename Image::PixelType, float>) huf_ = ct->GetBufferPointer();
    else hus_ = ct->GetBufferPointer();
    const auto sz = ct->GetLargestPossibleRegion().GetSize();
    for (int d = 0; d < 3; ++d) n_[d] = sz[d];
    voxel_ml_ = ct->GetSpacing()[0] * ct->GetSpacing()[1] * ct->GetSpacing()[2] / 1000.0;
  }
  SegmentationQcDrawing run();

 private:
  void thresholds();
  void scan_lumen();
  void find_bodies();
  bool seed_of(const std::array<double, 3>& lps, int cls, std::size_t& seed) const;
  void flood(QcBody& b, std::size_t seed, std::size_t cap);
  int voxel_class(std::size_t q) const {
    if (m_[q]) return -1;
    const float hu = huf_ ? huf_[q] : float(hus_[q]);
    return hu < gas_thr_ ? 0 : hu > fluid_thr_ ? 1 : -1;
  }
  std::array<double, 3> lps_of(std::size_t q) const {
    CtImage::IndexType i = {{long(q % n_[0]), long((q / n_[0]) % n_[1]), long(q / (n_[0] * n_[1]))}};
    CtImage::PointType p;
    ct_->TransformIndexToPhysicalPoint(i, p);
    return {p[0], p[1], p[2]};
  }
  void grow_box(const std::array<double, 3>& p) {
    for (int d = 0; d < 3; ++d) lo_[d] = std::min(lo_[d], p[d]), hi_[d] = std::max(hi_[d], p[d]);
  }
  std::vector<double> slice_positions(Plane p) const;
  void assign_reasons();
  const std::array<unsigned char, 3>& colour(int body_id) const { return reason_rgb(std::size_t(bodies_[std::size_t(body_id - 1)].reason)); }
  nlohmann::json draw(Plane p, double fixed, int n, QcMontage& out) const;
  SliceCanvas paint(Plane p, double fixed) const;
  void outline(SliceCanvas& cv) const;
  nlohmann::json tag(SliceCanvas& cv) const;
  nlohmann::json tables() const;

  const itk::ImageBase<3>* ct_;  // its geometry
  const MaskImage* lumen_;
  const nlohmann::json& result_;
  const SegmentationQcOptions& o_;
  const unsigned char* m_;
  std::function<PlaneImage(Plane, double, double, double, int, int, double)> sample_;  // sample_plane on the CT
  const float* huf_ = nullptr;  // the CT's HU: float, or
  const short* hus_ = nullptr;  // 16 bits
  std::size_t n_[3];
  double voxel_ml_ = 0, gas_thr_ = -500, fluid_thr_ = 200, lumen_ml_ = 0, pix_ = 1;
  std::array<double, 3> lo_{1e300, 1e300, 1e300}, hi_{-1e300, -1e300, -1e300}, hist_lo_{};
  std::array<std::vector<double>, 3> hist_;  // lumen voxels per 1 mm along each LPS axis from hist_lo_
  std::vector<QcBody> bodies_;
  std::vector<std::string> reasons_;  // distinct reasons of the bodies, in order of first appearance
  std::vector<bool> taken_;
  std::vector<std::pair<std::size_t, int>> body_voxels_;  // (voxel, body index + 1), sorted
};

// Gas below the midpoint of segment's air and tissue means, tagged fluid above the midpoint of its
// tissue and fluid means (its own classes); -500 / +200 HU when the run did not report them.
void SegmentationQc::thresholds() {
  const auto m = result_.value("class_means_hu", nlohmann::json::object());
  const double air = m.value("air", 0.0), tissue = m.value("tissue", 0.0), fluid = m.value("fluid", 0.0);
  if (air < tissue && tissue < fluid && air < -300 && fluid > 100) gas_thr_ = 0.5 * (air + tissue), fluid_thr_ = 0.5 * (tissue + fluid);
}

// Lumen volume, LPS box, and per-axis histograms (1 mm bins over the volume's LPS box).
void SegmentationQc::scan_lumen() {
  std::array<double, 3> vlo{1e300, 1e300, 1e300}, vhi{-1e300, -1e300, -1e300};
  for (int c = 0; c < 8; ++c) {
    const std::size_t q = ((c & 1) ? n_[0] - 1 : 0) + n_[0] * (((c & 2) ? n_[1] - 1 : 0) + n_[1] * ((c & 4) ? n_[2] - 1 : 0));
    const auto p = lps_of(q);
    for (int d = 0; d < 3; ++d) vlo[d] = std::min(vlo[d], p[d]), vhi[d] = std::max(vhi[d], p[d]);
  }
  for (int d = 0; d < 3; ++d) hist_lo_[d] = vlo[d], hist_[d].assign(std::size_t(vhi[d] - vlo[d]) + 2, 0.0);
  const std::size_t n = n_[0] * n_[1] * n_[2];
  std::size_t count = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (!m_[q]) continue;
    ++count;
    const auto p = lps_of(q);
    grow_box(p);
    for (int d = 0; d < 3; ++d) hist_[d][std::size_t(p[d] - hist_lo_[d])] += 1;
  }
  lumen_ml_ = count * voxel_ml_;
}

// The voxel of class `cls` (or either, -1) outside the lumen, not yet in a body, whose six
// neighbours are of its class too (no noise speck), nearest to `lps` within search_mm.
bool SegmentationQc::seed_of(const std::array<double, 3>& lps, int cls, std::size_t& seed) const {
  CtImage::PointType p;
  for (int d = 0; d < 3; ++d) p[d] = lps[d];
  itk::ContinuousIndex<double, 3> c;
  ct_->TransformPhysicalPointToContinuousIndex(p, c);
  long lo[3], hi[3];
  for (int d = 0; d < 3; ++d) {
    const double r = o_.search_mm / ct_->GetSpacing()[d];
    lo[d] = std::max(0L, long(std::floor(c[d] - r))), hi[d] = std::min(long(n_[d]) - 1, long(std::ceil(c[d] + r)));
  }
  double best = o_.search_mm * o_.search_mm;
  bool found = false;
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long i = lo[0]; i <= hi[0]; ++i) {
        const std::size_t q = std::size_t(i) + n_[0] * (std::size_t(j) + n_[1] * std::size_t(k));
        const int vc = voxel_class(q);
        if (vc < 0 || (cls >= 0 && vc != cls) || taken_[q]) continue;
        bool interior = i > 0 && j > 0 && k > 0 && i + 1 < long(n_[0]) && j + 1 < long(n_[1]) && k + 1 < long(n_[2]);
        const std::size_t sx = 1, sy = n_[0], sz = n_[0] * n_[1];
        for (std::size_t o : {sx, sy, sz})  // six neighbours of its kind: not a speck of noise
          interior = interior && voxel_class(q - o) == vc && voxel_class(q + o) == vc;
        if (!interior) continue;
        const auto x = lps_of(q);
        const double d2 = (x[0] - lps[0]) * (x[0] - lps[0]) + (x[1] - lps[1]) * (x[1] - lps[1]) + (x[2] - lps[2]) * (x[2] - lps[2]);
        if (d2 <= best) best = d2, seed = q, found = true;
      }
  return found;
}

// 6-connected voxels of the seed's class outside the lumen, at most `cap`.
void SegmentationQc::flood(QcBody& b, std::size_t seed, std::size_t cap) {
  b.cls = voxel_class(seed);
  std::vector<std::size_t> stack{seed};
  taken_[seed] = true;
  const long nx = long(n_[0]), ny = long(n_[1]), nz = long(n_[2]);
  while (!stack.empty()) {
    const std::size_t q = stack.back();
    stack.pop_back();
    b.voxels.push_back(q);
    if (b.voxels.size() >= cap) {
      b.truncated = true;
      break;
    }
    const long i = long(q % n_[0]), j = long((q / n_[0]) % n_[1]), k = long(q / (n_[0] * n_[1]));
    const long nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& x : nb) {
      if (x[0] < 0 || x[1] < 0 || x[2] < 0 || x[0] >= nx || x[1] >= ny || x[2] >= nz) continue;
      const std::size_t r = std::size_t(x[0] + nx * (x[1] + ny * x[2]));
      if (taken_[r] || voxel_class(r) != b.cls) continue;
      taken_[r] = true;
      stack.push_back(r);
    }
  }
}

// Every rejected decision of at least min_body_ml: its body, grown from the nearest voxel of its kind.
void SegmentationQc::find_bodies() {
  taken_.assign(n_[0] * n_[1] * n_[2], false);
  for (const auto& d : result_.value("decisions", nlohmann::json::array())) {
    const bool kept = d.value("decision", std::string()) == "kept" || d.value("kept", false);
    const double ml = d.value("volume_ml", 0.0);
    if (kept || ml < o_.min_body_ml || !d.contains("position_lps_mm")) continue;
    QcBody b;
    b.id = int(bodies_.size()) + 1;
    b.decision = d;
    const std::string what = d.value("what", std::string());
    const int cls = what.find("gas") != std::string::npos ? 0 : what.find("fluid") != std::string::npos ? 1 : -1;
    std::size_t seed = 0;
    b.too_large = ml > 2 * lumen_ml_;  // outside air: larger than twice the whole lumen, not colon
    // Pieces nearest first until half the decision's volume is found (segment's body may be split
    // here by the lumen or noise), at most 10.
    const std::size_t cap = std::max<std::size_t>(1000, std::size_t(3 * ml / voxel_ml_));
    for (int piece = 0; piece < 10 && !b.too_large && !b.truncated && b.voxels.size() * voxel_ml_ < 0.5 * ml; ++piece) {
      if (!seed_of(d["position_lps_mm"].get<std::array<double, 3>>(), b.cls >= 0 ? b.cls : cls, seed)) break;
      flood(b, seed, cap);
    }
    std::sort(b.voxels.begin(), b.voxels.end());
    for (std::size_t q : b.voxels) {
      grow_box(lps_of(q));
      body_voxels_.push_back({q, b.id});
    }
    bodies_.push_back(std::move(b));
  }
  std::sort(body_voxels_.begin(), body_voxels_.end());
}

// Each body's reason index (its colour): distinct reasons numbered in order of first appearance.
void SegmentationQc::assign_reasons() {
  for (QcBody& b : bodies_) {
    const std::string r = b.decision.value("reason", std::string());
    const auto it = std::find(reasons_.begin(), reasons_.end(), r);
    b.reason = int(it - reasons_.begin());
    if (it == reasons_.end()) reasons_.push_back(r);
  }
}

// The montages' slices are drawn on the threads, each into its own slot: the same drawing for
// any thread count.
SegmentationQcDrawing SegmentationQc::run() {
  thresholds();
  scan_lumen();
  find_bodies();
  assign_reasons();
  SegmentationQcDrawing out;
  if (lo_[0] > hi_[0]) {
    out.section = {{"missing", "the lumen mask is empty and no rejected body was found"}};
    return out;
  }
  double ext = 0;
  for (int d = 0; d < 3; ++d) ext = std::max(ext, hi_[d] - lo_[d] + 2 * o_.margin_mm);
  pix_ = std::max({ext / o_.max_pixels, ct_->GetSpacing()[0], ct_->GetSpacing()[1]});
  struct Slice {
    Plane plane;
    double fixed;
    int n;
  };
  std::vector<Slice> slices;
  for (Plane p : {Plane::coronal, Plane::axial, Plane::sagittal}) {
    int n = 0;
    for (double f : slice_positions(p)) slices.push_back({p, f, n++});
  }
  std::vector<nlohmann::json> entries(slices.size());
  out.montages.resize(slices.size());
  parallel_for(slices.size(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) entries[i] = draw(slices[i].plane, slices[i].fixed, slices[i].n, out.montages[i]);
  });
  out.section = tables();
  for (Plane p : {Plane::coronal, Plane::axial, Plane::sagittal}) out.section["planes"][plane_name(p)] = nlohmann::json::array();
  for (std::size_t i = 0; i < slices.size(); ++i) out.section["planes"][plane_name(slices[i].plane)].push_back(entries[i]);
  add_seen(out.section);
  return out;
}

// Slices through the largest bodies (where each has most voxels along the axis) and through the
// lumen (its 20-80 % quantiles along the axis), at least 8 mm apart, at least 4, sorted.
std::vector<double> SegmentationQc::slice_positions(Plane p) const {
  const int a = plane_axes(p).fixed_axis;
  std::vector<double> pos;
  const auto add = [&](double x) {
    for (double y : pos)
      if (std::abs(x - y) < 8) return;
    pos.push_back(x);
  };
  for (const QcBody& b : bodies_) {
    if (b.voxels.empty() || int(pos.size()) >= o_.slices - 2) continue;
    std::vector<int> h(hist_[a].size() / 2 + 2, 0);
    for (std::size_t q : b.voxels) {
      const double x = lps_of(q)[a] - hist_lo_[a];
      if (x >= 0 && std::size_t(x / 2) < h.size()) ++h[std::size_t(x / 2)];
    }
    add(hist_lo_[a] + 2.0 * double(std::max_element(h.begin(), h.end()) - h.begin()) + 1.0);
  }
  double total = 0;
  for (double c : hist_[a]) total += c;
  for (double f : {0.5, 0.2, 0.8, 0.35, 0.65, 0.1, 0.9}) {
    if (int(pos.size()) >= o_.slices || total <= 0) break;
    double acc = 0;
    std::size_t i = 0;
    while (i + 1 < hist_[a].size() && acc + hist_[a][i] < f * total) acc += hist_[a][i++];
    add(hist_lo_[a] + double(i) + 0.5);
  }
  // A thin lumen along this axis: fill up to 4 slices evenly over the box, 2 mm apart at least.
  for (int t = 1; t <= 8 && pos.size() < 4; ++t) {
    const double x = lo_[a] + (hi_[a] - lo_[a]) * t / 9.0;
    if (std::none_of(pos.begin(), pos.end(), [&](double y) { return std::abs(x - y) < 2; })) pos.push_back(x);
  }
  std::sort(pos.begin(), pos.end());
  return pos;
}

// One montage image: the CT plane (lung window), rejected bodies tinted and outlined in their
// reason's colour, the lumen outlined green, a numbered tag per body seen (placed by qc_tags.h,
// with a leader line when moved off its body).
nlohmann::json SegmentationQc::draw(Plane p, double fixed, int n, QcMontage& out) const {
  SliceCanvas cv = paint(p, fixed);
  outline(cv);
  const nlohmann::json tags = tag(cv);
  out.name = std::string("seg_") + plane_name(p) + "_" + std::to_string(n) + ".png";
  out.w = cv.w, out.h = cv.h, out.rgb = std::move(cv.rgb);
  return {{"position_mm", std::round(fixed * 10) / 10}, {"axis", std::string(1, "LPS"[plane_axes(p).fixed_axis])},
          {"w", out.w}, {"h", out.h}, {"pixel_mm", pix_}, {"tags", tags}};
}

// The CT plane in the lung window over the lumen's and bodies' box (+ margin), the lumen mask and
// the body number of every pixel, bodies tinted (65 % CT, 35 % their colour).
SliceCanvas SegmentationQc::paint(Plane p, double fixed) const {
  const PlaneAxes a = plane_axes(p);
  const auto range = [&](int axis, int sign) {
    const double x = sign * lo_[axis], y = sign * hi_[axis];
    return std::array<double, 2>{std::min(x, y) - o_.margin_mm, std::max(x, y) + o_.margin_mm};
  };
  const auto ur = range(a.u_axis, a.u_sign), vr = range(a.v_axis, a.v_sign);
  SliceCanvas cv;
  cv.w = std::max(1, int(std::ceil((ur[1] - ur[0]) / pix_))), cv.h = std::max(1, int(std::ceil((vr[1] - vr[0]) / pix_)));
  const PlaneImage im = sample_(p, fixed, ur[0], vr[0], cv.w, cv.h, pix_);
  const std::size_t np = std::size_t(cv.w) * cv.h;
  cv.lum.assign(np, 0), cv.rgb.assign(np * 3, 0), cv.body.assign(np, 0);
  for (int r = 0; r < cv.h; ++r)
    for (int c = 0; c < cv.w; ++c) {
      CtImage::PointType pt;
      pt[a.fixed_axis] = fixed;
      pt[a.u_axis] = a.u_sign * (ur[0] + c * pix_);
      pt[a.v_axis] = a.v_sign * (vr[0] + r * pix_);
      CtImage::IndexType idx;
      const std::size_t px = std::size_t(r) * cv.w + c;
      const unsigned char g = window_grey(im.hu[px], lung_window());
      for (int k = 0; k < 3; ++k) cv.rgb[3 * px + k] = g;
      if (!ct_->TransformPhysicalPointToIndex(pt, idx)) continue;
      const std::size_t q = std::size_t(idx[0]) + n_[0] * (std::size_t(idx[1]) + n_[1] * std::size_t(idx[2]));
      cv.lum[px] = m_[q];
      const auto it = std::lower_bound(body_voxels_.begin(), body_voxels_.end(), std::make_pair(q, 0));
      if (it == body_voxels_.end() || it->first != q) continue;
      cv.body[px] = it->second;
      for (int k = 0; k < 3; ++k) cv.rgb[3 * px + k] = static_cast<unsigned char>(0.65 * g + 0.35 * colour(it->second)[k]);
    }
  return cv;
}

// Outline pixels (4-neighbours outside the region): lumen green, each body in its colour.
void SegmentationQc::outline(SliceCanvas& cv) const {
  cv.lumen_edge.assign(cv.lum.size(), 0), cv.body_edge.assign(cv.lum.size(), 0);
  for (int r = 0; r < cv.h; ++r)
    for (int c = 0; c < cv.w; ++c) {
      const std::size_t px = std::size_t(r) * cv.w + c;
      bool lum_edge = false, body_edge = false;
      for (const auto& [dr, dc] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const int rr = r + dr, cc = c + dc;
        if (rr < 0 || cc < 0 || rr >= cv.h || cc >= cv.w) continue;
        const std::size_t o = std::size_t(rr) * cv.w + cc;
        lum_edge = lum_edge || (cv.lum[px] && !cv.lum[o]);
        body_edge = body_edge || (cv.body[px] && cv.body[o] != cv.body[px]);
      }
      cv.lumen_edge[px] = lum_edge, cv.body_edge[px] = body_edge;
      if (lum_edge) std::copy_n(kLumenRgb.data(), 3, &cv.rgb[3 * px]);
      if (body_edge) std::copy_n(colour(cv.body[px]).data(), 3, &cv.rgb[3 * px]);
    }
}

// Tags: each body seen points at its pixel nearest its pixels' centre; the bodies with fewest
// pixels here are placed first (they need a near place most). Leaders are drawn into the image.
nlohmann::json SegmentationQc::tag(SliceCanvas& cv) const {
  const std::size_t nb = bodies_.size() + 1;
  std::vector<std::array<double, 3>> sum(nb, {0, 0, 0});  // col, row, pixels
  for (std::size_t px = 0; px < cv.body.size(); ++px)
    if (const int b = cv.body[px]) sum[std::size_t(b)][0] += double(px % cv.w), sum[std::size_t(b)][1] += double(px / cv.w), sum[std::size_t(b)][2] += 1;
  std::vector<double> best(nb, 1e300);
  std::vector<QcTagAnchor> anchors(nb);
  for (std::size_t px = 0; px < cv.body.size(); ++px) {
    const std::size_t b = std::size_t(cv.body[px]);
    if (!b) continue;
    const double dc = double(px % cv.w) - sum[b][0] / sum[b][2], dr = double(px / cv.w) - sum[b][1] / sum[b][2];
    if (dc * dc + dr * dr < best[b]) best[b] = dc * dc + dr * dr, anchors[b] = {int(b), int(px % cv.w), int(px / cv.w)};
  }
  std::vector<QcTagAnchor> seen;
  for (std::size_t b = 1; b < nb; ++b)
    if (sum[b][2] > 0) seen.push_back(anchors[b]);
  std::stable_sort(seen.begin(), seen.end(), [&](const QcTagAnchor& x, const QcTagAnchor& y) { return sum[std::size_t(x.id)][2] < sum[std::size_t(y.id)][2]; });
  const std::vector<QcTag> tags = place_qc_tags(cv.w, cv.h, cv.lumen_edge, cv.body_edge, seen, o_.tags);
  std::vector<std::array<unsigned char, 3>> colours(nb);
  for (std::size_t b = 1; b < nb; ++b) colours[b] = colour(int(b));
  draw_qc_leaders(cv.w, cv.h, cv.rgb, tags, colours);
  nlohmann::json out = nlohmann::json::array();
  for (const QcTag& t : tags)
    out.push_back({{"id", t.id}, {"col", t.col}, {"row", t.row}, {"pixels", sum[std::size_t(t.id)][2]}, {"placed", t.placed},
                   {"x", t.x}, {"y", t.y}, {"w", t.w}, {"h", t.h}, {"leader", t.leader}, {"lumen_covered", t.lumen_covered}});
  return out;
}

// The kept and rejected bodies of segment's decisions, the lumen volume and the thresholds used.
nlohmann::json SegmentationQc::tables() const {
  nlohmann::json bodies = nlohmann::json::array(), kept = nlohmann::json::array();
  for (const QcBody& b : bodies_)
    bodies.push_back({{"id", b.id}, {"what", b.decision.value("what", "")}, {"reason", b.decision.value("reason", "")},
                      {"volume_ml", b.decision.value("volume_ml", 0.0)}, {"position_lps_mm", b.decision["position_lps_mm"]},
                      {"outlined", !b.voxels.empty()}, {"measured_ml", b.voxels.size() * voxel_ml_}, {"truncated", b.truncated},
                      {"too_large", b.too_large}, {"reason_index", b.reason}, {"colour", css_rgb(reason_rgb(std::size_t(b.reason)))},
                      {"seen", nlohmann::json::array()}, {"kind", b.cls == 0 ? "gas" : b.cls == 1 ? "tagged fluid" : "not found"}});
  nlohmann::json reasons = nlohmann::json::array();
  for (std::size_t r = 0; r < reasons_.size(); ++r) {
    const auto& c = reason_rgb(r);
    const bool light = 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2] > 140;  // dark digits on a light tag
    reasons.push_back({{"reason", reasons_[r]}, {"colour", css_rgb(c)}, {"ink", light ? "#000" : "#fff"}});
  }
  double small_ml = 0;
  int small = 0;
  for (const auto& d : result_.value("decisions", nlohmann::json::array())) {
    const bool is_kept = d.value("decision", std::string()) == "kept" || d.value("kept", false);
    if (is_kept) kept.push_back({{"what", d.value("what", "")}, {"volume_ml", d.value("volume_ml", 0.0)}, {"reason", d.value("reason", "")}});
    else if (d.value("volume_ml", 0.0) < o_.min_body_ml) small_ml += d.value("volume_ml", 0.0), ++small;
  }
  return {{"bodies", bodies}, {"kept", kept}, {"segment_volumes_ml", result_.value("segment_volumes_ml", nlohmann::json::array())},
          {"lumen_ml", lumen_ml_}, {"min_body_ml", o_.min_body_ml}, {"small_rejected", {{"count", small}, {"volume_ml", small_ml}}},
          {"thresholds_hu", {{"gas_below", gas_thr_}, {"fluid_above", fluid_thr_}}},
          {"reasons", reasons}, {"colours", {{"lumen", css_rgb(kLumenRgb)}}}};
}

template <class Image>
SegmentationQcDrawing draw_qc(const Image* ct, const MaskImage* lumen, const nlohmann::json& segment_result,
                              const SegmentationQcOptions& opts) {
  SegmentationQcDrawing missing;
  if (!ct || !lumen) {
    missing.section = {{"missing", "no CT or no lumen mask in the run folder"}};
    return missing;
  }
  bool same_grid = ct->GetLargestPossibleRegion().GetSize() == lumen->GetLargestPossibleRegion().GetSize();
  for (int d = 0; d < 3; ++d)
    same_grid = same_grid && std::abs(ct->GetOrigin()[d] - lumen->GetOrigin()[d]) <= 1e-3 &&
                std::abs(ct->GetSpacing()[d] - lumen->GetSpacing()[d]) <= 1e-6;
  if (!same_grid) {
    missing.section = {{"missing", "the lumen mask is not on the CT's grid"}};
    return missing;
  }
  return SegmentationQc(ct, lumen, segment_result, opts).run();
}

}  // namespace

SegmentationQcDrawing draw_segmentation_qc(const CtImage* ct, const MaskImage* lumen, const nlohmann::json& segment_result,
                                           const SegmentationQcOptions& opts) {
  return draw_qc(ct, lumen, segment_result, opts);
}

SegmentationQcDrawing draw_segmentation_qc(const CompactCtImage* ct, const MaskImage* lumen,
                                           const nlohmann::json& segment_result, const SegmentationQcOptions& opts) {
  return draw_qc(ct, lumen, segment_result, opts);
}

}  // namespace cf
