// Layout of the anatomy added for issues 13 and 17: fully tagged colon stretches, the prone
// position (mobile transverse and sigmoid colon displaced, features carried along), small-bowel
// loops with positive oral contrast and gas bubbles, the bladder with excreted contrast, the
// enhanced aorta and the rectal tube. All random draws come from extra_rng_, in the same order in
// both positions, so a seed gives the same anatomy supine and prone.
#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "phantom_model.h"

namespace cf::phantom_detail {

// Distance from q to the outer colon wall, in whichever position is nearer (supine and prone).
double PhantomLayout::colon_clearance(const V3& q) const {
  double d = 1e9;
  for (const Path* P : std::initializer_list<const Path*>{&md_.supine_path, &prone_path_})
    for (std::size_t i = 0; i < P->p.size(); i += 2) d = std::min(d, (P->p[i] - q).norm() - P->r[i] - md_.wall);
  return d;
}

// K stretches (descending, sigmoid, ascending) completely filled with tagged fluid, each between two
// collapsed necks (16 mm long, zero radius over their middle 35 %), so they touch no gas.
void PhantomLayout::place_tagged_stretches() {
  const Path& P = md_.path;
  const int segs[3] = {2, 1, 4};
  std::vector<double> seeds;
  for (const Pool& pool : md_.pools) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < P.p.size(); ++i)
      if ((P.p[i] - pool.seed).norm() < (P.p[best] - pool.seed).norm()) best = i;
    seeds.push_back(P.s[best]);
  }
  for (int k = 0; k < std::min(3, o_.fully_tagged_segments); ++k) {
    const double a = seg_start(segs[k]) + 15, b = seg_end(segs[k]) - 15;
    for (int attempt = 0; attempt < 200; ++attempt) {
      const double len = extra_rng_.uniform(60, 90);
      const double s0 = extra_rng_.uniform(a, std::max(a, b - len)), s1 = s0 + len;
      if (s1 > b || !free_s(s0, 16) || !free_s(s1, 16)) continue;
      bool holds_seed = false;
      for (double sd : seeds) holds_seed = holds_seed || (sd > s0 - 15 && sd < s1 + 15);
      if (holds_seed) continue;
      md_.collapses.push_back({s0, 16});
      md_.collapses.push_back({s1, 16});
      md_.folds.erase(std::remove_if(md_.folds.begin(), md_.folds.end(),
                                     [&](const Fold& f) { return std::abs(f.s - s0) < 10 || std::abs(f.s - s1) < 10; }),
                      md_.folds.end());
      md_.stretches.push_back({s0, s1, std::round(extra_rng_.uniform(350, 600))});
      used_s_.push_back(s0);
      used_s_.push_back(s1);
      break;
    }
  }
}

// The prone centreline: the mobile transverse and sigmoid colon move anteriorly (and along z) by
// a smooth displacement that vanishes at their fixed ends (sin^2 over each segment's arc length).
void PhantomLayout::make_prone_path() {
  const V3 d_trans(extra_rng_.uniform(-3, 3), -extra_rng_.uniform(7, 11), extra_rng_.uniform(6, 10));
  const V3 d_sig(extra_rng_.uniform(2, 6), -extra_rng_.uniform(5, 8), -extra_rng_.uniform(2, 5));
  const double t0 = seg_start(3), t1 = seg_end(3), g0 = seg_start(1), g1 = seg_end(1);
  prone_path_ = md_.supine_path;
  for (std::size_t i = 0; i < prone_path_.p.size(); ++i) {
    const double s = prone_path_.s[i];
    V3 d = V3::Zero();
    if (s > t0 && s < t1) d += std::pow(std::sin(kPi * (s - t0) / (t1 - t0)), 2) * d_trans;
    if (s > g0 && s < g1) d += std::pow(std::sin(kPi * (s - g0) / (g1 - g0)), 2) * d_sig;
    prone_path_.p[i] += d;
  }
  compute_frames(prone_path_);
  prone_path_.length = md_.supine_path.length;  // material length (s); arc holds the true length
}

// A point (or direction) attached to the supine frame at path index i, in the prone frame.
V3 PhantomLayout::to_prone(const V3& q, std::size_t i, bool direction) const {
  const Path &S = md_.supine_path, &Q = prone_path_;
  const V3 v = direction ? q : V3(q - S.p[i]);
  const V3 local(v.dot(S.T[i]), v.dot(S.N[i]), v.dot(S.B[i]));
  const V3 w = local.x() * Q.T[i] + local.y() * Q.N[i] + local.z() * Q.B[i];
  return direction ? w : V3(Q.p[i] + w);
}

// Moves every colon feature with its stretch of colon; the near-touching bulges are recomputed so
// that the two lumens stay one gap apart.
void PhantomLayout::deform_to_prone() {
  const Path& S = md_.supine_path;
  auto nearest = [&](const V3& q) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < S.p.size(); ++i)
      if ((S.p[i] - q).squaredNorm() < (S.p[best] - q).squaredNorm()) best = i;
    return best;
  };
  for (Polyp& p : md_.polyps) {
    const std::size_t i = index_at(p.gt.arclength_mm);
    p.center = to_prone(p.center, i, false);
    p.base = to_prone(p.base, i, false);
    p.axis = to_prone(p.axis, i, true);
    p.gt.center_lps_mm = {p.center.x(), p.center.y(), p.center.z()};
  }
  for (auto* caps : {&md_.strands, &md_.holes})
    for (Capsule& c : *caps) {
      const std::size_t i = index_at(c.s);
      c.a = to_prone(c.a, i, false);
      c.b = to_prone(c.b, i, false);
    }
  for (NoiseSite& site : md_.sites) {
    const V3 q(site.center_lps_mm[0], site.center_lps_mm[1], site.center_lps_mm[2]);
    const V3 m = to_prone(q, nearest(q), false);
    site.center_lps_mm = {m.x(), m.y(), m.z()};
  }
  md_.path = prone_path_;
  if (md_.bulges.size() == 2) {
    const Path& P = md_.path;
    const std::size_t bi = md_.touch_i, bj = md_.touch_j;
    const double need = std::max(0.0, (P.p[bi] - P.p[bj]).norm() - P.r[bi] - P.r[bj] - md_.touch_gap);
    const V3 dir = (P.p[bj] - P.p[bi]).normalized();
    md_.bulges[0] = {P.s[bi], need / 2, 8, cross_dir(bi, dir)};
    md_.bulges[1] = {P.s[bj], need / 2, 8, cross_dir(bj, -dir)};
  }
}

// One small-bowel loop: a C-shaped tube (radius 10-13 mm) in the mid abdomen, kept where it stays
// 8 mm clear of the colon in both positions, of the other organs and of the loops already placed.
bool PhantomLayout::add_bowel_loop() {
  const V3 c(extra_rng_.uniform(-45, 45), extra_rng_.uniform(-50, 5), extra_rng_.uniform(-95, 45));
  const double A = extra_rng_.uniform(22, 38), B = extra_rng_.uniform(18, 30), r = extra_rng_.uniform(10, 13);
  const double rot = extra_rng_.uniform(0, 2 * kPi), tilt = extra_rng_.uniform(-0.6, 0.6);
  const V3 e1(std::cos(rot), 0, std::sin(rot)), e2 = V3(-std::sin(rot), 0, std::cos(rot)) * std::cos(tilt) + V3(0, std::sin(tilt), 0);
  auto ok = [&](const V3& q) {
    if (colon_clearance(q) < r + 2 + 8) return false;
    for (const V3& d : {V3(1, 0, 0), V3(0, 1, 0), V3(0, 0, 1)})
      for (double sgn : {-1.0, 0.0, 1.0})
        if (body_material(q.x() + sgn * (r + 4) * d.x(), q.y() + sgn * (r + 4) * d.y(), q.z() + sgn * (r + 4) * d.z()) != kVisceralFat)
          return false;
    for (const auto& [gc, gr] : md_.gas)
      if ((q - gc).norm() < r + gr.maxCoeff() + 6) return false;
    if (md_.bladder && ((q - md_.bladder_c).cwiseQuotient(md_.bladder_r + V3::Constant(r + 8))).norm() < 1) return false;
    if (md_.aorta && std::sqrt(seg_point_dist2(q, md_.aorta_seg.a, md_.aorta_seg.b)) < r + md_.aorta_seg.r + 8) return false;
    for (const BowelLoop& other : md_.bowel)
      for (const V3& p : other.pts)
        if ((p - q).norm() < r + other.r + 6) return false;
    return true;
  };
  std::vector<V3> best, run;
  for (double t = 0; t <= 1.6 * kPi; t += 0.02) {
    const V3 q = c + A * std::cos(t) * e1 + B * std::sin(t) * e2 + V3(0, 8 * std::sin(2 * t), 0);
    if (ok(q)) {
      if (run.empty() || (q - run.back()).norm() >= 2) run.push_back(q);
    } else {
      if (run.size() > best.size()) best = run;
      run.clear();
    }
  }
  if (run.size() > best.size()) best = run;
  if (best.size() < 20) return false;  // at least ~40 mm
  BowelLoop loop;
  loop.pts = best;
  loop.r = r;
  loop.hu = md_.bowel.empty() ? std::round(extra_rng_.uniform(350, 550)) : md_.bowel.front().hu;
  double top = 1e9;  // the non-dependent extreme of the lumen, along gravity
  for (const V3& p : best) top = std::min(top, md_.gravity * p.y() - r);
  loop.gas_level = md_.bowel.size() % 2 == 0 ? top + extra_rng_.uniform(3, 5) : -1e9;  // every other loop holds gas
  md_.bowel.push_back(loop);
  return true;
}

void PhantomLayout::place_small_bowel() {
  if (!o_.oral_contrast) return;
  for (int attempt = 0; attempt < 40 && md_.bowel.size() < 4; ++attempt) add_bowel_loop();
}

// Bladder in the pelvis (excreted contrast in its dependent third, urine above) and the aorta
// (arterial enhancement) in front of the spine, each only where it stays clear of the colon.
void PhantomLayout::place_bladder_and_aorta() {
  if (o_.excreted_contrast) {
    V3 r(40, 30, 26);
    const V3 c(0, -40, -165);
    for (int shrink = 0; shrink < 4 && !md_.bladder; ++shrink, r *= 0.85) {
      bool clear = true;
      for (double th = 0; th < kPi && clear; th += 0.2)
        for (double ph = 0; ph < 2 * kPi && clear; ph += 0.2) {
          const V3 q = c + V3(r.x() * std::sin(th) * std::cos(ph), r.y() * std::sin(th) * std::sin(ph), r.z() * std::cos(th));
          clear = colon_clearance(q) > 3 + 6;
        }
      if (clear) {
        md_.bladder = true;
        md_.bladder_c = c;
        md_.bladder_r = r;
      }
    }
  }
  if (o_.enhanced_vessels) {
    const Capsule ao{{10, 58, -45}, {8, 55, 125}, 10, 0};
    bool clear = true;
    for (double t = 0; t <= 1 && clear; t += 0.02) clear = colon_clearance(ao.a + t * (ao.b - ao.a)) > ao.r + 5;
    md_.aorta = clear;
    md_.aorta_seg = ao;
  }
}

// A rectal catheter (outer radius 3.5 mm, air lumen 2.3 mm, open tip) from below the volume
// through the anal canal, 40 mm up the rectum along its centreline.
void PhantomLayout::place_rectal_tube() {
  const Path& P = md_.path;
  md_.tube.push_back({P.p[0] - P.T[0] * 45.0, P.p[0], 3.5, 0});
  for (std::size_t i = 0; i + 10 <= 40; i += 10) md_.tube.push_back({P.p[i], P.p[i + 10], 3.5, P.s[i]});
}

}  // namespace cf::phantom_detail
