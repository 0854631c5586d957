#include "colonflat/register/support.h"

#include <algorithm>
#include <cmath>

namespace cf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Largest local length change between the scans the map may show where it is supported: a stretch
// of colon between two folds does not halve or double its length between supine and prone.
constexpr double kMaxStretch = 2.0;

// Highest present bin on one side of the midline that is a turning point of the course, or -1.
int flexure_bin(const LengthProfile& p, double midline, int side, const LandmarkOptions& o) {
  int best = -1;
  for (int k = 0; k < p.bins(); ++k) {
    if (p.count[size_t(k)] == 0 || side * (p.centre[size_t(k)].x() - midline) < o.side_mm) continue;
    if (best < 0 || p.centre[size_t(k)].z() > p.centre[size_t(best)].z()) best = k;
  }
  if (best < 0) return -1;
  const int w = int(std::ceil(o.drop_window_mm / p.bin_mm)), near = std::max(1, int(std::ceil(10.0 / p.bin_mm)));
  const double top = p.centre[size_t(best)].z();
  bool below[2] = {false, false};
  for (int d = 1; d <= w; ++d)
    for (int dir = 0; dir < 2; ++dir) {
      const int k = best + (dir == 0 ? -d : d);
      if (k < 0 || k >= p.bins()) continue;
      if (p.count[size_t(k)] == 0 && d <= near) return -1;  // a gap next to it: the top may be missing
      if (p.count[size_t(k)] > 0 && p.centre[size_t(k)].z() <= top - o.drop_mm) below[dir] = true;
    }
  return below[0] && below[1] ? best : -1;
}

// Distance along (mm) from every bin to the nearest flagged bin (infinity when none is).
std::vector<double> distance_to(const std::vector<char>& flag, double bin_mm) {
  const size_t n = flag.size();
  std::vector<double> d(n, kInf);
  double last = -kInf;
  for (size_t k = 0; k < n; ++k) {
    if (flag[k]) last = double(k);
    d[k] = (double(k) - last) * bin_mm;
  }
  last = kInf;
  for (size_t k = n; k-- > 0;) {
    if (flag[k]) last = double(k);
    d[k] = std::min(d[k], (last - double(k)) * bin_mm);
  }
  return d;
}

}  // namespace

std::vector<Landmark> find_landmarks(const LengthProfile& p, double rectum_s, double cecum_s, const LandmarkOptions& o) {
  std::vector<Landmark> out;
  auto add = [&](const std::string& name, double s) {
    if (std::isfinite(s)) out.push_back({name, s, p.centre[size_t(p.bin_of(s))]});
  };
  add("rectum", rectum_s);
  add("cecum", cecum_s);
  std::vector<double> x;
  for (int k = 0; k < p.bins(); ++k)
    if (p.count[size_t(k)] > 0) x.push_back(p.centre[size_t(k)].x());
  if (x.empty()) return out;
  std::nth_element(x.begin(), x.begin() + long(x.size() / 2), x.end());
  const double midline = x[x.size() / 2];
  if (const int k = flexure_bin(p, midline, +1, o); k >= 0) add("splenic flexure", (k + 0.5) * p.bin_mm);  // L = left
  if (const int k = flexure_bin(p, midline, -1, o); k >= 0) add("hepatic flexure", (k + 0.5) * p.bin_mm);
  return out;
}

std::vector<SharedLandmark> share_landmarks(const std::vector<Landmark>& supine, const std::vector<Landmark>& prone,
                                            const LengthAlignment& length, double tolerance_mm) {
  std::vector<SharedLandmark> out;
  for (const auto& a : supine)
    for (const auto& b : prone)
      if (a.name == b.name)
        out.push_back({a.name, a.s_mm, b.s_mm, std::abs(length.a_to_b(a.s_mm) - b.s_mm) <= tolerance_mm});
  return out;
}

AlignmentSupport alignment_support(const LengthProfile& a, const LengthProfile& b, const LengthAlignment& length,
                                   const Eigen::Vector3d& b_to_a, double radius, const std::vector<double>& anchors_mm) {
  AlignmentSupport s;
  s.supine_supported.assign(size_t(a.bins()), 0);
  s.prone_supported.assign(size_t(b.bins()), 0);
  int with_wall = 0, supported = 0;
  // Local slope of the length map: where the warping stretches one colon over a stretch missing
  // in the other (slope near 0 or very large) the map is not supported, even next to wall.
  auto slope_ok = [&](double s, bool forward) {
    const double h = a.bin_mm;
    const double d = forward ? length.a_to_b(s + h) - length.a_to_b(s - h) : length.b_to_a(s + h) - length.b_to_a(s - h);
    return d >= 2 * h / kMaxStretch && d <= 2 * h * kMaxStretch;
  };
  for (int i = 0; i < a.bins(); ++i) {
    const int j = b.bin_of(length.a_to_b((i + 0.5) * a.bin_mm));
    const bool ok = a.count[size_t(i)] > 0 && b.count[size_t(j)] > 0 && slope_ok((i + 0.5) * a.bin_mm, true) &&
                    (a.centre[size_t(i)] - b.centre[size_t(j)] - b_to_a).norm() <= radius;
    s.supine_supported[size_t(i)] = ok;
    with_wall += a.count[size_t(i)] > 0, supported += ok;
  }
  for (int j = 0; j < b.bins(); ++j) {
    const int i = a.bin_of(length.b_to_a((j + 0.5) * b.bin_mm));
    s.prone_supported[size_t(j)] = b.count[size_t(j)] > 0 && a.count[size_t(i)] > 0 && slope_ok((j + 0.5) * b.bin_mm, false) &&
                                   (a.centre[size_t(i)] - b.centre[size_t(j)] - b_to_a).norm() <= radius;
  }
  s.supported_fraction = with_wall > 0 ? double(supported) / with_wall : 0.0;
  s.supine_gap_mm = distance_to(s.supine_supported, a.bin_mm);
  s.prone_gap_mm = distance_to(s.prone_supported, b.bin_mm);
  std::vector<char> anchor(size_t(a.bins()), 0);
  for (double m : anchors_mm) anchor[size_t(a.bin_of(m))] = 1;
  s.supine_anchor_mm = distance_to(anchor, a.bin_mm);
  for (int i = 0; i < a.bins();) {  // stretches of unsupported bins
    if (s.supine_supported[size_t(i)]) { ++i; continue; }
    int e = i;
    while (e < a.bins() && !s.supine_supported[size_t(e)]) ++e;
    s.unsupported.push_back({i * a.bin_mm, e * a.bin_mm});
    i = e;
  }
  return s;
}

}  // namespace cf
