// Layout of the colon features: path perturbation, haustral folds, collapsed stretch, near-touching
// segments, tagged-fluid pools, polyps, strands, holes through folds, other gas. The random draws
// happen in a fixed order (the supine case of a seed is the same as before the prone position and
// the extra anatomy existed); everything added later draws from a second stream (extra_rng_).
#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "phantom_model.h"

namespace cf::phantom_detail {

PhantomLayout::PhantomLayout(const PhantomOptions& o, Model& md)
    : o_(o), md_(md), rng_(o.seed), extra_rng_(o.seed * 0xD1B54A32D192ED03ull + 0x8CB92BA72F3D8DD7ull) {}

void PhantomLayout::run() {
  make_grid();
  make_colon_path();
  place_folds();
  place_collapse();
  place_near_touch();
  if (o_.tagged_fluid) place_pools(rng_, false);
  place_polyps();
  place_strands_and_holes();
  place_other_gas();
  for (std::size_t k = 0; k < md_.sites.size(); ++k) md_.sites[k].id = int(k + 1);
  place_tagged_stretches();
  make_prone_path();  // drawn in both positions: the extra anatomy avoids the colon in both
  if (md_.gravity < 0) {
    deform_to_prone();
    md_.pools.clear();
    Rng pool_rng(o_.seed * 0xA0761D6478BD642Full + 0xE7037ED1A0B428DBull);  // keeps extra_rng_ in step with supine
    if (o_.tagged_fluid) place_pools(pool_rng, true);
  }
  place_bladder_and_aorta();
  place_small_bowel();
  if (o_.rectal_tube) place_rectal_tube();
  if (md_.gravity < 0)  // other gas the moved colon would reach (after the small bowel: same loops in both positions)
    md_.gas.erase(std::remove_if(md_.gas.begin(), md_.gas.end(),
                                 [&](const std::pair<V3, V3>& g) { return colon_clearance(g.first) < g.second.maxCoeff() + 9; }),
                  md_.gas.end());
}

void PhantomLayout::make_grid() {
  Grid& g = md_.g;
  if (o_.size == "full") g = {{512, 512, 400}, {0.7, 0.7, 1.0}, {-178.85, -178.85, -199.5}};
  else if (o_.size == "medium") g = {{256, 256, 200}, {1.4, 1.4, 2.0}, {-178.5, -178.5, -199.0}};
  else g = {{128, 128, 128}, {2.8, 2.8, 3.125}, {-177.8, -177.8, -198.4375}};
  hmax_ = std::max({g.sp[0], g.sp[1], g.sp[2]});
  md_.gravity = o_.position == "prone" ? -1.0 : 1.0;
}

// Control points perturbed by the seed, radii scaled.
void PhantomLayout::make_colon_path() {
  std::vector<ControlPoint> cps = base_path();
  for (std::size_t i = 1; i + 1 < cps.size(); ++i) {
    cps[i].p += V3(rng_.uniform(-5, 5), rng_.uniform(-4, 4), rng_.uniform(-5, 5));
    cps[i].r *= rng_.uniform(0.9, 1.08);
  }
  md_.path = make_path(cps, 1.0);
  md_.supine_path = md_.path;
}

double PhantomLayout::seg_start(int seg) const {
  double a = md_.path.length;
  for (std::size_t i = 0; i < md_.path.p.size(); ++i)
    if (md_.path.seg[i] == seg) a = std::min(a, md_.path.s[i]);
  return a;
}
double PhantomLayout::seg_end(int seg) const {
  double b = 0;
  for (std::size_t i = 0; i < md_.path.p.size(); ++i)
    if (md_.path.seg[i] == seg) b = std::max(b, md_.path.s[i]);
  return b;
}
std::size_t PhantomLayout::index_at(double s) const {
  return std::min(md_.path.p.size() - 1, std::size_t(std::max(0.0, std::round(s / 1.0))));
}
double PhantomLayout::nearest_fold_gap(double s) const {
  double d = 1e9;
  for (const Fold& f : md_.folds) d = std::min(d, std::abs(f.s - s));
  return d;
}
bool PhantomLayout::in_pool_s(double s) const {
  for (const Pool& p : md_.pools)
    if (s > p.s0 - 10 && s < p.s1 + 10) return true;
  return false;
}
bool PhantomLayout::free_s(double s, double clearance) const {
  for (double u : used_s_)
    if (std::abs(u - s) < clearance) return false;
  return true;
}
// Direction in the cross-section at path index i closest to `want`.
V3 PhantomLayout::cross_dir(std::size_t i, const V3& want) const {
  const Path& P = md_.path;
  V3 u = want - want.dot(P.T[i]) * P.T[i];
  if (u.norm() < 1e-6) u = P.N[i];
  return u.normalized();
}

// Haustral folds: none in the rectum, sparse in the sigmoid, every ~28-40 mm elsewhere.
void PhantomLayout::place_folds() {
  const double fold_w = std::max(1.4, 0.8 * hmax_);
  double s = seg_end(0) + 20;
  while (s < md_.path.length - 25) {
    const int seg = md_.path.seg[index_at(s)];
    md_.folds.push_back({s, rng_.uniform(0.28, 0.42), fold_w, rng_.uniform(0, 2 * kPi / 3)});
    s += seg == 1 ? rng_.uniform(45, 60) : rng_.uniform(28, 40);
  }
}

// Collapsed stretch (option) in the middle of the descending colon.
void PhantomLayout::place_collapse() {
  if (!o_.collapsed_segment) return;
  const double a = seg_start(2), b = seg_end(2);
  const double cs = a + (b - a) * rng_.uniform(0.4, 0.6);
  md_.collapses.push_back({cs, 36});
  md_.folds.erase(std::remove_if(md_.folds.begin(), md_.folds.end(), [&](const Fold& f) { return std::abs(f.s - cs) < 30; }),
                  md_.folds.end());
  used_s_.push_back(cs);
}

// Near-touching segments: the closest approach between distant sigmoid/transverse parts, bulged
// towards each other until the lumens are about one voxel apart.
void PhantomLayout::place_near_touch() {
  if (!o_.topological_noise) return;
  const Path& P = md_.path;
  const std::size_t np = P.p.size();
  md_.touch_gap = std::max(0.8, 0.9 * hmax_);
  auto away_from_collapse = [&](std::size_t i) {
    for (const Collapse& c : md_.collapses)
      if (std::abs(P.s[i] - c.s) <= 40) return false;
    return true;
  };
  double best = 1e9;
  std::size_t bi = 0, bj = 0;
  for (std::size_t i = 0; i < np; i += 2)
    for (std::size_t j = i + 200; j < np; j += 2) {
      const double gap = (P.p[i] - P.p[j]).norm() - P.r[i] - P.r[j];
      if (gap < best && (P.seg[i] == 1 || P.seg[i] == 3) && (P.seg[j] == 1 || P.seg[j] == 3) &&
          nearest_fold_gap(P.s[i]) > 8 && nearest_fold_gap(P.s[j]) > 8 && away_from_collapse(i) && away_from_collapse(j)) {
        best = gap;
        bi = i;
        bj = j;
      }
    }
  if (best >= 60) return;
  const double need = best - md_.touch_gap;  // total bulge so that the lumens are touch_gap apart
  const V3 dir = (P.p[bj] - P.p[bi]).normalized();
  md_.bulges.push_back({P.s[bi], need / 2, 8, cross_dir(bi, dir)});
  md_.bulges.push_back({P.s[bj], need / 2, 8, cross_dir(bj, -dir)});
  md_.touch_i = bi;
  md_.touch_j = bj;
  const V3 mid = P.p[bi] + dir * (P.r[bi] + need / 2 + md_.touch_gap / 2);
  md_.sites.push_back({0, "near_touch", {mid.x(), mid.y(), mid.z()}, md_.touch_gap, "possible_handle"});
  md_.folds.erase(std::remove_if(md_.folds.begin(), md_.folds.end(),
                                 [&](const Fold& f) { return std::abs(f.s - P.s[bi]) < 20 || std::abs(f.s - P.s[bj]) < 20; }),
                  md_.folds.end());
  for (const Bulge& b : md_.bulges) used_s_.push_back(b.s);
}

// Tagged-fluid pools in the dependent parts (supine: rectum, descending, ascending + cecum; prone:
// sigmoid, transverse, ascending + cecum). Each has one horizontal level (constant LPS y) at its
// lowest point and fills the lumen below it connected to that point (communicating vessels).
void PhantomLayout::place_pools(Rng& rng, bool prone) {
  const Path& P = md_.path;
  const double g = prone ? -1.0 : 1.0;  // the legacy supine pools are placed in both positions
  const std::vector<int> segs = prone ? std::vector<int>{1, 3, 4} : std::vector<int>{0, 2, 4};
  for (int ps : segs) {
    const double a = seg_start(ps), b = ps == 4 ? P.length : seg_end(ps);  // ascending + cecum
    std::size_t low = index_at(a + 10);
    auto in_stretch = [&](double s) {
      for (const TaggedStretch& t : md_.stretches)
        if (s > t.s0 - 10 && s < t.s1 + 10) return true;
      return false;
    };
    for (std::size_t i = index_at(a + 10); i <= index_at(b - 5); ++i)
      if (g * P.p[i].y() > g * P.p[low].y() && !in_stretch(P.s[i])) low = i;
    // Fluid surface: between 20 % and 55 % of the diameter from the dependent side.
    const double level = P.p[low].y() + g * P.r[low] * rng.uniform(-0.1, 0.6);
    const V3 seed = P.p[low] + V3(0, g, 0) * (0.5 * g * (level - P.p[low].y()) + 0.5 * P.r[low]);
    md_.pools.push_back({a, b, level, std::round(rng.uniform(320, 580)), seed});
  }
}

// Polyps: sizes 4-15 mm, sessile and pedunculated, on non-dependent (supine) walls between folds.
void PhantomLayout::place_polyps() {
  if (!o_.polyps) return;
  const Path& P = md_.path;
  const V3 up(0, -1, 0);  // anterior: away from gravity for a supine patient
  const std::vector<std::pair<double, std::string>> list = {{5, "sessile"}, {6, "pedunculated"}, {8, "sessile"},
                                                            {10, "pedunculated"}, {12, "sessile"}, {15, "pedunculated"},
                                                            {4, "sessile"}};
  int id = 1;
  for (const auto& [d, type] : list) {
    for (int attempt = 0; attempt < 400; ++attempt) {
      const double s = rng_.uniform(40, P.length - 40);
      const std::size_t i = index_at(s);
      const bool ped = type == "pedunculated";
      if (ped && P.r[i] < 19) continue;
      if (P.r[i] < d + 6 || nearest_fold_gap(s) < 0.5 * d + 5 || !free_s(s, d + 25)) continue;
      V3 u = cross_dir(i, up);
      const double rot = rng_.uniform(-0.9, 0.9);
      u = (std::cos(rot) * u + std::sin(rot) * P.T[i].cross(u)).normalized();
      if (in_pool_s(s) && u.dot(up) < 0.5) continue;
      Polyp p;
      p.axis = -u;  // from the wall towards the centreline
      p.base = P.p[i] + u * radius_at(md_, i, 0);
      if (ped) {
        p.center = p.base + p.axis * (std::clamp(0.6 * d, 5.0, 8.0) + 0.5 * d);
        p.stalk_r = std::max(1.2, std::max(0.18 * d, 0.7 * hmax_));
      } else {
        p.center = p.base + p.axis * (0.25 * d);  // a dome three quarters of a sphere high
      }
      p.gt = {id++, {p.center.x(), p.center.y(), p.center.z()}, d, type, kSegmentNames[P.seg[i]], s};
      md_.polyps.push_back(p);
      used_s_.push_back(s);
      break;
    }
  }
}

// Strands of tissue across the lumen (through the centreline) and holes through fold ridges.
void PhantomLayout::place_strands_and_holes() {
  if (!o_.topological_noise) return;
  const Path& P = md_.path;
  const double strand_r = std::max(0.8, 0.7 * hmax_);
  for (int n = 0, attempt = 0; n < 3 && attempt < 500; ++attempt) {
    const double s = rng_.uniform(60, P.length - 60);
    const std::size_t i = index_at(s);
    if (in_pool_s(s) || !free_s(s, 30) || nearest_fold_gap(s) < 6 || radius_at(md_, i, 0) < 14) continue;
    const double ang = rng_.uniform(0, 2 * kPi);
    const V3 u = (std::cos(ang) * P.N[i] + std::sin(ang) * P.B[i]).normalized();
    const double R = radius_at(md_, i, 0);
    md_.strands.push_back({P.p[i] - u * (R + 1.5), P.p[i] + u * (R + 1.5), strand_r, P.s[i]});
    md_.sites.push_back({0, "strand", {P.p[i].x(), P.p[i].y(), P.p[i].z()}, 2 * strand_r, "handle"});
    used_s_.push_back(s);
    ++n;
  }
  const double hole_r = std::max(0.9, 0.75 * hmax_);
  int made = 0;
  for (std::size_t f = 2; f < md_.folds.size() && made < 3; f += std::max<std::size_t>(1, md_.folds.size() / 4)) {
    Fold& fd = md_.folds[f];
    if (in_pool_s(fd.s) || !free_s(fd.s, 15)) continue;
    fd.depth = std::max(fd.depth, 0.42);
    fd.width = std::max(fd.width, hole_r * 1.6 + 0.6 * hmax_);
    const std::size_t i = index_at(fd.s);
    const double th = fd.theta0;  // the crescent peak: cos(3(theta - theta0)) = 1
    const V3 u = (std::cos(th) * P.N[i] + std::sin(th) * P.B[i]).normalized();
    const V3 c = P.p[i] + u * (radius_at(md_, i, 0) * (1 - 0.5 * fd.depth));
    md_.holes.push_back({c - P.T[i] * (3 * fd.width), c + P.T[i] * (3 * fd.width), hole_r, fd.s});
    md_.sites.push_back({0, "fold_hole", {c.x(), c.y(), c.z()}, 2 * hole_r, "handle"});
    used_s_.push_back(fd.s);
    ++made;
  }
}

// Other gas (stomach bubble, small-bowel gas) away from the colon.
void PhantomLayout::place_other_gas() {
  const Path& P = md_.path;
  const std::vector<std::pair<V3, V3>> cand = {
      {{40, -55, 128}, {22, 12, 10}}, {{-20, -70, -10}, {8, 6, 6}}, {{30, -70, 10}, {7, 6, 6}}, {{-40, -60, 20}, {6, 5, 5}}};
  for (const auto& [c, r] : cand) {
    double dmin = 1e9;
    for (std::size_t i = 0; i < P.p.size(); ++i) dmin = std::min(dmin, (P.p[i] - c).norm() - P.r[i] - r.maxCoeff());
    if (dmin > 12) md_.gas.push_back({c, r});
  }
}

}  // namespace cf::phantom_detail
