#include "colonflat/flatten/synthetic_colon.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

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
}  // namespace

Colon colon(const ColonOptions& o) {
  Colon c;
  const double R = o.radius;
  c.circumference = 2 * M_PI * R;
  const int nu = o.around > 0 ? o.around : std::max(8, int(std::lround(c.circumference / o.spacing)));
  const int nr = std::max(2, int(std::lround(o.length / o.spacing)));
  // Fine samples of the centreline with arc length, then rings at equal arc length.
  const int fine = nr * 8;
  std::vector<V3> cp(fine + 1);
  std::vector<double> arc(fine + 1, 0.0);
  // Parameter range giving arc length `length` (iterate the scale once or twice).
  double tmax = o.length;
  for (int it = 0; it < 4; ++it) {
    for (int i = 0; i <= fine; ++i) cp[i] = curve(tmax * i / fine, o.bent);
    for (int i = 1; i <= fine; ++i) arc[i] = arc[i - 1] + (cp[i] - cp[i - 1]).norm();
    tmax *= o.length / arc[fine];
  }
  for (int i = 0; i <= fine; ++i) cp[i] = curve(tmax * i / fine, o.bent);
  for (int i = 1; i <= fine; ++i) arc[i] = arc[i - 1] + (cp[i] - cp[i - 1]).norm();
  // Rings with parallel-transported frames.
  std::vector<V3> C(nr + 1), T(nr + 1), N1(nr + 1), N2(nr + 1);
  {
    int k = 0;
    for (int i = 0; i <= nr; ++i) {
      const double s = o.length * i / nr * (arc[fine] / o.length);
      while (k + 1 < fine && arc[k + 1] < s) ++k;
      const double a = (s - arc[k]) / std::max(1e-12, arc[k + 1] - arc[k]);
      C[i] = cp[k] + std::clamp(a, 0.0, 1.0) * (cp[k + 1] - cp[k]);
      T[i] = (cp[k + 1] - cp[k]).normalized();
    }
    V3 ref = std::abs(T[0].z()) < 0.9 ? V3(0, 0, 1) : V3(1, 0, 0);
    N1[0] = (ref - ref.dot(T[0]) * T[0]).normalized();
    for (int i = 1; i <= nr; ++i) {
      const V3 n = N1[i - 1] - N1[i - 1].dot(T[i]) * T[i];
      N1[i] = n.normalized();
    }
    for (int i = 0; i <= nr; ++i) N2[i] = T[i].cross(N1[i]);
  }
  auto fold = [&](double s, double th) {
    if (o.fold_height <= 0) return 0.0;
    double h = 0;
    const double first = 0.5 * o.fold_spacing + 10;
    for (double sk = first; sk < o.length - 10; sk += o.fold_spacing) {
      const double d = (s - sk) / o.fold_width;
      if (std::abs(d) < 5) h += o.fold_height * std::exp(-d * d) * (0.6 + 0.4 * std::cos(3 * th));
    }
    return h;
  };
  auto bump = [&](double s, double th) {
    double h = 0;
    for (const auto& p : o.polyps) {
      // a hemisphere of the polyp's diameter, with a small fillet at its base
      const double r = 0.5 * p.diameter;
      const double ds = s - p.s, dt = R * ang_diff(th, p.angle);
      const double q = (ds * ds + dt * dt) / (r * r);
      if (q < 1) h += r * std::sqrt(1 - q) * (1 - std::exp(-8 * (1 - q)));
    }
    return h;
  };
  auto& P = c.mesh.points;
  auto& F = c.mesh.triangles;
  auto add = [&](const V3& p) {
    P.push_back({p.x(), p.y(), p.z()});
    return int(P.size()) - 1;
  };
  std::vector<std::vector<int>> rings;
  for (int i = 0; i <= nr; ++i) {
    const double s = o.length * i / nr;
    std::vector<int> ring(nu);
    for (int j = 0; j < nu; ++j) {
      const double th = 2 * M_PI * j / nu;
      const double r = R - fold(s, th) - bump(s, th);
      ring[j] = add(C[i] + r * (std::cos(th) * N1[i] + std::sin(th) * N2[i]));
    }
    rings.push_back(ring);
  }
  auto strip = [&](const std::vector<int>& a, const std::vector<int>& b) {
    for (int j = 0; j < nu; ++j) {
      const int j1 = (j + 1) % nu;
      F.push_back({a[j], a[j1], b[j1]});
      F.push_back({a[j], b[j1], b[j]});
    }
  };
  for (int i = 0; i < nr; ++i) strip(rings[i], rings[i + 1]);
  if (o.closed) {
    const int nc = std::max(2, int(std::lround(0.5 * M_PI * R / o.spacing)));
    for (int end = 0; end < 2; ++end) {
      const int i = end == 0 ? 0 : nr;
      const V3 dir = end == 0 ? V3(-T[0]) : V3(T[nr]);
      std::vector<int> prev = rings[i];
      for (int k = 1; k < nc; ++k) {
        const double phi = 0.5 * M_PI * k / nc;
        std::vector<int> ring(nu);
        for (int j = 0; j < nu; ++j) {
          const double th = 2 * M_PI * j / nu;
          ring[j] = add(C[i] + R * std::cos(phi) * (std::cos(th) * N1[i] + std::sin(th) * N2[i]) +
                        R * std::sin(phi) * dir);
        }
        if (end == 0) strip(ring, prev);
        else strip(prev, ring);
        prev = ring;
      }
      const int pole = add(C[i] + R * dir);
      for (int j = 0; j < nu; ++j) {
        const int j1 = (j + 1) % nu;
        if (end == 0) F.push_back({pole, prev[j1], prev[j]});
        else F.push_back({prev[j], prev[j1], pole});
      }
    }
  }
  // Outward normals: flip every triangle if the signed volume is negative.
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
  // Ground truth.
  int id = 1;
  for (const auto& p : o.polyps) {
    const double f = std::clamp(p.s / o.length * nr, 0.0, double(nr));
    const int i = int(std::lround(f));
    const double r = R - fold(p.s, p.angle) - bump(p.s, p.angle);
    const V3 x = C[i] + r * (std::cos(p.angle) * N1[i] + std::sin(p.angle) * N2[i]);
    c.polyps.push_back({id++, {x.x(), x.y(), x.z()}, p.diameter});
  }
  if (o.fold_height > 0)
    for (double sk = 0.5 * o.fold_spacing + 10; sk < o.length - 10; sk += o.fold_spacing) {
      const int i = int(std::lround(sk / o.length * nr));
      for (int j = 0; j < 6; ++j) {
        const double th = 2 * M_PI * j / 6;
        const V3 x = C[i] + (R - fold(sk, th)) * (std::cos(th) * N1[i] + std::sin(th) * N2[i]);
        c.fold_crests.push_back({x.x(), x.y(), x.z()});
      }
    }
  return c;
}

}  // namespace cf::synthetic
