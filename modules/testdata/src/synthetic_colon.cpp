#include "colonflat/testdata/synthetic_colon.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace cf::synthetic {

namespace {
using V3 = Eigen::Vector3d;

V3 curve(double t, bool bent) {
  if (!bent) return {0, 0, t};
  return {t, 40 * std::sin(2 * M_PI * t / 300), 25 * std::sin(2 * M_PI * t / 420 + 0.7)};
}

double ang_diff(double a, double b) {
  double d = std::fmod(a - b, 2 * M_PI);
  if (d > M_PI) d -= 2 * M_PI;
  if (d < -M_PI) d += 2 * M_PI;
  return d;
}

// colon() as named steps: the centreline and its ring frames, the wall rings (folds and polyps as
// radius changes), the strips between rings, the end caps, outward orientation, ground truth.
class ColonBuilder {
 public:
  explicit ColonBuilder(const ColonOptions& o) : o_(o), R_(o.radius) {
    c_.circumference = 2 * M_PI * R_;
    nu_ = o.around > 0 ? o.around : std::max(8, int(std::lround(c_.circumference / o.spacing)));
    nr_ = std::max(2, int(std::lround(o.length / o.spacing)));
  }
  Colon run() {
    ring_frames(sample_centreline());
    wall();
    if (o_.closed) {
      const int nc = std::max(2, int(std::lround(0.5 * M_PI * R_ / o_.spacing)));
      for (int end = 0; end < 2; ++end) cap(end, nc);
    }
    orient_outward();
    ground_truth();
    return std::move(c_);
  }

 private:
  struct Samples {
    std::vector<V3> points;
    std::vector<double> arc;
  };
  Samples sample_centreline() const;
  void ring_frames(const Samples& fine);
  double fold(double s, double th) const;
  double bump(double s, double th) const;
  int add(const V3& p) {
    c_.mesh.points.push_back({p.x(), p.y(), p.z()});
    return int(c_.mesh.points.size()) - 1;
  }
  V3 around(int i, double th) const { return std::cos(th) * N1_[i] + std::sin(th) * N2_[i]; }
  void wall();
  void strip(const std::vector<int>& a, const std::vector<int>& b);
  void cap(int end, int cap_rings);
  void orient_outward();
  void ground_truth();

  const ColonOptions& o_;
  const double R_;
  Colon c_;
  int nu_ = 0, nr_ = 0;                 // vertices per ring, ring intervals along the colon
  std::vector<V3> C_, T_, N1_, N2_;     // per ring: centre, tangent, parallel-transported frame
  std::vector<std::vector<int>> rings_;  // wall rings' vertex ids
};

// Fine samples of the centreline (8 per ring) with arc length, its parameter range scaled so that
// the arc length is `length` (the scale iterated 4 times).
ColonBuilder::Samples ColonBuilder::sample_centreline() const {
  const int fine = nr_ * 8;
  Samples f{std::vector<V3>(fine + 1), std::vector<double>(fine + 1, 0.0)};
  double tmax = o_.length;
  for (int it = 0; it < 4; ++it) {
    for (int i = 0; i <= fine; ++i) f.points[i] = curve(tmax * i / fine, o_.bent);
    for (int i = 1; i <= fine; ++i) f.arc[i] = f.arc[i - 1] + (f.points[i] - f.points[i - 1]).norm();
    tmax *= o_.length / f.arc[fine];
  }
  for (int i = 0; i <= fine; ++i) f.points[i] = curve(tmax * i / fine, o_.bent);
  for (int i = 1; i <= fine; ++i) f.arc[i] = f.arc[i - 1] + (f.points[i] - f.points[i - 1]).norm();
  return f;
}

// Ring centres at equal arc length, with parallel-transported frames.
void ColonBuilder::ring_frames(const Samples& f) {
  const int fine = int(f.points.size()) - 1;
  C_.resize(nr_ + 1), T_.resize(nr_ + 1), N1_.resize(nr_ + 1), N2_.resize(nr_ + 1);
  int k = 0;
  for (int i = 0; i <= nr_; ++i) {
    const double s = o_.length * i / nr_ * (f.arc[fine] / o_.length);
    while (k + 1 < fine && f.arc[k + 1] < s) ++k;
    const double a = (s - f.arc[k]) / std::max(1e-12, f.arc[k + 1] - f.arc[k]);
    C_[i] = f.points[k] + std::clamp(a, 0.0, 1.0) * (f.points[k + 1] - f.points[k]);
    T_[i] = (f.points[k + 1] - f.points[k]).normalized();
  }
  V3 ref = std::abs(T_[0].z()) < 0.9 ? V3(0, 0, 1) : V3(1, 0, 0);
  N1_[0] = (ref - ref.dot(T_[0]) * T_[0]).normalized();
  for (int i = 1; i <= nr_; ++i) {
    const V3 n = N1_[i - 1] - N1_[i - 1].dot(T_[i]) * T_[i];
    N1_[i] = n.normalized();
  }
  for (int i = 0; i <= nr_; ++i) N2_[i] = T_[i].cross(N1_[i]);
}

// Height of the haustral folds at (s mm, th rad): Gaussian ridges, higher on three sides.
double ColonBuilder::fold(double s, double th) const {
  if (o_.fold_height <= 0) return 0.0;
  double h = 0;
  const double first = 0.5 * o_.fold_spacing + 10;
  for (double sk = first; sk < o_.length - 10; sk += o_.fold_spacing) {
    const double d = (s - sk) / o_.fold_width;
    if (std::abs(d) < 5) h += o_.fold_height * std::exp(-d * d) * (0.6 + 0.4 * std::cos(3 * th));
  }
  return h;
}

// Height of the polyps at (s, th): a hemisphere of each polyp's diameter, filleted at its base.
double ColonBuilder::bump(double s, double th) const {
  double h = 0;
  for (const auto& p : o_.polyps) {
    const double r = 0.5 * p.diameter;
    const double ds = s - p.s, dt = R_ * ang_diff(th, p.angle);
    const double q = (ds * ds + dt * dt) / (r * r);
    if (q < 1) h += r * std::sqrt(1 - q) * (1 - std::exp(-8 * (1 - q)));
  }
  return h;
}

// The tube: one ring per centreline ring, radius lowered by folds and polyps, strips between.
void ColonBuilder::wall() {
  for (int i = 0; i <= nr_; ++i) {
    const double s = o_.length * i / nr_;
    std::vector<int> ring(nu_);
    for (int j = 0; j < nu_; ++j) {
      const double th = 2 * M_PI * j / nu_;
      const double r = R_ - fold(s, th) - bump(s, th);
      ring[j] = add(C_[i] + r * around(i, th));
    }
    rings_.push_back(ring);
  }
  for (int i = 0; i < nr_; ++i) strip(rings_[i], rings_[i + 1]);
}

void ColonBuilder::strip(const std::vector<int>& a, const std::vector<int>& b) {
  auto& F = c_.mesh.triangles;
  for (int j = 0; j < nu_; ++j) {
    const int j1 = (j + 1) % nu_;
    F.push_back({a[j], a[j1], b[j1]});
    F.push_back({a[j], b[j1], b[j]});
  }
}

// A hemispherical cap of `cap_rings` rings and a pole on end 0 (start) or 1 (end).
void ColonBuilder::cap(int end, int nc) {
  const int i = end == 0 ? 0 : nr_;
  const V3 dir = end == 0 ? V3(-T_[0]) : V3(T_[nr_]);
  std::vector<int> prev = rings_[i];
  for (int k = 1; k < nc; ++k) {
    const double phi = 0.5 * M_PI * k / nc;
    std::vector<int> ring(nu_);
    for (int j = 0; j < nu_; ++j) {
      const double th = 2 * M_PI * j / nu_;
      ring[j] = add(C_[i] + R_ * std::cos(phi) * around(i, th) + R_ * std::sin(phi) * dir);
    }
    if (end == 0) strip(ring, prev);
    else strip(prev, ring);
    prev = ring;
  }
  const int pole = add(C_[i] + R_ * dir);
  for (int j = 0; j < nu_; ++j) {
    const int j1 = (j + 1) % nu_;
    if (end == 0) c_.mesh.triangles.push_back({pole, prev[j1], prev[j]});
    else c_.mesh.triangles.push_back({prev[j], prev[j1], pole});
  }
}

// Outward normals: every triangle flipped if the signed volume is negative.
void ColonBuilder::orient_outward() {
  const auto& P = c_.mesh.points;
  auto& F = c_.mesh.triangles;
  V3 cen = V3::Zero();
  for (const auto& p : P) cen += V3(p[0], p[1], p[2]);
  cen /= double(P.size());
  double vol = 0;
  for (const auto& t : F) {
    auto q = [&](int v) -> V3 { return V3(P[v][0], P[v][1], P[v][2]) - cen; };
    vol += q(t[0]).dot(q(t[1]).cross(q(t[2])));
  }
  if (vol < 0)
    for (auto& t : F) std::swap(t[1], t[2]);
}

// The polyps' apexes and six points on each fold crest.
void ColonBuilder::ground_truth() {
  int id = 1;
  for (const auto& p : o_.polyps) {
    const double f = std::clamp(p.s / o_.length * nr_, 0.0, double(nr_));
    const int i = int(std::lround(f));
    const double r = R_ - fold(p.s, p.angle) - bump(p.s, p.angle);
    const V3 x = C_[i] + r * around(i, p.angle);
    c_.polyps.push_back({id++, {x.x(), x.y(), x.z()}, p.diameter});
  }
  if (o_.fold_height <= 0) return;
  for (double sk = 0.5 * o_.fold_spacing + 10; sk < o_.length - 10; sk += o_.fold_spacing) {
    const int i = int(std::lround(sk / o_.length * nr_));
    for (int j = 0; j < 6; ++j) {
      const double th = 2 * M_PI * j / 6;
      const V3 x = C_[i] + (R_ - fold(sk, th)) * around(i, th);
      c_.fold_crests.push_back({x.x(), x.y(), x.z()});
    }
  }
}

}  // namespace

Colon colon(const ColonOptions& o) { return ColonBuilder(o).run(); }

ColonOptions colon_options(double length, double radius, double spacing, std::vector<PolypSpec> polyps) {
  ColonOptions o;
  o.length = length;
  o.radius = radius;
  o.spacing = spacing;
  o.polyps = std::move(polyps);
  return o;
}

}  // namespace cf::synthetic
