// paint_phantom_from_mask: the mask's frame (grid, LPS mapping, gravity) -> the phantom's body scaled
// around the colon, a pelvis -> the 3 mm colon wall -> coarse clearance from the lumen (bone and lung
// moved away) -> fully tagged stretches, pools (mask_phantom_fluid.cpp) -> small bowel and bladder
// (mask_phantom_organs.cpp) -> images (the phantom's HU table, truth labels, blur and noise) in the
// mask's geometry.
#include "colonflat/phantom/mask_phantom.h"

#include <itkSignedMaurerDistanceMapImageFilter.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "mask_phantom_model.h"
#include "phantom_description.h"

namespace cf {

using namespace phantom_detail;

std::array<double, 3> gravity_of_position(const std::string& p) {
  if (p == "supine") return {0, 1, 0};
  if (p == "prone") return {0, -1, 0};
  if (p == "left-down") return {1, 0, 0};
  if (p == "right-down") return {-1, 0, 0};
  throw UsageError("--position must be supine, prone, left-down or right-down (got '" + p + "')");
}

MaskImage::Pointer read_binary_mask(const std::filesystem::path& file) {
  CtImage::Pointer v = read_ct_volume(file);
  const std::size_t n = v->GetLargestPossibleRegion().GetNumberOfPixels();
  const float* a = v->GetBufferPointer();
  std::size_t on = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (a[q] != 0.f && a[q] != 1.f)
      throw InputError(file.string(), "not a binary mask: found the value " + std::to_string(a[q]) + " (expected 0 and 1)");
    on += a[q] == 1.f;
  }
  if (on == 0) throw InputError(file.string(), "empty mask: no lumen voxel (value 1)");
  auto m = MaskImage::New();
  m->CopyInformation(v);
  m->SetRegions(v->GetLargestPossibleRegion());
  m->Allocate();
  std::transform(a, a + n, m->GetBufferPointer(), [](float x) { return static_cast<unsigned char>(x != 0.f); });
  return m;
}

MaskPhantom paint_phantom_from_mask(const MaskImage* mask, const MaskPhantomOptions& o) {
  gravity_of_position(o.position);
  if (!(o.noise_hu >= 0 && o.noise_hu <= 500)) throw UsageError("--noise must be in [0, 500] HU");
  if (!(o.blur_mm >= 0 && o.blur_mm <= 5)) throw UsageError("--blur must be in [0, 5] mm");
  if (o.fully_tagged < 0 || o.fully_tagged > 3) throw UsageError("--fully-tagged-segments must be in [0, 3]");
  if (o.bowel_loops < 0 || o.bowel_loops > 8) throw UsageError("--bowel-loops must be in [0, 8]");
  if (o.long_stretch_mm != 0 && !(o.long_stretch_mm >= 100 && o.long_stretch_mm <= 400))
    throw UsageError("--long-stretch must be 0 or in [100, 400] mm");
  MaskPhantom out;
  MaskPainter(mask, o, out).run();
  return out;
}

namespace phantom_detail {

MaskPainter::MaskPainter(const MaskImage* mask, const MaskPhantomOptions& o, MaskPhantom& out)
    : mask_(mask), mask_buf_(mask->GetBufferPointer()), o_(o), out_(out), rng_(o.seed * 7919ull + 5) {}

void MaskPainter::run() {
  make_frame();
  map_body();
  paint_body_around();
  paint_wall();
  make_clearance();
  clear_near_colon();
  phase_done("body and colon wall");
  place_stretches();
  if (o_.pools) place_pools();
  phase_done("tagged fluid");
  place_bowel();
  if (o_.bladder) place_bladder();
  phase_done("small bowel and bladder");
  make_images();
  phase_done("CT with blur and noise");
}

// Grid frame (index x spacing), LPS origin and direction, gravity, lumen box, most inferior voxel.
void MaskPainter::make_frame() {
  const auto size = mask_->GetLargestPossibleRegion().GetSize();
  for (int d = 0; d < 3; ++d) {
    g_.n[d] = int(size[d]);
    g_.sp[d] = mask_->GetSpacing()[d];
    g_.org[d] = 0;
    origin_[d] = mask_->GetOrigin()[d];
    for (int e = 0; e < 3; ++e) dir_(d, e) = mask_->GetDirection()(d, e);
  }
  md_.g = g_;  // the grid materials_to_images builds the images on
  out_.gravity_lps = gravity_of_position(o_.position);
  const V3 down(out_.gravity_lps[0], out_.gravity_lps[1], out_.gravity_lps[2]);
  down_ = dir_.transpose() * down;
  depth0_ = down.dot(origin_);
  for (int d = 0; d < 3; ++d) lo_[d] = g_.n[d], hi_[d] = 0;
  double zmin = std::numeric_limits<double>::infinity();
  for (int k = 0; k < g_.n[2]; ++k)
    for (int j = 0; j < g_.n[1]; ++j)
      for (int i = 0; i < g_.n[0]; ++i) {
        const std::size_t q = g_.index(i, j, k);
        if (!lumen(q)) continue;
        const int ix[3] = {i, j, k};
        for (int d = 0; d < 3; ++d) lo_[d] = std::min(lo_[d], ix[d]), hi_[d] = std::max(hi_[d], ix[d] + 1);
        const double z = lps(g_.point(i, j, k)).z();
        if (z < zmin) zmin = z, rectum_ = q;
      }
  mat_.assign(g_.voxels(), kVisceralFat);
  out_.fluid_id.assign(g_.voxels(), 0);
  // Tagged fluid of one scan: one mean (450-750 HU) and +-50 HU between pools (same oral agent).
  const double mean = rng_.uniform(450, 750);
  md_.pools.assign(kPoolSlots, Pool{});
  for (Pool& p : md_.pools) p.hu = std::round(mean + rng_.uniform(-50, 50));
}

// The phantom body's frame around this colon: the colon's x-y extent is centred and scaled (never
// shrunk) so every lumen voxel lies in the visceral cavity with 20 mm to spare; its z extent is
// stretched over the phantom colon's z range (rectum at -178 mm, splenic flexure below the lungs).
void MaskPainter::map_body() {
  V3 lo = V3::Constant(1e18), hi = V3::Constant(-1e18);
  const int step = std::max(1, int(std::round(2.0 / std::min(g_.sp[0], g_.sp[1]))));
  std::vector<V3> pts;
  for (int k = lo_[2]; k < hi_[2]; k += step)
    for (int j = lo_[1]; j < hi_[1]; j += step)
      for (int i = lo_[0]; i < hi_[0]; i += step)
        if (lumen(g_.index(i, j, k))) {
          pts.push_back(lps(g_.point(i, j, k)));
          lo = lo.cwiseMin(pts.back());
          hi = hi.cwiseMax(pts.back());
        }
  if (pts.empty()) pts.push_back(lps(g_.point(lo_[0], lo_[1], lo_[2]))), lo = hi = pts.back();
  cx_ = 0.5 * (lo.x() + hi.x());
  cy_ = 0.5 * (lo.y() + hi.y());
  // Visceral cavity of the phantom body at mid height: 139 x 99 mm half axes; keep 20 mm inside.
  double need = 1;
  for (const V3& p : pts) {
    const double ex = (p.x() - cx_) / 119.0, ey = (p.y() - cy_) / 79.0;
    need = std::max(need, std::sqrt(ex * ex + ey * ey));
  }
  scale_ = need;
  zmin_ = lo.z();
  zscale_ = hi.z() > lo.z() ? (110.0 + 178.0) / (hi.z() - lo.z()) : 1.0;
}

// The phantom's body (outline, fat, muscle, organs, spine, lungs) in the mapped frame, plus a pelvis
// (iliac wings: cortical shell over cancellous bone) beside the lower colon.
void MaskPainter::paint_body_around() {
  parallel_for(g_.n[2], [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < g_.n[1]; ++j)
        for (int i = 0; i < g_.n[0]; ++i) {
          const V3 p = lps(g_.point(i, j, k));
          const double x = (p.x() - cx_) / scale_, y = (p.y() - cy_) / scale_ + 5, z = -178 + (p.z() - zmin_) * zscale_;
          unsigned char m = body_material(x, y, z);
          const double ix = (std::abs(x) - 105) / 22, iy = (y - 50) / 42, iz = (z + 105) / 48;
          const double e = ix * ix + iy * iy + iz * iz;
          if (e <= 1 && m != kOutsideAir && m != kSubcutFat) m = e > 0.7 ? kSpineCortex : kSpineCancellous;
          mat_[g_.index(i, j, k)] = m;
        }
  });
}

// The lumen (as colon gas) and a kMaskWallMm shell of colon wall around it (ball around every
// boundary voxel).
void MaskPainter::paint_wall() {
  std::vector<std::array<int, 3>> ball;
  int r[3];
  for (int d = 0; d < 3; ++d) r[d] = int(std::ceil(kMaskWallMm / g_.sp[d]));
  for (int dk = -r[2]; dk <= r[2]; ++dk)
    for (int dj = -r[1]; dj <= r[1]; ++dj)
      for (int di = -r[0]; di <= r[0]; ++di)
        if (V3(di * g_.sp[0], dj * g_.sp[1], dk * g_.sp[2]).norm() <= kMaskWallMm) ball.push_back({di, dj, dk});
  for (int k = lo_[2]; k < hi_[2]; ++k)
    for (int j = lo_[1]; j < hi_[1]; ++j)
      for (int i = lo_[0]; i < hi_[0]; ++i) {
        const std::size_t q = g_.index(i, j, k);
        if (!lumen(q)) continue;
        mat_[q] = kColonGas;
        bool boundary = false;
        const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const auto& n : nb)
          boundary = boundary || n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= g_.n[0] || n[1] >= g_.n[1] ||
                     n[2] >= g_.n[2] || !lumen(g_.index(n[0], n[1], n[2]));
        if (!boundary) continue;
        for (const auto& b : ball) {
          const int a = i + b[0], c = j + b[1], e = k + b[2];
          if (a < 0 || c < 0 || e < 0 || a >= g_.n[0] || c >= g_.n[1] || e >= g_.n[2]) continue;
          const std::size_t t = g_.index(a, c, e);
          if (!lumen(t)) mat_[t] = kColonWall;
        }
      }
}

// Distance (mm) from the lumen on a grid of ~2 mm cells (a cell is lumen if any voxel in it is).
void MaskPainter::make_clearance() {
  using Img = itk::Image<unsigned char, 3>;
  using Dist = itk::Image<float, 3>;
  auto img = Img::New();
  Img::SizeType sz;
  double sp[3];
  for (int d = 0; d < 3; ++d) {
    cf_[d] = std::max(1, int(std::lround(2.0 / g_.sp[d])));
    cn_[d] = (g_.n[d] + cf_[d] - 1) / cf_[d];
    sz[d] = std::size_t(cn_[d]);
    sp[d] = cf_[d] * g_.sp[d];
  }
  img->SetRegions(sz);
  img->SetSpacing(sp);
  img->Allocate();
  img->FillBuffer(0);
  unsigned char* b = img->GetBufferPointer();
  for (int k = lo_[2]; k < hi_[2]; ++k)
    for (int j = lo_[1]; j < hi_[1]; ++j)
      for (int i = lo_[0]; i < hi_[0]; ++i)
        if (lumen(g_.index(i, j, k))) b[(std::size_t(k / cf_[2]) * cn_[1] + j / cf_[1]) * cn_[0] + i / cf_[0]] = 1;
  auto f = itk::SignedMaurerDistanceMapImageFilter<Img, Dist>::New();
  f->SetInput(img);
  f->SetUseImageSpacing(true);
  f->SetSquaredDistance(false);
  f->SetInsideIsPositive(false);
  f->SetBackgroundValue(0);
  f->Update();
  const float* d = f->GetOutput()->GetBufferPointer();
  clear_.assign(d, d + img->GetLargestPossibleRegion().GetNumberOfPixels());
  for (float& v : clear_) v = std::max(0.f, v);
}

double MaskPainter::clearance(const V3& p) const {
  int c[3];
  for (int d = 0; d < 3; ++d) {
    c[d] = int(std::floor(p[d] / g_.sp[d] + 0.5)) / cf_[d];
    if (c[d] < 0 || c[d] >= cn_[d]) return 1e9;  // outside the volume: far from this lumen
  }
  return clear_[(std::size_t(c[2]) * cn_[1] + c[1]) * cn_[0] + c[0]];
}

// Bone and lung within kOrganClearanceMm of the lumen become visceral fat.
void MaskPainter::clear_near_colon() {
  parallel_for(g_.n[2], [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < g_.n[1]; ++j)
        for (int i = 0; i < g_.n[0]; ++i) {
          unsigned char& m = mat_[g_.index(i, j, k)];
          if ((m == kSpineCortex || m == kSpineCancellous || m == kLung) && clearance(g_.point(i, j, k)) < kOrganClearanceMm)
            m = kVisceralFat;
        }
  });
}

// HU and truth images from the materials (the phantom's tables), blur and noise, the mask's geometry.
void MaskPainter::make_images() {
  Phantom& p = out_.phantom;
  VolumeCounts counts;
  CtImage::Pointer sharp = materials_to_images(md_, mat_, p, counts);
  p.ct = blur_and_noise(sharp, o_.noise_hu, o_.blur_mm, o_.seed, g_);
  for (itk::ImageBase<3>* im : {static_cast<itk::ImageBase<3>*>(p.ct.GetPointer()), static_cast<itk::ImageBase<3>*>(p.lumen.GetPointer()),
                                static_cast<itk::ImageBase<3>*>(p.labels.GetPointer())}) {
    im->SetOrigin(mask_->GetOrigin());
    im->SetDirection(mask_->GetDirection());
  }
  static const char* const kHeader[] = {"HFS", "HFP", "HFDL", "HFDR"};
  const char* const kPos[] = {"supine", "prone", "left-down", "right-down"};
  p.patient_position.clear();
  for (int t = 0; t < 4 && o_.position_header; ++t)
    if (o_.position == kPos[t]) p.patient_position = kHeader[t];
  set_patient_position(p.ct.GetPointer(), p.patient_position);
  p.description = describe();
  p.description["volumes_ml"] = {{"lumen", counts.lumen * g_.sp[0] * g_.sp[1] * g_.sp[2] / 1000.0},
                                 {"colon_fluid", counts.fluid * g_.sp[0] * g_.sp[1] * g_.sp[2] / 1000.0},
                                 {"small_bowel", counts.by_label[kTruthBowelContrast] * g_.sp[0] * g_.sp[1] * g_.sp[2] / 1000.0},
                                 {"bladder", counts.by_label[kTruthBladder] * g_.sp[0] * g_.sp[1] * g_.sp[2] / 1000.0}};
}

}  // namespace phantom_detail
}  // namespace cf
