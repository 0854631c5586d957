// Colon segments and fully tagged stretches: components of gas + pools + layer are colon segments
// when they hold enough gas; fluid bodies without gas above them (and fluid-dominated bodies with a
// little gas: small bowel) are kept only as fully tagged colon stretches: they continue the path of
// a colon segment from its end across a short gap (a collapsed or fluid-filled neck).
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <deque>
#include <iomanip>
#include <numeric>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kGas = 1, kPool = 2, kLayer = 3, kCandidate = 4;
bool colon_kind(unsigned char v) { return v == kGas || v == kPool || v == kLayer; }
std::string fixed1(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << v;
  return s.str();
}
}  // namespace

// Components of gas + pools + layer, largest first: kept while they hold >= min-segment-volume of
// gas, reach min-segment-fraction of the largest and max-segments is not reached. Rejected bodies
// with enough fluid become candidates for fully tagged stretches (lab 4).
void ColonSegmenter::select_segments() {
  MaskImage::Pointer work = mask_of_size(d_.n);
  unsigned char* w = work->GetBufferPointer();
  for (std::size_t q = 0; q < d_.total; ++q) w[q] = colon_kind(lab_[q]);
  std::uint32_t n = 0;
  LabelImage::Pointer cl = components(work, n);
  const std::uint32_t* clb = cl->GetBufferPointer();
  std::vector<BodyStats> bodies(n + 1);
  for (std::size_t k = 0, q = 0; k < d_.n[2]; ++k)
    for (std::size_t j = 0; j < d_.n[1]; ++j)
      for (std::size_t i = 0; i < d_.n[0]; ++i, ++q) {
        BodyStats& b = bodies[clb[q]];
        ++b.voxels;
        b.gas += lab_[q] == kGas;
        b.sum[0] += double(i), b.sum[1] += double(j), b.sum[2] += double(k);
      }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 1u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return bodies[a].voxels > bodies[b].voxels; });
  std::vector<unsigned char> fate(n + 1, 0);  // 1 kept, 2 candidate, 0 rejected
  std::vector<double> vols;
  for (std::uint32_t l : order) {
    const BodyStats& b = bodies[l];
    const double ml = double(b.voxels) * voxel_ml_, gas_ml = double(b.gas) * voxel_ml_;
    const double c[3] = {b.sum[0] / double(b.voxels), b.sum[1] / double(b.voxels), b.sum[2] / double(b.voxels)};
    std::string reason;
    if (gas_ml < opts_.min_segment_volume) reason = "less gas than --min-segment-volume";
    else if (int(vols.size()) >= opts_.max_segments) reason = "more segments than --max-segments";
    else if (!vols.empty() && ml < opts_.min_segment_fraction * vols.front()) reason = "below --min-segment-fraction of the largest";
    if (reason.empty()) {
      fate[l] = 1;
      vols.push_back(ml);
      decide("segment", ml, c, true, "colon segment (" + fixed1(gas_ml) + " mL gas)");
    } else if (ml - gas_ml >= opts_.min_tagged_volume || gas_ml >= opts_.min_segment_volume) {
      fate[l] = 2;  // decided with the fully tagged candidates: kept if it continues the colon
    } else {
      ++st_.removed_components;
      decide(b.gas == b.voxels ? "gas body" : "segment", ml, c, false, reason);
    }
  }
  seg_label_.assign(d_.total, 0);
  for (std::size_t q = 0; q < d_.total; ++q) {
    if (colon_kind(lab_[q]) && fate[clb[q]] != 1) lab_[q] = fate[clb[q]] == 2 ? kCandidate : 0;
    if (fate[clb[q]] == 1) seg_label_[q] = clb[q];
  }
  if (vols.empty())
    throw PreconditionError("no colon found: no gas/fluid body inside the body of at least " +
                            format_number(opts_.min_segment_volume) + " mL");
  const double total = std::accumulate(vols.begin(), vols.end(), 0.0);
  if (total < opts_.min_colon_volume)
    throw PreconditionError("no colon found: the gas/fluid bodies inside the body total " + fixed1(total) +
                            " mL, less than --min-colon-volume " + format_number(opts_.min_colon_volume) +
                            " mL (an insufflated colon holds several hundred mL)");
}

// Candidates (lab 4): kept when they continue a colon segment's end within link-gap, in passes
// (a stretch kept in one pass is colon for the next: chains of stretches and small gas pieces
// between them); the last pass rejects every other candidate with its reason.
void ColonSegmenter::link_tagged_stretches() {
  for (int pass = 0; pass < 6; ++pass)
    if (link_pass(false) == 0) break;
  link_pass(true);
  std::vector<std::uint32_t>().swap(cand_label_);
  std::vector<std::uint32_t>().swap(seg_label_);
}

std::size_t ColonSegmenter::link_pass(bool last) {
  MaskImage::Pointer work = mask_of_size(d_.n);
  unsigned char* w = work->GetBufferPointer();
  for (std::size_t q = 0; q < d_.total; ++q) w[q] = lab_[q] == kCandidate;
  std::uint32_t n = 0;
  LabelImage::Pointer cl = components(work, n);
  cand_label_.assign(cl->GetBufferPointer(), cl->GetBufferPointer() + d_.total);
  cl = nullptr;
  work = nullptr;
  std::vector<BodyStats> bodies(n + 1);
  for (std::size_t k = 0, q = 0; k < d_.n[2]; ++k)
    for (std::size_t j = 0; j < d_.n[1]; ++j)
      for (std::size_t i = 0; i < d_.n[0]; ++i, ++q) {
        BodyStats& b = bodies[cand_label_[q]];
        ++b.voxels;
        b.gas += hu_[q] < opts_.air_threshold;
        b.sum[0] += double(i), b.sum[1] += double(j), b.sum[2] += double(k);
        b.touches_face = b.touches_face || i == 0 || j == 0 || k == 0 || i + 1 == d_.n[0] || j + 1 == d_.n[1] || k + 1 == d_.n[2];
      }
  std::vector<std::size_t> from(n + 1, SIZE_MAX), to(n + 1, SIZE_MAX);
  std::vector<double> gap(n + 1, 1e9);
  if (n > 0) nearest_colon(bodies, from, to, gap);
  std::vector<std::uint32_t> keep(n + 1, 0);  // new segment label of a kept candidate
  std::size_t kept = 0;
  for (std::uint32_t l = 1; l <= n; ++l) {
    const BodyStats& b = bodies[l];
    const double ml = double(b.voxels) * voxel_ml_;
    const double c[3] = {b.sum[0] / double(b.voxels), b.sum[1] / double(b.voxels), b.sum[2] / double(b.voxels)};
    const std::string what = 2 * b.gas > b.voxels ? "gas body" : (b.gas > 0 ? "fluid body with gas" : "fluid body");
    std::string why;
    if (ml < opts_.min_tagged_volume) why = "smaller than --min-tagged-volume";
    else if (b.touches_face) why = "reaches beyond the colon's region (bone, vessel, bladder)";
    else if (from[l] == SIZE_MAX) why = "no colon segment end within --link-gap";
    else if (continues_colon(l, from[l], to[l], why)) {
      keep[l] = 0x80000000u + std::uint32_t(++linked_);
      ++kept;
      if (what != "gas body") ++st_.tagged_stretches, st_.tagged_stretch_volume_ml += ml;
      decide(what, ml, c, true,
             (what == "gas body" ? "colon segment continuing a segment's end (gap " : "fully tagged colon stretch continuing a segment's end (gap ") +
                 fixed1(gap[l]) + " mm)");
      continue;
    }
    if (!last) continue;
    ++st_.rejected_fluid_components;
    decide(what, ml, c, false, why);
  }
  for (std::size_t q = 0; q < d_.total; ++q) {
    if (lab_[q] != kCandidate) continue;
    const std::uint32_t l = cand_label_[q];
    if (keep[l]) lab_[q] = hu_[q] < opts_.air_threshold ? kGas : kPool, seg_label_[q] = keep[l];
    else if (last) lab_[q] = 0;
  }
  return kept;
}

// Breadth-first growth from the colon segments through everything else, up to link-gap: per
// candidate the voxel reached first (`from`), the colon voxel it was reached from (`to`), the gap.
void ColonSegmenter::nearest_colon(const std::vector<BodyStats>& bodies, std::vector<std::size_t>& from,
                                   std::vector<std::size_t>& to, std::vector<double>& gap) const {
  const double hmin = std::min({d_.sp[0], d_.sp[1], d_.sp[2]});
  const int max_steps = int(std::ceil(opts_.link_gap / hmin)) + 1;
  std::vector<std::uint32_t> source(d_.total, UINT32_MAX);
  std::vector<std::size_t> front, next;
  for (std::size_t q = 0; q < d_.total; ++q)
    if (colon_kind(lab_[q])) source[q] = std::uint32_t(q), front.push_back(q);
  for (int step = 1; step <= max_steps && !front.empty(); ++step) {
    next.clear();
    for (std::size_t q : front) {
      std::size_t c[3];
      d_.coords(q, c[0], c[1], c[2]);
      for (int a = 0; a < 3; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
          if ((dir < 0 && c[a] == 0) || (dir > 0 && c[a] + 1 == d_.n[a])) continue;
          const std::size_t r = dir < 0 ? q - d_.stride[a] : q + d_.stride[a];
          if (source[r] != UINT32_MAX) continue;
          source[r] = source[q];
          const std::uint32_t l = cand_label_[r];
          if (l && from[l] == SIZE_MAX) {
            std::size_t s[3];
            d_.coords(source[r], s[0], s[1], s[2]);
            double g2 = 0;
            for (int b = 0; b < 3; ++b) g2 += std::pow((double(c[b]) - double(s[b])) * d_.sp[b], 2);
            if (std::sqrt(g2) <= opts_.link_gap + hmin) from[l] = r, to[l] = source[r], gap[l] = std::sqrt(g2);
          }
          if (!l) next.push_back(r);  // grow through the gap, not through other candidates
        }
    }
    front.swap(next);
  }
  (void)bodies;
}

// Centroid and principal axis (mm, crop frame) of the voxels with `pred` within radius_mm of centre.
std::size_t ColonSegmenter::local_shape(const std::function<bool(std::size_t)>& pred, std::size_t centre, double radius_mm,
                                        std::array<double, 3>& centroid, std::array<double, 3>& axis) const {
  std::size_t c[3];
  d_.coords(centre, c[0], c[1], c[2]);
  std::size_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const std::size_t r = std::size_t(std::ceil(radius_mm / d_.sp[a]));
    lo[a] = c[a] > r ? c[a] - r : 0;
    hi[a] = std::min(d_.n[a] - 1, c[a] + r);
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sq = Eigen::Matrix3d::Zero();
  std::size_t count = 0;
  for (std::size_t k = lo[2]; k <= hi[2]; ++k)
    for (std::size_t j = lo[1]; j <= hi[1]; ++j)
      for (std::size_t i = lo[0]; i <= hi[0]; ++i) {
        const Eigen::Vector3d p((double(i) - double(c[0])) * d_.sp[0], (double(j) - double(c[1])) * d_.sp[1],
                                (double(k) - double(c[2])) * d_.sp[2]);
        if (p.squaredNorm() > radius_mm * radius_mm || !pred(d_.idx(i, j, k))) continue;
        sum += p;
        sq += p * p.transpose();
        ++count;
      }
  if (count < 4) return count;
  const Eigen::Vector3d mean = sum / double(count);
  const Eigen::Matrix3d cov = sq / double(count) - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  const Eigen::Vector3d ax = es.eigenvectors().col(2);
  for (int a = 0; a < 3; ++a) centroid[a] = mean[a], axis[a] = ax[a];
  return count;
}

// The candidate continues the colon: at the link, both bodies end (their local mass lies behind
// the link point along their own axis) and point at each other.
bool ColonSegmenter::continues_colon(std::uint32_t cand, std::size_t from, std::size_t to, std::string& why) const {
  // Two ball radii: 45 mm (a tube piece longer than the colon is wide) and 30 mm (a bending sigmoid).
  for (double radius : {std::max(45.0, 1.5 * opts_.link_gap), 30.0})
    if (continues_colon_at(cand, from, to, radius, why)) return true;
  return false;
}

bool ColonSegmenter::continues_colon_at(std::uint32_t cand, std::size_t from, std::size_t to, double radius,
                                        std::string& why) const {
  std::array<double, 3> cg{}, ag{}, cf{}, af{};
  const std::uint32_t segment = seg_label_[to];
  const std::size_t ng = local_shape([&](std::size_t q) { return seg_label_[q] == segment; }, to, radius, cg, ag);
  const std::size_t nf = local_shape([&](std::size_t q) { return cand_label_[q] == cand; }, from, radius, cf, af);
  if (ng < 4 || nf < 4) return why = "too small near the link", false;
  std::size_t a[3], b[3];
  d_.coords(to, a[0], a[1], a[2]);
  d_.coords(from, b[0], b[1], b[2]);
  Eigen::Vector3d link, axg(ag[0], ag[1], ag[2]), axf(af[0], af[1], af[2]);
  for (int k = 0; k < 3; ++k) link[k] = (double(b[k]) - double(a[k])) * d_.sp[k];
  const Eigen::Vector3d ug = -Eigen::Vector3d(cg[0], cg[1], cg[2]);  // colon end -> out of the colon
  const Eigen::Vector3d uf(cf[0], cf[1], cf[2]);                      // candidate end -> into the candidate
  if (ug.norm() < 0.15 * radius || uf.norm() < 0.15 * radius) return why = "touches the colon's side, not an end", false;
  if (std::abs(ug.normalized().dot(axg)) < 0.6) return why = "lies beside a colon segment, not at its end", false;
  if (std::abs(uf.normalized().dot(axf)) < 0.6) return why = "meets the colon with its side (not tube-shaped there)", false;
  if (ug.normalized().dot(uf.normalized()) < 0.5) return why = "does not continue the colon's direction", false;
  if (link.norm() > 1e-9 && ug.normalized().dot(link.normalized()) < 0.3) return why = "does not continue the colon's direction", false;
  return true;
}

}  // namespace cf::segment_detail
