// Distortion measures of the flat map (quasi-conformal ratio, area ratio), its coverage of the
// 3D wall, and their JSON form.
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "colonflat/core/params.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/union_find.h"
#include "flatten_internal.h"

namespace cf {
namespace flat_detail {

FaceFrame face_frame(const V3& p0, const V3& p1, const V3& p2) {
  const V3 e1 = p1 - p0, e2 = p2 - p0;
  const V3 n = e1.cross(e2);
  FaceFrame fr;
  fr.area3 = 0.5 * n.norm();
  const double l1 = e1.norm();
  if (fr.area3 <= 0 || l1 <= 0) return fr;
  const V3 x = e1 / l1, y = n.normalized().cross(x);
  Eigen::Matrix2d S;
  S << l1, e2.dot(x), 0, e2.dot(y);
  fr.s_inv = S.inverse();
  fr.valid = true;
  return fr;
}

namespace {

// |(a, b)| = sqrt(a^2 + b^2) as the rounded sum of squares' square root where that sum is a normal
// double (no overflow, no bits lost to underflow: within 1.5 ulp of the exact length, as
// std::hypot is within 1), else std::hypot. Every face of every distortion measure takes two (the
// stop check of the whole-band pass: 2 M faces per step); hypot, which scales its arguments to
// avoid overflow, was 2.9 % of the real CT flatten's CPU (docs/flatten.md, session 23).
double length2d(double a, double b) {
  const double sum = a * a + b * b;
  return sum >= std::numeric_limits<double>::min() && sum <= std::numeric_limits<double>::max() ? std::sqrt(sum)
                                                                                                 : std::hypot(a, b);
}

}  // namespace

FaceDistortion face_distortion(const FaceFrame& fr, const V2& q0, const V2& q1, const V2& q2) {
  FaceDistortion d{kInf, fr.area3, 0, false};
  const Eigen::Vector2d d1 = q1 - q0, d2 = q2 - q0;
  d.area2 = 0.5 * (d1.x() * d2.y() - d1.y() * d2.x());
  if (!fr.valid) return d;
  Eigen::Matrix2d Q;
  Q << d1.x(), d2.x(), d1.y(), d2.y();
  const Eigen::Matrix2d J = Q * fr.s_inv;
  const double E_ = (J(0, 0) + J(1, 1)) / 2, F = (J(0, 0) - J(1, 1)) / 2, G = (J(1, 0) + J(0, 1)) / 2,
               H = (J(1, 0) - J(0, 1)) / 2;
  const double Qn = length2d(E_, H), R = length2d(F, G);
  d.qc = std::abs(Qn - R) > 0 ? (Qn + R) / std::abs(Qn - R) : kInf;
  return d;
}

FaceDistortion face_distortion(const V3& p0, const V3& p1, const V3& p2, const V2& q0, const V2& q1, const V2& q2) {
  return face_distortion(face_frame(p0, p1, p2), q0, q1, q2);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

namespace {

// A value's bucket: the top kBucketBits of its bit pattern (sign, exponent, 4 mantissa bits), which
// for values >= +0 (-0 counts as +0) orders like the values; 16 buckets per power of two, so a
// bucket holds a few % of a band's area ratios at most.
constexpr int kBucketBits = 16;
constexpr std::size_t kBuckets = std::size_t(1) << kBucketBits;
std::size_t bucket_of(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return x > 0 ? std::size_t(bits >> (64 - kBucketBits)) : 0;
}

// The values per bucket, counted in one chunk of v per thread (integer counts: the same for any
// thread count). False when a value is negative or NaN (the buckets do not order those).
bool bucket_counts(const std::vector<double>& v, std::vector<std::uint64_t>& total) {
  const std::size_t chunks = std::size_t(std::max(1, thread_count()));
  std::vector<std::vector<std::uint32_t>> part(chunks, std::vector<std::uint32_t>(kBuckets, 0));
  std::vector<char> ordered(chunks, 1);
  parallel_for(chunks, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      for (std::size_t i = v.size() * c / chunks; i < v.size() * (c + 1) / chunks; ++i) {
        ordered[c] &= char(v[i] >= 0);
        ++part[c][bucket_of(v[i])];
      }
  });
  total.assign(kBuckets, 0);
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t b = 0; b < kBuckets; ++b) total[b] += part[c][b];
  return std::all_of(ordered.begin(), ordered.end(), [](char o) { return o != 0; });
}

// v's values in `bucket` (in chunk order; their order does not change an order statistic).
std::vector<double> values_in_bucket(const std::vector<double>& v, std::size_t bucket) {
  const std::size_t chunks = std::size_t(std::max(1, thread_count()));
  std::vector<std::vector<double>> part(chunks);
  parallel_for(chunks, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      for (std::size_t i = v.size() * c / chunks; i < v.size() * (c + 1) / chunks; ++i)
        if (bucket_of(v[i]) == bucket) part[c].push_back(v[i]);
  });
  std::vector<double> out;
  for (const std::vector<double>& p : part) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace

OrderStatistics order_statistics(std::vector<double>& v, const std::vector<std::size_t>& ks) {
  OrderStatistics out;
  std::vector<std::uint64_t> count;
  // fewer values than buckets: counting them costs more than nth_element over them
  if (v.size() < kBuckets || v.size() >= std::numeric_limits<std::uint32_t>::max() || !bucket_counts(v, count)) {
    for (std::size_t k : ks) {
      std::nth_element(v.begin(), v.begin() + long(k), v.end());
      out.values.push_back(v[k]);
    }
    out.searched = v.size() * ks.size();
    return out;
  }
  for (std::size_t k : ks) {
    std::size_t bucket = 0, below = 0;
    while (below + count[bucket] <= k) below += count[bucket++];
    std::vector<double> in = values_in_bucket(v, bucket);
    std::nth_element(in.begin(), in.begin() + long(k - below), in.end());
    out.values.push_back(in[k - below]);
    out.searched += in.size();
  }
  return out;
}

BoundStats bound_stats_in_map(const std::vector<FaceDistortion>& fd, std::vector<double>* scratch) {
  auto in_map = [](const FaceDistortion& d) { return !d.degenerate && !too_small_in_map(d.area2, d.area3); };
  double a3 = 0, a2 = 0, qsum = 0;  // sums in face order, as stats_of adds them
  std::size_t n = 0;
  for (const FaceDistortion& d : fd)
    if (in_map(d)) a3 += d.area3, a2 += std::abs(d.area2), ++n, qsum += std::isfinite(d.qc) ? d.qc : 1e9;
  const double scale = a2 > 0 ? a3 / a2 : 1;
  std::vector<double> own;
  std::vector<double>& ratio = scratch ? *scratch : own;
  ratio.clear();
  ratio.reserve(fd.size());
  for (const FaceDistortion& d : fd)
    if (in_map(d) && d.area3 > 0) ratio.push_back(std::abs(d.area2) * scale / d.area3);
  BoundStats b;
  b.qc_mean = n ? qsum / double(n) : 0;
  if (ratio.empty()) return b;
  // percentile()'s order statistics
  const std::size_t k05 = std::min(ratio.size() - 1, std::size_t(0.05 * double(ratio.size() - 1) + 0.5));
  const std::size_t k95 = std::min(ratio.size() - 1, std::size_t(0.95 * double(ratio.size() - 1) + 0.5));
  const OrderStatistics q = order_statistics(ratio, {k05, k95});
  b.area_p05 = q.values[0], b.area_p95 = q.values[1];
  return b;
}

DistortionStats stats_of(const std::vector<FaceDistortion>& fd) {
  DistortionStats s;
  s.faces = fd.size();
  if (fd.empty()) return s;
  std::vector<double> qc, ar;
  qc.reserve(fd.size());
  ar.reserve(fd.size());
  double a3 = 0, a2 = 0;
  for (const auto& d : fd) a3 += d.area3, a2 += std::abs(d.area2);
  const double scale = a2 > 0 ? a3 / a2 : 1;
  double qsum = 0, lsum = 0, wsum = 0;
  for (const auto& d : fd) {
    if (d.degenerate) {
      ++s.degenerate;
      continue;
    }
    if (d.area2 <= 0) ++s.flipped;
    const double q = std::isfinite(d.qc) ? d.qc : 1e9;
    qc.push_back(q);
    qsum += q;
    s.qc_max = std::max(s.qc_max, q);
    if (d.area3 > 0) {
      const double r = std::abs(d.area2) * scale / d.area3;
      ar.push_back(r);
      if (r > 0) lsum += d.area3 * std::abs(std::log2(r)), wsum += d.area3;
    }
  }
  s.qc_mean = qc.empty() ? 0 : qsum / double(qc.size());
  s.qc_p95 = percentile(qc, 0.95);
  s.area_p05 = percentile(ar, 0.05);
  s.area_median = percentile(ar, 0.5);
  s.area_p95 = percentile(ar, 0.95);
  s.area_log2_mean_abs = wsum > 0 ? lsum / wsum : 0;
  return s;
}


Coverage coverage_of(const Surface& s, const Edges& E, const std::vector<char>& in_map,
                     const std::vector<double>& ratio, double min_ratio, double removed_cap_area) {
  Coverage c;
  c.end_cap_area_mm2 = removed_cap_area;
  UnionFind uf(s.t.size());
  std::vector<char> hidden(s.t.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const double a = face_area_3d(s, int(f));
    c.wall_area_mm2 += a;
    if (!in_map[f]) c.missing_area_mm2 += a, hidden[f] = 1;
    else if (ratio[f] < min_ratio) c.compressed_area_mm2 += a, hidden[f] = 1;
    else c.shown_area_mm2 += a;
  }
  c.fraction = c.wall_area_mm2 > 0 ? c.shown_area_mm2 / c.wall_area_mm2 : 1.0;
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (E.ef[e][1] >= 0 && hidden[E.ef[e][0]] && hidden[E.ef[e][1]]) uf.unite(E.ef[e][0], E.ef[e][1]);
  std::unordered_map<std::size_t, Coverage::Cluster> clusters;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (!hidden[f]) continue;
    auto& cl = clusters[uf.find(f)];
    const double a = face_area_3d(s, int(f));
    const Tri& t = s.t[f];
    const V3 m = (s.p[t[0]] + s.p[t[1]] + s.p[t[2]]) / 3 * a;
    for (int k = 0; k < 3; ++k) cl.centroid_lps_mm[k] += m[k];
    cl.area_mm2 += a;
    ++cl.faces;
  }
  for (auto& [root, cl] : clusters) {
    for (double& x : cl.centroid_lps_mm) x /= std::max(cl.area_mm2, 1e-300);
    c.not_shown.push_back(cl);
  }
  std::sort(c.not_shown.begin(), c.not_shown.end(), [](const auto& a, const auto& b) { return a.area_mm2 > b.area_mm2; });
  if (c.not_shown.size() > 20) c.not_shown.resize(20);
  return c;
}

}  // namespace flat_detail

using flat_detail::FaceDistortion;
using flat_detail::V3;

// The triangles' distortions (of `segment`'s only when >= 0) in triangle order, on the worker
// threads (each face on its own: the same values for any thread count).
DistortionStats distortion_stats(const FlatMap& flat, int segment) {
  std::vector<std::size_t> picked;  // segment >= 0: its triangles
  if (segment >= 0)
    for (std::size_t k = 0; k < flat.triangles.size(); ++k)
      if (flat.segment[flat.triangles[k][0]] == segment) picked.push_back(k);
  std::vector<FaceDistortion> fd(segment >= 0 ? picked.size() : flat.triangles.size());
  parallel_for(fd.size(), [&](std::size_t begin, std::size_t end) {
    auto P = [&](int i) { return V3(flat.position[i][0], flat.position[i][1], flat.position[i][2]); };
    auto Q = [&](int i) { return flat_detail::V2(flat.uv[i][0], flat.uv[i][1]); };
    for (std::size_t k = begin; k < end; ++k) {
      const auto& t = flat.triangles[segment >= 0 ? picked[k] : k];
      fd[k] = flat_detail::face_distortion(P(t[0]), P(t[1]), P(t[2]), Q(t[0]), Q(t[1]), Q(t[2]));
    }
  });
  double mean = 0;
  for (const auto& d : fd) mean += d.area3;
  mean /= std::max<std::size_t>(1, fd.size());
  for (auto& d : fd) d.degenerate = d.area3 <= 1e-6 * mean;
  return flat_detail::stats_of(fd);
}

nlohmann::json distortion_to_json(const DistortionStats& s) {
  return {{"faces", s.faces},
          {"flipped_triangles", s.flipped},
          {"degenerate_triangles", s.degenerate},
          {"quasi_conformal_mean", s.qc_mean},
          {"quasi_conformal_p95", s.qc_p95},
          {"quasi_conformal_max", s.qc_max},
          {"area_ratio_p05", s.area_p05},
          {"area_ratio_median", s.area_median},
          {"area_ratio_p95", s.area_p95},
          {"area_log2_mean_abs", s.area_log2_mean_abs}};
}


nlohmann::json coverage_to_json(const Coverage& c) {
  nlohmann::json cl = nlohmann::json::array();
  for (const auto& k : c.not_shown)
    cl.push_back({{"centroid_lps_mm", k.centroid_lps_mm}, {"area_mm2", k.area_mm2}, {"faces", k.faces}});
  return {{"fraction_shown", c.fraction},
          {"wall_area_mm2", c.wall_area_mm2},
          {"shown_area_mm2", c.shown_area_mm2},
          {"compressed_area_mm2", c.compressed_area_mm2},
          {"missing_area_mm2", c.missing_area_mm2},
          {"end_cap_area_mm2", c.end_cap_area_mm2},
          {"not_shown_clusters", cl}};
}

Coverage coverage_from_json(const nlohmann::json& j) {
  Coverage c;
  c.fraction = j.value("fraction_shown", 1.0);
  c.wall_area_mm2 = j.value("wall_area_mm2", 0.0);
  c.shown_area_mm2 = j.value("shown_area_mm2", 0.0);
  c.compressed_area_mm2 = j.value("compressed_area_mm2", 0.0);
  c.missing_area_mm2 = j.value("missing_area_mm2", 0.0);
  c.end_cap_area_mm2 = j.value("end_cap_area_mm2", 0.0);
  if (j.contains("not_shown_clusters"))
    for (const auto& k : j["not_shown_clusters"]) {
      Coverage::Cluster cl;
      cl.centroid_lps_mm = k.at("centroid_lps_mm").get<std::array<double, 3>>();
      cl.area_mm2 = k.value("area_mm2", 0.0);
      cl.faces = k.value("faces", std::size_t(0));
      c.not_shown.push_back(cl);
    }
  return c;
}

nlohmann::json segment_to_json(const FlatSegment& s) {
  nlohmann::json j = {{"id", s.id},
                      {"component", s.component},
                      {"input", s.input_kind},
                      {"rectangle_mm", {{"x0", s.x0}, {"y0", s.y0}, {"length", s.length}, {"period", s.period}}},
                      {"area_3d_mm2", s.area_3d},
                      {"faces", s.faces},
                      {"vertices", s.vertices},
                      {"removed_end_faces", s.removed_faces},
                      {"end_a_lps_mm", s.end_a},
                      {"end_b_lps_mm", s.end_b},
                      {"weights", s.weights},
                      {"untangled_vertices", s.untangled_vertices},
                      {"crowded_faces_left_out", s.crowded_faces},
                      {"inverted_faces_left_out", s.inverted_faces},
                      {"period_consistency", s.dirichlet_period_ratio},
                      {"distortion", distortion_to_json(s.stats)}};
  if (s.map.empty()) return j;
  j["map"] = s.map;
  j["centreline_lps_mm"] = s.centreline;
  j["centreline_length_mm"] = s.centreline_length;
  if (!s.centreline_x.empty()) j["centreline_to_x_mm"] = s.centreline_x;
  j["x0_end"] = s.x0_end;
  j["x1_end"] = s.x1_end;
  j["order"] = s.order;
  j["centreline_offset_mm"] = s.centreline_offset;
  j["balanced_vertices"] = s.balanced_vertices;
  j["area_correction_iterations"] = s.corrected_iterations;
  j["balance_strength"] = s.balance_strength;
  j["coverage"] = coverage_to_json(s.coverage);
  j["kind"] = s.kind;
  if (s.kind == "branch") {
    j["parent"] = s.parent;
    j["attach_mm"] = s.attach_mm;
    j["attach_lps_mm"] = s.attach_lps;
    j["neck_mm"] = s.neck_mm;
    j["holds"] = s.holds;
  }
  return j;
}

nlohmann::json flat_report(const FlatMap& f) {
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : f.segments) segs.push_back(segment_to_json(s));
  return {{"segments", segs},
          {"segment_count", f.segments.size()},
          {"skipped_components", f.skipped_components},
          {"skipped", f.skipped},
          {"flat_vertices", f.uv.size()},
          {"flat_triangles", f.triangles.size()},
          {"coverage", coverage_to_json(f.coverage)},
          {"distortion", distortion_to_json(f.stats)}};
}

}  // namespace cf

namespace cf::flat_detail {

// Distortion, faces left out (zero or negative area) and coverage of a segment.
void measure(SegmentWork& w, const Edges& E, const std::vector<char>& degenerate, const FlattenOptions& o) {
  const Surface& s = w.ann;
  const std::vector<FaceDistortion> fd = band_distortion(w, degenerate);
  w.in_map.assign(s.t.size(), 1);
  std::vector<FaceDistortion> kept;
  kept.reserve(fd.size());
  double a2 = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    if (!degenerate[f] && too_small_in_map(fd[f].area2, fd[f].area3)) {
      w.in_map[f] = 0, ++w.seg.crowded_faces;
      w.seg.inverted_faces += fd[f].area2 < 0;
    } else kept.push_back(fd[f]), a2 += std::abs(fd[f].area2);
  }
  w.seg.stats = stats_of(kept);
  const double scale = a2 > 0 ? w.seg.area_3d / a2 : 1.0;
  std::vector<double> ratio(s.t.size(), 1.0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (!degenerate[f] && fd[f].area3 > 0) ratio[f] = fd[f].area2 * scale / fd[f].area3;
  Coverage& c = w.seg.coverage;
  c = coverage_of(s, E, w.in_map, ratio, o.coverage_min_ratio, w.cap_area);
  c.wall_area_mm2 += w.lost_area;  // faces dropped at a branch's neck, a branch tip's cap
  c.missing_area_mm2 += w.lost_area;
  c.fraction = c.wall_area_mm2 > 0 ? c.shown_area_mm2 / c.wall_area_mm2 : 1.0;
}

}  // namespace cf::flat_detail
