#include "colonflat/register/profile.h"

#include <algorithm>
#include <map>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "colonflat/core/error.h"

namespace cf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 6.283185307179586;

// Mean of `values` per bin index (bins without vertices are filled by linear interpolation).
std::vector<Eigen::Vector3d> bin_centroids(const std::vector<double>& s, const std::vector<Eigen::Vector3d>& lps,
                                           double bin_mm, int bins, std::vector<int>& count) {
  std::vector<Eigen::Vector3d> sum(size_t(bins), Eigen::Vector3d::Zero());
  count.assign(size_t(bins), 0);
  for (size_t v = 0; v < s.size(); ++v) {
    if (std::isnan(s[v])) continue;
    const int k = std::clamp(int(s[v] / bin_mm), 0, bins - 1);
    sum[size_t(k)] += lps[v];
    ++count[size_t(k)];
  }
  std::vector<int> filled;
  for (int k = 0; k < bins; ++k)
    if (count[size_t(k)] > 0) {
      sum[size_t(k)] /= count[size_t(k)];
      filled.push_back(k);
    }
  if (filled.empty()) return sum;
  for (int k = 0; k < bins; ++k) {
    if (count[size_t(k)] > 0) continue;
    auto hi = std::lower_bound(filled.begin(), filled.end(), k);
    if (hi == filled.begin()) sum[size_t(k)] = sum[size_t(*hi)];
    else if (hi == filled.end()) sum[size_t(k)] = sum[size_t(filled.back())];
    else {
      const int a = *(hi - 1), b = *hi;
      const double w = double(k - a) / double(b - a);
      sum[size_t(k)] = (1 - w) * sum[size_t(a)] + w * sum[size_t(b)];
    }
  }
  return sum;
}

std::vector<Eigen::Vector3d> smooth_points(const std::vector<Eigen::Vector3d>& p, double sigma) {
  std::vector<Eigen::Vector3d> out(p.size());
  for (int c = 0; c < 3; ++c) {
    std::vector<double> x(p.size());
    for (size_t i = 0; i < p.size(); ++i) x[i] = p[i][c];
    x = gaussian_smooth(x, sigma);
    for (size_t i = 0; i < p.size(); ++i) out[i][c] = x[i];
  }
  return out;
}

int largest_segment(const ColonScan& scan) {
  std::vector<int> n;
  for (int g : scan.segment) {
    if (g < 0) continue;
    if (g >= int(n.size())) n.resize(size_t(g) + 1, 0);
    ++n[size_t(g)];
  }
  return int(std::max_element(n.begin(), n.end()) - n.begin());
}

// The label of end x0 of segment `id` in FlatSegments ("" when absent).
std::string x0_label(const ColonScan& scan, int id) {
  for (const auto& seg : scan.segments)
    if (seg.value("id", -1) == id && seg.contains("x0_end") && seg["x0_end"].is_string())
      return seg["x0_end"].get<std::string>();
  return "";
}

// s from the flat x of the largest segment: arc length of the centroid line of x-slices.
std::vector<double> axial_from_flat_x(const ColonScan& scan, const ProfileOptions& o, ScanCoordinates& c) {
  const int seg = largest_segment(scan);
  const size_t n = scan.uv.size();
  std::vector<double> t(n, kNaN);
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (size_t v = 0; v < n; ++v)
    if (scan.segment[v] == seg) lo = std::min(lo, scan.uv[v].x()), hi = std::max(hi, scan.uv[v].x());
  const std::string label = x0_label(scan, seg);
  const bool flip = label == "cecum";
  c.from_rectum = label == "rectum" || label == "cecum";
  for (size_t v = 0; v < n; ++v)
    if (scan.segment[v] == seg) t[v] = flip ? hi - scan.uv[v].x() : scan.uv[v].x() - lo;
  const int bins = std::max(1, int(std::ceil((hi - lo) / o.bin_mm)));
  std::vector<int> count;
  auto centre = smooth_points(bin_centroids(t, scan.lps, o.bin_mm, bins, count), o.smooth_mm / o.bin_mm);
  std::vector<double> arc(size_t(bins), 0.0);  // arc length at bin centres
  for (int k = 1; k < bins; ++k) arc[size_t(k)] = arc[size_t(k) - 1] + (centre[size_t(k)] - centre[size_t(k) - 1]).norm();
  std::vector<double> s(n, kNaN);
  for (size_t v = 0; v < n; ++v) {
    if (std::isnan(t[v])) continue;
    const double f = std::clamp(t[v] / o.bin_mm - 0.5, 0.0, double(bins - 1));
    const int k = std::min(int(f), bins - 2 < 0 ? 0 : bins - 2);
    const double w = f - k;
    s[v] = bins == 1 ? 0.0 : (1 - w) * arc[size_t(k)] + w * arc[size_t(k) + 1] + 0.5 * o.bin_mm;
  }
  c.axial_source = "flat x of segment " + std::to_string(seg);
  return s;
}

// A side branch's vertices (a pouch flattened as a band of its own, flatten's FlatSegments
// kind "branch") carry centreline mm along the pouch; along the colon they sit at the neck of the
// branch chain on its colon band (attach_mm).
void place_branches_at_their_neck(const ColonScan& scan, std::vector<double>& s) {
  std::map<int, std::pair<int, double>> branch;  // id -> (parent, attach_mm)
  for (const auto& seg : scan.segments)
    if (is_branch_entry(seg))
      branch[seg.value("id", -1)] = {seg.value("parent", -1), seg.value("attach_mm", 0.0)};
  if (branch.empty()) return;
  std::map<int, double> at;  // branch id -> centreline mm of its chain's neck on the colon band
  for (const auto& [id, pa] : branch) {
    int cur = id;
    double attach = pa.second;
    for (int guard = 0; guard < 16 && branch.count(cur); ++guard) attach = branch[cur].second, cur = branch[cur].first;
    at[id] = attach;
  }
  for (size_t v = 0; v < s.size() && v < scan.segment.size(); ++v)
    if (auto it = at.find(scan.segment[v]); it != at.end()) s[v] = it->second;
}

std::vector<double> axial_coordinate(const ColonScan& scan, const ProfileOptions& o, ScanCoordinates& c) {
  if (scan.centreline_mm.empty()) return axial_from_flat_x(scan, o, c);
  c.axial_source = "centreline_mm";
  for (const auto& seg : scan.segments)
    for (const char* key : {"x0_end", "x1_end"})
      if (seg.contains(key) && seg[key].is_string() && (seg[key] == "rectum" || seg[key] == "cecum"))
        c.from_rectum = true;
  std::vector<double> s = scan.centreline_mm;
  for (double& x : s)
    if (!std::isfinite(x) || x < 0) x = kNaN;
  place_branches_at_their_neck(scan, s);
  return s;
}

// Reference direction per bin: anterior projected on the cross-section; parallel transport where
// the tangent is nearly anterior-posterior.
void reference_frames(LengthProfile& p) {
  const Eigen::Vector3d anterior(0, -1, 0);
  const int n = p.bins();
  p.reference.assign(size_t(n), Eigen::Vector3d::Zero());
  std::vector<bool> good(size_t(n), false);
  int first_good = -1;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d& t = p.tangent[size_t(k)];
    const Eigen::Vector3d r = anterior - anterior.dot(t) * t;
    if (r.norm() > 0.35) {
      p.reference[size_t(k)] = r.normalized();
      good[size_t(k)] = true;
      if (first_good < 0) first_good = k;
    }
  }
  if (first_good < 0) first_good = 0, p.reference[0] = p.tangent[0].unitOrthogonal(), good[0] = true;
  auto transport = [&](int from, int to) {
    const Eigen::Vector3d& t = p.tangent[size_t(to)];
    const Eigen::Vector3d& r = p.reference[size_t(from)];
    p.reference[size_t(to)] = (r - r.dot(t) * t).normalized();
  };
  for (int k = first_good - 1; k >= 0; --k) transport(k + 1, k);
  for (int k = first_good + 1; k < n; ++k)
    if (!good[size_t(k)]) transport(k - 1, k);
}

void profile_shape(LengthProfile& p, const ProfileOptions& o) {
  const int n = p.bins();
  p.tangent.resize(size_t(n));
  for (int k = 0; k < n; ++k) {
    const int a = std::max(0, k - 1), b = std::min(n - 1, k + 1);
    Eigen::Vector3d d = p.centre[size_t(b)] - p.centre[size_t(a)];
    p.tangent[size_t(k)] = d.norm() > 1e-12 ? d.normalized() : (k > 0 ? p.tangent[size_t(k) - 1] : Eigen::Vector3d(0, 0, 1));
  }
  p.curvature.assign(size_t(n), 0.0);
  for (int k = 1; k + 1 < n; ++k)
    p.curvature[size_t(k)] = (p.tangent[size_t(k) + 1] - p.tangent[size_t(k) - 1]).norm() / (2 * o.bin_mm);
  reference_frames(p);
}

}  // namespace

int LengthProfile::bin_of(double s) const { return std::clamp(int(s / bin_mm), 0, std::max(0, bins() - 1)); }

std::vector<double> gaussian_smooth(const std::vector<double>& v, double sigma) {
  if (sigma <= 0 || v.empty()) return v;
  const int r = int(std::ceil(3 * sigma));
  std::vector<double> w(size_t(2 * r + 1));
  for (int i = -r; i <= r; ++i) w[size_t(i + r)] = std::exp(-0.5 * i * i / (sigma * sigma));
  std::vector<double> out(v.size());
  const int n = int(v.size());
  for (int k = 0; k < n; ++k) {
    double sum = 0, ws = 0;
    for (int i = std::max(-r, -k); i <= std::min(r, n - 1 - k); ++i) sum += w[size_t(i + r)] * v[size_t(k + i)], ws += w[size_t(i + r)];
    out[size_t(k)] = sum / ws;
  }
  return out;
}

ScanCoordinates colon_coordinates(const ColonScan& scan, const ProfileOptions& o, bool reverse) {
  ScanCoordinates c;
  c.s = axial_coordinate(scan, o, c);
  double max_s = 0;
  for (double x : c.s)
    if (!std::isnan(x)) max_s = std::max(max_s, x);
  const int bins = int(std::ceil(max_s / o.bin_mm));
  if (bins < 20)
    throw PreconditionError(scan.name + ": colon map too short to register (" + std::to_string(int(max_s)) + " mm)");
  if (reverse) {
    for (double& x : c.s)
      if (!std::isnan(x)) x = std::min(max_s - x, bins * o.bin_mm - 1e-9);
    c.reversed = true;
    c.from_rectum = false;
  }
  fill_profile(scan, o, bins, c);
  return c;
}

ScanCoordinates colon_coordinates_from_s(const ColonScan& scan, std::vector<double> s, const ProfileOptions& o,
                                         double min_length_mm, const std::string& source, bool from_rectum) {
  ScanCoordinates c;
  c.s = std::move(s);
  c.axial_source = source;
  c.from_rectum = from_rectum;
  double max_s = 0, min_s = std::numeric_limits<double>::max();
  for (double x : c.s)
    if (!std::isnan(x)) max_s = std::max(max_s, x), min_s = std::min(min_s, x);
  if (max_s - std::min(min_s, max_s) < 20 * o.bin_mm)
    throw PreconditionError(scan.name + ": colon map too short to register (" + std::to_string(int(std::max(0.0, max_s - min_s))) + " mm)");
  fill_profile(scan, o, int(std::ceil(std::max(max_s, min_length_mm) / o.bin_mm)), c);
  return c;
}

namespace {
// Angle in [0, 2 pi) of x about the axis (centre, unit t), 0 = the unit e1 (perpendicular to t);
// x's distance from the axis in `radial` when given.
double angle_in_frame(const Eigen::Vector3d& centre, const Eigen::Vector3d& t, const Eigen::Vector3d& e1,
                      const Eigen::Vector3d& x, double* radial) {
  Eigen::Vector3d d = x - centre;
  d -= d.dot(t) * t;
  if (radial) *radial = d.norm();
  const double a = std::atan2(d.dot(t.cross(e1)), d.dot(e1));
  return a < 0 ? a + kTwoPi : a;
}
}  // namespace

double angle_about_centre(const LengthProfile& p, double s, const Eigen::Vector3d& x, double* radial) {
  const size_t k = size_t(p.bin_of(s));
  return angle_in_frame(p.centre[k], p.tangent[k], p.reference[k], x, radial);
}

double angle_about_axis(const Eigen::Vector3d& centre, const Eigen::Vector3d& tangent, const Eigen::Vector3d& reference,
                        const Eigen::Vector3d& x, double* radial) {
  Eigen::Vector3d e1 = reference - reference.dot(tangent) * tangent;
  if (e1.norm() < 1e-9) return std::numeric_limits<double>::quiet_NaN();
  return angle_in_frame(centre, tangent, e1.normalized(), x, radial);
}

void fill_profile(const ColonScan& scan, const ProfileOptions& o, int bins, ScanCoordinates& c) {
  LengthProfile& p = c.profile;
  p.bin_mm = o.bin_mm;
  p.centre = smooth_points(bin_centroids(c.s, scan.lps, o.bin_mm, bins, p.count), o.smooth_mm / o.bin_mm);
  profile_shape(p, o);
  c.theta.assign(c.s.size(), kNaN);
  c.radial.assign(c.s.size(), kNaN);
  std::vector<double> rsum(size_t(bins), 0.0);
  for (size_t v = 0; v < c.s.size(); ++v) {
    if (std::isnan(c.s[v])) continue;
    const int k = p.bin_of(c.s[v]);
    c.theta[v] = angle_about_centre(p, c.s[v], scan.lps[v], &c.radial[v]);
    rsum[size_t(k)] += c.radial[v];
  }
  p.radius.assign(size_t(bins), 0.0);
  double total = 0, counted = 0;
  for (int k = 0; k < bins; ++k)
    if (p.count[size_t(k)] > 0) p.radius[size_t(k)] = rsum[size_t(k)] / p.count[size_t(k)], total += rsum[size_t(k)], counted += p.count[size_t(k)];
  c.mean_radius_mm = counted > 0 ? total / counted : 0;
  for (int k = 0; k < bins; ++k)
    if (p.count[size_t(k)] == 0) p.radius[size_t(k)] = c.mean_radius_mm;
  const auto trend = gaussian_smooth(p.radius, o.fold_band_mm / o.bin_mm);
  p.fold.resize(size_t(bins));
  for (int k = 0; k < bins; ++k) p.fold[size_t(k)] = p.radius[size_t(k)] - trend[size_t(k)];
}

}  // namespace cf
