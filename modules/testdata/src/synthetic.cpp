#include "colonflat/testdata/synthetic.h"

#include <cmath>
#include <map>

#include "colonflat/core/error.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/validation.h"

namespace cf::synthetic {
namespace {
constexpr double kPi = 3.14159265358979323846;
void quad(TriangleList& t, int a, int b, int c, int d) {  // a-b-c-d counter-clockwise
  t.triangles.push_back({a, b, c});
  t.triangles.push_back({a, c, d});
}
}  // namespace

TriangleList sphere(double r, int nu, int nv) {
  TriangleList t;
  t.points.push_back({0, 0, -r});
  for (int j = 1; j < nv; ++j) {
    const double th = -kPi / 2 + kPi * j / nv;
    for (int i = 0; i < nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      t.points.push_back({r * std::cos(th) * std::cos(ph), r * std::cos(th) * std::sin(ph), r * std::sin(th)});
    }
  }
  t.points.push_back({0, 0, r});
  const int top = static_cast<int>(t.points.size()) - 1;
  auto id = [&](int j, int i) { return 1 + (j - 1) * nu + ((i % nu) + nu) % nu; };
  for (int i = 0; i < nu; ++i) t.triangles.push_back({0, id(1, i + 1), id(1, i)});
  for (int j = 1; j + 1 < nv; ++j)
    for (int i = 0; i < nu; ++i) quad(t, id(j, i), id(j, i + 1), id(j + 1, i + 1), id(j + 1, i));
  for (int i = 0; i < nu; ++i) t.triangles.push_back({top, id(nv - 1, i), id(nv - 1, i + 1)});
  return t;
}

TriangleList torus(double R, double r, int nu, int nv) {
  TriangleList t;
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      t.points.push_back({(R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  }
  auto id = [&](int i, int j) { return ((i % nu) + nu) % nu * nv + ((j % nv) + nv) % nv; };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) quad(t, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  return t;
}

TriangleList disk(double r, int rings, int sectors) {
  TriangleList t;
  t.points.push_back({0, 0, 0});
  for (int k = 1; k <= rings; ++k)
    for (int s = 0; s < sectors; ++s) {
      const double a = 2 * kPi * s / sectors;
      t.points.push_back({r * k / rings * std::cos(a), r * k / rings * std::sin(a), 0});
    }
  auto id = [&](int k, int s) { return 1 + (k - 1) * sectors + ((s % sectors) + sectors) % sectors; };
  for (int s = 0; s < sectors; ++s) t.triangles.push_back({0, id(1, s), id(1, s + 1)});
  for (int k = 1; k < rings; ++k)
    for (int s = 0; s < sectors; ++s) quad(t, id(k, s), id(k + 1, s), id(k + 1, s + 1), id(k, s + 1));
  return t;
}

TriangleList open_cylinder(double r, double h, int nu, int nv) {
  TriangleList t;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double a = 2 * kPi * i / nu;
      t.points.push_back({r * std::cos(a), r * std::sin(a), h * j / nv});
    }
  auto id = [&](int j, int i) { return j * nu + ((i % nu) + nu) % nu; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) quad(t, id(j, i), id(j, i + 1), id(j + 1, i + 1), id(j + 1, i));
  return t;
}

TriangleList disjoint_union(const TriangleList& a, const TriangleList& b) {
  TriangleList t = a;
  const int off = static_cast<int>(a.points.size());
  t.points.insert(t.points.end(), b.points.begin(), b.points.end());
  for (auto tri : b.triangles) t.triangles.push_back({tri[0] + off, tri[1] + off, tri[2] + off});
  return t;
}

TriangleList translated(TriangleList m, double dx, double dy, double dz) {
  for (auto& p : m.points) {
    p[0] += dx;
    p[1] += dy;
    p[2] += dz;
  }
  return m;
}

TriangleList torus_chain(int g, double R, double r, int nu, int nv, double spacing) {
  if (g < 1 || nu < 4 || nu % 2 || nv < 4 || nv % 2) throw Error("torus_chain: need g >= 1 and even nu, nv >= 4");
  TriangleList out;
  // Torus grid quad (i, j) spans u in [i, i+1] du and v in [j, j+1] dv; the outer equator is v = 0.
  // Hole toward +x: quad (0, 0) (u in [0, du]); toward -x: quad (nu/2 - 1, 0) (u in [pi - du, pi]).
  // Both have corners with the same (y, z) values, so straight tubes along x join them.
  std::vector<std::array<int, 4>> plus_hole, minus_hole;  // corner ids in `out`, per torus
  for (int k = 0; k < g; ++k) {
    TriangleList tk = translated(torus(R, r, nu, nv), k * spacing, 0, 0);
    const int off = static_cast<int>(out.points.size());
    auto id = [&](int i, int j) { return off + ((i % nu) + nu) % nu * nv + ((j % nv) + nv) % nv; };
    const int qa = 0, qb = nu / 2 - 1;
    // Skip the two triangles of each hole quad (quad(i,j) emits 2 triangles at index 2*(i*nv+j)).
    for (std::size_t f = 0; f < tk.triangles.size(); ++f) {
      const int q = static_cast<int>(f / 2);
      const int i = q / nv, j = q % nv;
      const bool hole = j == 0 && ((k + 1 < g && i == qa) || (k > 0 && i == qb));
      if (hole) continue;
      auto tri = tk.triangles[f];
      out.triangles.push_back({tri[0] + off, tri[1] + off, tri[2] + off});
    }
    out.points.insert(out.points.end(), tk.points.begin(), tk.points.end());
    // Corners ordered by (u-side, v-side) so that matching corners share (y, z):
    // +x hole: u=du side is larger y; -x hole: u=pi-du side is larger y.
    plus_hole.push_back({id(qa, 0), id(qa + 1, 0), id(qa + 1, 1), id(qa, 1)});
    minus_hole.push_back({id(qb + 1, 0), id(qb, 0), id(qb, 1), id(qb + 1, 1)});
  }
  for (int k = 0; k + 1 < g; ++k) {
    const auto& a = plus_hole[k];
    const auto& b = minus_hole[k + 1];
    for (int s = 0; s < 4; ++s) quad(out, a[s], b[s], b[(s + 1) % 4], a[(s + 1) % 4]);
  }
  return out;
}

Mesh to_mesh(const TriangleList& t) {
  const TopologyReport topo = analyze_topology(t);
  return triangles_to_mesh(t, topo, /*fix_orientation=*/true);
}

}  // namespace cf::synthetic
