// Centreline of a colon segment from the level sets of the harmonic function u, and the
// anatomical labelling (rectum / cecum) and order of the segments' ends.
#include <algorithm>
#include <cmath>
#include <memory>

#include "face_blocks.h"
#include "flatten_internal.h"

namespace cf::flat_detail {
namespace {

constexpr double kHuge = 1e300;

struct FaceSample {
  double key;   // binning key (u or coarse arc length)
  double u;
  double area;
  V3 centroid;
};

// The used faces' samples in face order, each computed on its own in blocks of faces on the worker
// threads (the same bits for any thread count; the array is first written there too, not zeroed
// on the calling thread first).
class FaceSamples {
 public:
  FaceSamples(const Surface& s, const std::vector<double>& u, const std::vector<char>& use_face) {
    const std::size_t nb = face_blocks(s.t.size());
    std::vector<std::size_t> first(nb + 1, 0);  // per block: its first sample
    for (std::size_t f = 0; f < s.t.size(); ++f) first[f / kFaceBlock + 1] += use_face[f] != 0;
    for (std::size_t b = 0; b < nb; ++b) first[b + 1] += first[b];
    size_ = first[nb];
    data_.reset(new FaceSample[size_]);  // (default-initialised: not written here)
    for_each_block(s.t.size(), [&](std::size_t begin, std::size_t end) {
      std::size_t k = first[begin / kFaceBlock];
      for (std::size_t f = begin; f < end; ++f) {
        if (!use_face[f]) continue;
        const Tri& t = s.t[f];
        const double uf = (u[t[0]] + u[t[1]] + u[t[2]]) / 3;
        data_[k++] = {uf, uf, face_area_3d(s, int(f)), (s.p[t[0]] + s.p[t[1]] + s.p[t[2]]) / 3};
      }
    });
  }
  std::size_t size() const { return size_; }
  FaceSample* begin() const { return data_.get(); }
  FaceSample* end() const { return data_.get() + size_; }

 private:
  std::unique_ptr<FaceSample[]> data_;
  std::size_t size_ = 0;
};

// Area-weighted centroid and mean u of the faces in each of `bins` equal bins of key in [0, kmax].
void slice_centroids(const FaceSamples& faces, int bins, double kmax, std::vector<V3>& centre,
                     std::vector<double>& mean_u) {
  std::vector<V3> sum(bins, V3::Zero());
  std::vector<double> su(bins, 0.0), sa(bins, 0.0);
  for (const auto& fs : faces) {
    const int b = std::clamp(int(fs.key / kmax * bins), 0, bins - 1);
    sum[b] += fs.area * fs.centroid;
    su[b] += fs.area * fs.u;
    sa[b] += fs.area;
  }
  centre.clear();
  mean_u.clear();
  for (int b = 0; b < bins; ++b)
    if (sa[b] > 0) centre.push_back(sum[b] / sa[b]), mean_u.push_back(su[b] / sa[b]);
}

// Polyline end A, slice centroids, end B; knots (u, cumulative length).
Centreline polyline(const std::vector<V3>& centre, const std::vector<double>& mean_u, const V3& a, const V3& b,
                    int smoothing) {
  std::vector<V3> pts;
  pts.push_back(a);
  pts.insert(pts.end(), centre.begin(), centre.end());
  pts.push_back(b);
  std::vector<double> us;
  us.push_back(0.0);
  us.insert(us.end(), mean_u.begin(), mean_u.end());
  us.push_back(1.0);
  // [1 2 1] / 4 smoothing across the curve only (the displacement's component along the local
  // tangent removed, so points do not slide along it and s(u) keeps its shape), ends fixed.
  for (int it = 0; it < smoothing; ++it) {
    std::vector<V3> q = pts;
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
      const V3 d = 0.25 * (pts[i - 1] + pts[i + 1]) - 0.5 * pts[i];
      const V3 tangent = (pts[i + 1] - pts[i - 1]).normalized();
      q[i] = pts[i] + d - d.dot(tangent) * tangent;
    }
    pts.swap(q);
  }
  Centreline c;
  double s = 0, last_u = -1;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i > 0) s += (pts[i] - pts[i - 1]).norm();
    if (us[i] <= last_u) continue;  // keep u strictly increasing
    last_u = us[i];
    c.knot_u.push_back(us[i]);
    c.knot_s.push_back(s);
    c.points.push_back({pts[i].x(), pts[i].y(), pts[i].z()});
  }
  c.length = s;
  c.knot_s.back() = s;
  for (std::size_t i = 1; i < c.knot_s.size(); ++i)  // strictly increasing s
    c.knot_s[i] = std::max(c.knot_s[i], c.knot_s[i - 1] + 1e-6 * std::max(1.0, s));
  c.length = c.knot_s.back();
  return c;
}

}  // namespace

double Centreline::area_fraction_of_u(double u) const {
  if (area_cdf.size() < 2) return u;
  const double x = std::clamp(u, 0.0, 1.0) * double(area_cdf.size() - 1);
  const std::size_t i = std::min(area_cdf.size() - 2, std::size_t(x));
  return area_cdf[i] + (x - double(i)) * (area_cdf[i + 1] - area_cdf[i]);
}

std::vector<double> Centreline::blended_axis(double beta) const {
  const std::size_t n = std::max<std::size_t>(area_cdf.size(), 2);
  std::vector<double> axis(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) {
    const double density = area_cdf.size() == n ? (area_cdf[i] - area_cdf[i - 1]) * double(n - 1) : 1.0;
    axis[i] = axis[i - 1] + std::pow(std::max(density, 1e-12), beta);
  }
  for (double& x : axis) x /= axis.back();
  return axis;
}

double interpolate_axis(const std::vector<double>& axis, double u) {
  const double x = std::clamp(u, 0.0, 1.0) * double(axis.size() - 1);
  const std::size_t i = std::min(axis.size() - 2, std::size_t(x));
  return axis[i] + (x - double(i)) * (axis[i + 1] - axis[i]);
}

double Centreline::s_of_u(double u) const {
  if (knot_u.empty()) return u;
  if (u <= knot_u.front()) return knot_s.front();
  if (u >= knot_u.back()) return knot_s.back();
  const auto it = std::upper_bound(knot_u.begin(), knot_u.end(), u);
  const std::size_t i = std::size_t(it - knot_u.begin());
  const double a = (u - knot_u[i - 1]) / (knot_u[i] - knot_u[i - 1]);
  return knot_s[i - 1] + a * (knot_s[i] - knot_s[i - 1]);
}

Centreline centreline_from_u(const Surface& s, const std::vector<double>& u, const std::vector<char>& use_face,
                             const V3& end_a, const V3& end_b) {
  const FaceSamples faces(s, u, use_face);
  // Pass 1: 256 slices equal in u give a coarse arc length s1(u).
  std::vector<V3> centre;
  std::vector<double> mean_u;
  slice_centroids(faces, 256, 1.0, centre, mean_u);
  const Centreline coarse = polyline(centre, mean_u, end_a, end_b, 2);
  // Pass 2: slices about 8 mm apart in s1 (equal in length, not in u), smoothed across.
  const int bins = std::clamp(int(coarse.length / 8.0), 8, 2000);
  for_each_block(faces.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) faces.begin()[k].key = coarse.s_of_u(faces.begin()[k].u);
  });
  slice_centroids(faces, bins, coarse.length, centre, mean_u);
  Centreline c = polyline(centre, mean_u, end_a, end_b, 8);
  // Cumulative wall area as a function of u (4096 bins), made strictly increasing.
  const int nb = 4096;
  std::vector<double> hist(nb, 0.0);
  double total = 0;
  for (const auto& fs : faces) hist[std::clamp(int(fs.u * nb), 0, nb - 1)] += fs.area, total += fs.area;
  c.area_cdf.assign(nb + 1, 0.0);
  for (int b = 0; b < nb; ++b) c.area_cdf[b + 1] = c.area_cdf[b] + hist[b] / total + 1e-9;
  for (double& a : c.area_cdf) a /= c.area_cdf.back();
  return c;
}

namespace {

double dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Order rectum -> cecum: start at the segment holding the rectum (else the first), then repeatedly
// the segment with an end nearest to the current segment's x1 end (reversed to start there if
// its ends are not labelled). Sets `order` and `centreline_offset`.
void order_segments(std::vector<FlatSegment>& segs, std::vector<char>& reversed) {
  std::vector<char> used(segs.size(), 0);
  int cur = 0;
  for (std::size_t i = 0; i < segs.size(); ++i)
    if (segs[i].x0_end == "rectum") cur = int(i);
  double offset = 0;
  for (int k = 0; k < int(segs.size()); ++k) {
    used[cur] = 1;
    segs[cur].order = k;
    segs[cur].centreline_offset = offset;
    offset += segs[cur].centreline_length;
    int next = -1;
    bool flip = false;
    double best = kHuge;
    for (std::size_t i = 0; i < segs.size(); ++i) {
      if (used[i]) continue;
      const bool labelled = segs[i].x0_end != "end A" || segs[i].x1_end != "end B";
      const double da = dist(segs[cur].end_b, segs[i].end_a), db = dist(segs[cur].end_b, segs[i].end_b);
      if (da < best) best = da, next = int(i), flip = false;
      if (!labelled && db < best) best = db, next = int(i), flip = true;
    }
    if (next < 0) break;
    if (flip) std::swap(segs[next].end_a, segs[next].end_b), reversed[next] = !reversed[next];
    cur = next;
  }
}

}  // namespace

void label_ends(std::vector<FlatSegment>& segs, double midline_x, std::vector<char>& reversed) {
  // Candidate ends: (segment, which end, LPS point). Rectum: inferior and near the midline;
  // cecum: the patient's right (smaller L) end. Decided only with a clear margin.
  struct End {
    int seg, which;
    std::array<double, 3> p;
  };
  std::vector<End> ends;
  for (std::size_t i = 0; i < segs.size(); ++i)
    ends.push_back({int(i), 0, segs[i].end_a}), ends.push_back({int(i), 1, segs[i].end_b});
  auto rect_score = [&](const End& e) { return e.p[2] + 0.5 * std::abs(e.p[0] - midline_x); };
  std::vector<int> by_rect(ends.size());
  for (std::size_t i = 0; i < ends.size(); ++i) by_rect[i] = int(i);
  std::sort(by_rect.begin(), by_rect.end(), [&](int a, int b) { return rect_score(ends[a]) < rect_score(ends[b]); });
  const double margin = 25.0;  // mm
  int rectum = -1, cecum = -1;
  if (rect_score(ends[by_rect[1]]) - rect_score(ends[by_rect[0]]) > margin) rectum = by_rect[0];
  if (rectum >= 0) {
    int best = -1, second = -1;
    for (std::size_t i = 0; i < ends.size(); ++i) {
      if (int(i) == rectum) continue;
      if (best < 0 || ends[i].p[0] < ends[best].p[0]) second = best, best = int(i);
      else if (second < 0 || ends[i].p[0] < ends[second].p[0]) second = int(i);
    }
    const bool right_of_midline = ends[best].p[0] < midline_x - margin;
    const bool clear = second < 0 || ends[second].p[0] - ends[best].p[0] > margin;
    if (best >= 0 && right_of_midline && clear) cecum = best;
  }
  reversed.assign(segs.size(), 0);
  std::vector<std::array<std::string, 2>> label(segs.size());
  if (rectum >= 0) label[ends[rectum].seg][ends[rectum].which] = "rectum";
  if (cecum >= 0) label[ends[cecum].seg][ends[cecum].which] = "cecum";
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const bool rev = label[i][1] == "rectum" || (label[i][0] == "cecum" && label[i][1] != "rectum");
    if (rev) std::swap(label[i][0], label[i][1]), std::swap(segs[i].end_a, segs[i].end_b);
    reversed[i] = rev;
    segs[i].x0_end = label[i][0].empty() ? "end A" : label[i][0];
    segs[i].x1_end = label[i][1].empty() ? "end B" : label[i][1];
  }
  order_segments(segs, reversed);
}

}  // namespace cf::flat_detail
