// Organs around a mask phantom's colon: small-bowel loops with positive oral contrast (C-shaped
// tubes in the mid abdomen, clear of the colon, every other one touching its wall), the bladder
// with excreted contrast (anterior-superior of the rectum, shrunk until clear of the colon), and
// phantom.json's description of the case.
#include <algorithm>
#include <cmath>

#include "mask_phantom_model.h"

namespace cf::phantom_detail {

namespace {
// Small bowel: 22-30 mm wide (radius 11-15 mm), C-shaped loops of 25-40 mm bend radius, 2 mm wall;
// oral contrast 270-330 HU (issue 25's phantoms: about 320 HU).
constexpr double kBowelWallMm = 2.0;
// A loop's centreline keeps this far from the lumen beyond its radius: colon wall + bowel wall, so
// the walls touch but never overlap; a "touching" loop comes within 2 mm more of that somewhere.
constexpr double kBowelGapMm = kMaskWallMm + kBowelWallMm, kTouchSlackMm = 2.0;
// A pressed loop (--pressed-bowel) comes within 1 mm of the colon wall: its contrast lies against
// the colon wall (the two walls pressed into one of ~3 mm), as loops packed against the colon do.
constexpr double kPressedSlackMm = 1.0;
}  // namespace

// One C-shaped loop in the middle 60 % of the lumen box: every centreline point in visceral fat,
// clear of the colon and of the other loops.
bool MaskPainter::try_bowel_loop(bool touching, BowelLoop& loop) {
  V3 c;
  for (int d = 0; d < 3; ++d) c[d] = g_.sp[d] * (lo_[d] + (hi_[d] - lo_[d]) * rng_.uniform(0.2, 0.8));
  const double R = rng_.uniform(25, 40), r = rng_.uniform(11, 15), arc = rng_.uniform(200, 300) * kPi / 180;
  const double t0 = rng_.uniform(0, 2 * kPi);
  const V3 n = V3(rng_.normal(), rng_.normal(), rng_.normal()).normalized(), u = n.unitOrthogonal(), w = n.cross(u);
  const int m = std::max(2, int(arc * R / 3));
  loop.pts.clear();
  loop.r = r;
  double minc = 1e9;
  for (int t = 0; t <= m; ++t) {
    const double a = t0 + arc * t / m;
    const V3 p = c + R * (std::cos(a) * u + std::sin(a) * w);
    int ix[3];
    for (int d = 0; d < 3; ++d) {
      ix[d] = int(std::lround(p[d] / g_.sp[d]));
      if (ix[d] < 0 || ix[d] >= g_.n[d]) return false;
    }
    if (mat_[g_.index(ix[0], ix[1], ix[2])] != kVisceralFat) return false;
    const double cl = clearance(p);
    if (cl < r + (touching && o_.pressed_bowel ? kMaskWallMm : kBowelGapMm)) return false;
    minc = std::min(minc, cl);
    for (const BowelLoop& o : md_.bowel)
      for (const V3& q : o.pts)
        if ((p - q).norm() < r + o.r + 2 * kBowelWallMm) return false;
    loop.pts.push_back(p);
  }
  if (touching && minc > r + (o_.pressed_bowel ? kMaskWallMm + kPressedSlackMm : kBowelGapMm + kTouchSlackMm)) return false;
  loop_clearance_.push_back(minc - r);
  return true;
}

// Contrast within the radius, wall within 2 mm more; never on the colon's lumen or wall.
void MaskPainter::paint_bowel_loop(const BowelLoop& loop) {
  for (std::size_t s = 0; s + 1 < loop.pts.size(); ++s) {
    const V3 &a = loop.pts[s], &b = loop.pts[s + 1];
    int l[3], h[3];
    for (int d = 0; d < 3; ++d) g_.range(d, std::min(a[d], b[d]) - loop.r - 3, std::max(a[d], b[d]) + loop.r + 3, l[d], h[d]);
    for (int k = l[2]; k < h[2]; ++k)
      for (int j = l[1]; j < h[1]; ++j)
        for (int i = l[0]; i < h[0]; ++i) {
          const std::size_t q = g_.index(i, j, k);
          unsigned char& mm = mat_[q];
          if (lumen(q) || mm == kColonWall || mm == kOutsideAir || mm == kSubcutFat || mm == kBowelContrast) continue;
          const double d = std::sqrt(seg_point_dist2(g_.point(i, j, k), a, b));
          if (d <= loop.r) mm = kBowelContrast;
          else if (d <= loop.r + kBowelWallMm && mm != kBowelWall) mm = kBowelWall;
        }
  }
}

void MaskPainter::place_bowel() {
  const double hu = std::round(rng_.uniform(270, 330));
  for (int t = 0; t < o_.bowel_loops; ++t) {
    BowelLoop loop;
    loop.hu = hu;
    for (int attempt = 0; attempt < 1000; ++attempt)
      if (try_bowel_loop(t % 2 == 0, loop)) {
        md_.bowel.push_back(loop);
        break;
      }
  }
  for (const BowelLoop& loop : md_.bowel) paint_bowel_loop(loop);
}

// Bladder: ellipsoid 40 x 30 x 26 mm (LPS radii) 45 mm anterior and 30 mm superior of the rectal end,
// shrunk (down to 40 %) until its 3 mm wall is 6 mm clear of the colon and lies in visceral fat or muscle.
void MaskPainter::place_bladder() {
  int i, j, k;
  ijk(rectum_, i, j, k);
  const V3 c = lps(g_.point(i, j, k)) + V3(0, -45, 30);
  for (double s = 1.0; s > 0.35; s -= 0.1) {
    const V3 r = s * V3(40, 30, 26);
    bool ok = true;
    for (int a = 0; a < 12 && ok; ++a)
      for (int b = 1; b < 6 && ok; ++b) {
        const double th = kPi * b / 6, ph = 2 * kPi * a / 12;
        const V3 dir(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
        const V3 p = dir_.transpose() * (c + (r + V3::Constant(3)).cwiseProduct(dir) - origin_);
        int ix[3];
        for (int d = 0; d < 3 && ok; ++d) {
          ix[d] = int(std::lround(p[d] / g_.sp[d]));
          ok = ix[d] >= 0 && ix[d] < g_.n[d];
        }
        if (!ok) break;
        const unsigned char m = mat_[g_.index(ix[0], ix[1], ix[2])];
        ok = clearance(p) >= 6 && (m == kVisceralFat || m == kMuscle);
      }
    if (!ok) continue;
    paint_bladder(c, r);
    return;
  }
}

// Excreted contrast in the dependent 35 % of the bladder, urine above, 3 mm wall in the fat.
void MaskPainter::paint_bladder(const V3& c, const V3& r) {
  bladder_c_ = c;
  bladder_r_ = r;
  const V3 down(out_.gravity_lps[0], out_.gravity_lps[1], out_.gravity_lps[2]);
  const double level = 0.35 * r.cwiseProduct(down).norm();
  const V3 cg = dir_.transpose() * (c - origin_);
  const double reach = r.maxCoeff() + 4;
  int l[3], h[3];
  for (int d = 0; d < 3; ++d) g_.range(d, cg[d] - reach, cg[d] + reach, l[d], h[d]);
  for (int k = l[2]; k < h[2]; ++k)
    for (int j = l[1]; j < h[1]; ++j)
      for (int i = l[0]; i < h[0]; ++i) {
        const std::size_t q = g_.index(i, j, k);
        unsigned char& m = mat_[q];
        if (lumen(q) || m == kColonWall) continue;
        const V3 v = lps(g_.point(i, j, k)) - c;
        const double e = v.cwiseQuotient(r).norm();
        if (e <= 1) m = v.dot(down) > level ? kBladderContrast : kUrine;
        else if (e <= 1 + 3.0 / r.minCoeff() && m == kVisceralFat) m = kBladderWall;
      }
}

nlohmann::json MaskPainter::describe() const {
  const double ml = g_.sp[0] * g_.sp[1] * g_.sp[2] / 1000.0;
  nlohmann::json bodies = nlohmann::json::array(), loops = nlohmann::json::array();
  double pool_ml = 0, fmin = 1, fmax = 0;
  int pools = 0;
  for (std::size_t b = 0; b < out_.bodies.size(); ++b) {
    const MaskFluidBody& f = out_.bodies[b];
    nlohmann::json j = {{"id", b + 1}, {"kind", f.kind}, {"volume_ml", f.voxels * ml}, {"hu", f.hu}};
    if (f.kind == "pool") {
      j.update({{"fraction", f.fraction}, {"pocket_height_mm", f.pocket_height_mm}, {"level_depth_mm", f.level_depth_mm}});
      pool_ml += f.voxels * ml, ++pools, fmin = std::min(fmin, f.fraction), fmax = std::max(fmax, f.fraction);
    } else {
      j.update({{"from_mm", f.from_mm}, {"to_mm", f.to_mm}});
    }
    bodies.push_back(j);
  }
  for (std::size_t t = 0; t < md_.bowel.size(); ++t)
    loops.push_back({{"radius_mm", md_.bowel[t].r}, {"hu", md_.bowel[t].hu}, {"centreline_clearance_mm", loop_clearance_[t]}});
  nlohmann::json d = {
      {"source", "mask"}, {"seed", o_.seed}, {"position", o_.position}, {"patient_position", out_.phantom.patient_position},
      {"gravity_lps", out_.gravity_lps}, {"size", {g_.n[0], g_.n[1], g_.n[2]}}, {"spacing_mm", {g_.sp[0], g_.sp[1], g_.sp[2]}},
      {"body_frame", {{"centre_x_mm", cx_}, {"centre_y_mm", cy_}, {"scale", scale_}, {"z_min_mm", zmin_}, {"z_scale", zscale_}}},
      {"pools", {{"count", pools}, {"volume_ml", pool_ml}, {"fraction_min", pools ? fmin : 0.0}, {"fraction_max", fmax}}},
      {"fluid_bodies", bodies}, {"small_bowel", loops},
      {"bladder", {{"present", bladder_r_.x() > 0}, {"centre_lps_mm", {bladder_c_.x(), bladder_c_.y(), bladder_c_.z()}},
                   {"radii_mm", {bladder_r_.x(), bladder_r_.y(), bladder_r_.z()}}}},
      {"options", {{"noise_hu", o_.noise_hu}, {"blur_mm", o_.blur_mm}, {"fully_tagged", o_.fully_tagged},
                   {"bowel_loops", o_.bowel_loops}, {"bladder", o_.bladder}, {"pools", o_.pools},
                   {"long_stretch_mm", o_.long_stretch_mm}, {"deep_pools", o_.deep_pools}, {"pressed_bowel", o_.pressed_bowel}}}};
  return d;
}

}  // namespace cf::phantom_detail
