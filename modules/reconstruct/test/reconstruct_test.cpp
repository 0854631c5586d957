// reconstruct_surface on synthetic masks with analytic answers: geometry in LPS mm through any
// origin/spacing/direction, outward normals, closed manifold surfaces whose topology is the
// mask's (6,18) digital topology (also on adversarial masks), component dropping, parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <algorithm>
#include <random>

#include <itkImageRegionIteratorWithIndex.h>

#include "colonflat/core/error.h"
#include "colonflat/core/topology.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "mask_components.h"
#include "synthetic_masks.h"

namespace cf {
namespace {

using namespace testing::masks;

// A mask from an explicit voxel list on an n^3 unit grid.
MaskImage::Pointer voxels(std::size_t n, const std::vector<std::array<int, 3>>& on) {
  MaskSpec s;
  s.size = {n, n, n};
  auto m = make_mask(s);
  for (const auto& v : on) m->SetPixel({{v[0], v[1], v[2]}}, 1);
  return m;
}

double dist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

double signed_volume(const Mesh& m) {
  double v = 0;
  for (auto f : m.faces()) {
    auto it = m.cfv_begin(f);
    const Vec3 a = m.point(*it), b = m.point(*++it), c = m.point(*++it);
    v += OpenMesh::dot(a, OpenMesh::cross(b, c)) / 6.0;
  }
  return v;
}

std::array<double, 3> rotation(double ax, double ay, double az, std::array<double, 9>* out) {
  // R = Rz * Ry * Rx, row major into *out.
  const double cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay), cz = std::cos(az),
               sz = std::sin(az);
  *out = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx, sz * cy, sz * sy * sx + cz * cx,
          sz * sy * cx - cz * sx, -sy, cy * sx, cy * cx};
  return {0, 0, 0};
}

ReconstructOptions raw() {
  ReconstructOptions o;
  o.subvoxel = "off";
  o.smoothing_iterations = 0;
  o.min_component_volume = 0;
  return o;
}

// Euler characteristic of the lumen in (6,18) topology by direct counting (voxels, face pairs,
// full squares, full blocks, and blocks whose two background voxels are opposite corners).
long long brute_euler_6_18(const MaskImage* m) {
  const auto sz = m->GetBufferedRegion().GetSize();
  const long nx = long(sz[0]), ny = long(sz[1]), nz = long(sz[2]);
  auto at = [&](long i, long j, long k) -> int {
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return 0;
    return m->GetBufferPointer()[(k * ny + j) * nx + i] != 0;
  };
  long long chi = 0;
  for (long k = -1; k <= nz; ++k)
    for (long j = -1; j <= ny; ++j)
      for (long i = -1; i <= nx; ++i) {
        const int c = at(i, j, k);
        chi += c;
        chi -= (c & at(i + 1, j, k)) + (c & at(i, j + 1, k)) + (c & at(i, j, k + 1));
        chi += (c & at(i + 1, j, k) & at(i, j + 1, k) & at(i + 1, j + 1, k)) +
               (c & at(i + 1, j, k) & at(i, j, k + 1) & at(i + 1, j, k + 1)) +
               (c & at(i, j + 1, k) & at(i, j, k + 1) & at(i, j + 1, k + 1));
        int b[8], bg = 0;
        for (int q = 0; q < 8; ++q) {
          b[q] = at(i + (q & 1), j + ((q >> 1) & 1), k + ((q >> 2) & 1));
          bg += !b[q];
        }
        chi -= bg == 0;
        if (bg == 2)
          for (int q = 0; q < 4; ++q)
            if (!b[q] && !b[7 - q]) chi += 1;
      }
  return chi;
}

// Checks the closed-manifold guarantee and the topology against independent counts: one outer
// surface (positive volume) per 6-connected lumen component, chi = 2 * chi(lumen).
void expect_faithful(const MaskImage* m, const Mesh& s, const std::string& what) {
  const TopologyReport t = analyze_topology(s);
  EXPECT_TRUE(t.closed) << what;
  EXPECT_TRUE(t.manifold) << what;
  EXPECT_TRUE(t.consistently_oriented) << what;
  EXPECT_EQ(t.unreferenced_vertices, 0u) << what;
  EXPECT_EQ(t.euler, 2 * brute_euler_6_18(m)) << what;
  EXPECT_EQ(mask_euler_characteristic_6_18(m), brute_euler_6_18(m)) << what;
  // Outer surfaces: components with positive signed volume.
  const TriangleList tl = to_triangle_list(s);
  std::vector<double> vol(t.components.size(), 0.0);
  for (std::size_t f = 0; f < tl.triangles.size(); ++f) {
    const auto& a = tl.points[tl.triangles[f][0]], &b = tl.points[tl.triangles[f][1]], &c = tl.points[tl.triangles[f][2]];
    vol[std::size_t(t.face_component[f])] += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                                              a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
  }
  int outer = 0;
  for (double v : vol) outer += v > 0;
  EXPECT_EQ(outer, static_cast<int>(testing::component_sizes_6(m).size())) << what;
}

// A sphere in an anisotropic, rotated, offset image lies within a voxel of the true sphere in LPS
// mm, is one closed genus-0 component with outward normals, and encloses the right volume.
TEST(ReconstructGeometry, SphereWithinAVoxelInLps) {
  MaskSpec s;
  s.size = {40, 34, 28};
  s.spacing = {0.8, 0.9, 1.3};
  s.origin = {-120.5, 40.25, 300.0};
  rotation(0.3, -0.5, 0.9, &s.direction);
  // The sphere centre: the image centre in LPS.
  auto m0 = make_mask(s);
  MaskImage::PointType c;
  itk::ContinuousIndex<double, 3> ci;
  for (int a = 0; a < 3; ++a) ci[a] = (double(s.size[a]) - 1) / 2;
  m0->TransformContinuousIndexToPhysicalPoint(ci, c);
  const std::array<double, 3> centre{c[0], c[1], c[2]};
  const double R = 11.0;
  auto m = rasterize(s, [&](const std::array<double, 3>& p) { return dist(p, centre) <= R; });
  for (bool smooth : {false, true}) {
    ReconstructOptions o;
    o.smoothing_iterations = smooth ? 20 : 0;
    ReconstructStats st;
    const Mesh surf = reconstruct_surface(m, o, &st);
    const TopologyReport t = analyze_topology(surf);
    EXPECT_TRUE(t.closed && t.manifold);
    EXPECT_EQ(t.components.size(), 1u);
    ASSERT_TRUE(t.genus);
    EXPECT_EQ(*t.genus, 0);
    double worst = 0;
    for (auto v : surf.vertices()) {
      const auto& p = surf.point(v);
      worst = std::max(worst, std::abs(dist({p[0], p[1], p[2]}, centre) - R));
    }
    EXPECT_LT(worst, 1.3) << "smoothing " << smooth;  // the largest spacing
    const double v = signed_volume(surf);
    EXPECT_NEAR(v, 4.0 / 3.0 * M_PI * R * R * R, 0.08 * 4.0 / 3.0 * M_PI * R * R * R) << "smoothing " << smooth;
    EXPECT_EQ(st.genus, 0);
    EXPECT_EQ(st.kept.size(), 1u);
    EXPECT_GT(st.kept[0].volume_mm3, 0);
    EXPECT_EQ(st.smoothed, smooth);
  }
}

// Whatever the direction matrix (rotations, axis permutations, reflections with det < 0) and a
// non-zero region start index, normals point out of the lumen (signed volume > 0) and the surface
// sits where ITK puts the voxels.
TEST(ReconstructGeometry, OutwardNormalsForEveryDirection) {
  std::vector<std::array<double, 9>> dirs = {
      {1, 0, 0, 0, 1, 0, 0, 0, 1},   {-1, 0, 0, 0, 1, 0, 0, 0, 1}, {1, 0, 0, 0, -1, 0, 0, 0, 1},
      {1, 0, 0, 0, 1, 0, 0, 0, -1},  {-1, 0, 0, 0, -1, 0, 0, 0, 1}, {0, 1, 0, 1, 0, 0, 0, 0, 1},
      {0, 0, 1, 1, 0, 0, 0, 1, 0},   {-1, 0, 0, 0, -1, 0, 0, 0, -1}};
  std::array<double, 9> rot;
  rotation(0.7, 0.2, -1.1, &rot);
  dirs.push_back(rot);
  std::array<double, 9> rot_flip = rot;
  for (int c = 0; c < 3; ++c) rot_flip[3 * c + 1] = -rot_flip[3 * c + 1];  // negate one column: det -1
  dirs.push_back(rot_flip);
  for (const auto& d : dirs) {
    MaskSpec s;
    s.size = {20, 18, 16};
    s.spacing = {1.1, 0.7, 1.5};
    s.origin = {10, -20, 30};
    s.direction = d;
    s.start = {5, -3, 2};
    // An off-centre ellipsoid (index space), so that a wrong axis or sign moves it.
    auto m = make_mask(s);
    std::array<double, 3> centre{0, 0, 0};
    long n = 0;
    itk::ImageRegionIteratorWithIndex<MaskImage> it(m, m->GetBufferedRegion());
    for (; !it.IsAtEnd(); ++it) {
      const auto idx = it.GetIndex();
      const double x = (idx[0] - 5 - 8.0) / 5.0, y = (idx[1] + 3 - 10.0) / 6.0, z = (idx[2] - 2 - 6.0) / 4.0;
      if (x * x + y * y + z * z <= 1.0) {
        it.Set(1);
        MaskImage::PointType p;
        m->TransformIndexToPhysicalPoint(idx, p);
        for (int a = 0; a < 3; ++a) centre[a] += p[a];
        ++n;
      }
    }
    for (auto& c : centre) c /= double(n);
    ReconstructStats st;
    const Mesh surf = reconstruct_surface(m, raw(), &st);
    EXPECT_GT(signed_volume(surf), 0) << "direction " << d[0] << " " << d[1] << " " << d[2] << " ...";
    // Volume-weighted centroid of the closed surface ~ centroid of the voxel centres.
    std::array<double, 3> sc{0, 0, 0};
    double vol = 0;
    for (auto f : surf.faces()) {
      auto fv = surf.cfv_begin(f);
      const Vec3 a = surf.point(*fv), b = surf.point(*++fv), c = surf.point(*++fv);
      const double v = OpenMesh::dot(a, OpenMesh::cross(b, c)) / 6.0;
      vol += v;
      for (int k = 0; k < 3; ++k) sc[k] += v * (a[k] + b[k] + c[k]) / 4.0;
    }
    for (auto& c : sc) c /= vol;
    EXPECT_LT(dist(sc, centre), 0.5) << "direction " << d[0] << " " << d[1] << " " << d[2];
    EXPECT_EQ(st.direction_flips_orientation,
              d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) + d[2] * (d[3] * d[7] - d[4] * d[6]) < 0);
  }
}

// A solid torus (ring radius 12 mm, tube radius 4 mm) in a 40 x 40 x 16 mask of 1 x 1 x 1.2 mm voxels.
MaskImage::Pointer solid_torus() {
  MaskSpec s;
  s.size = {40, 40, 16};
  s.spacing = {1.0, 1.0, 1.2};
  s.origin = {-20, -20, -9};
  return rasterize(s, [](const std::array<double, 3>& p) {
    const double q = std::sqrt(p[0] * p[0] + p[1] * p[1]) - 12.0;
    return q * q + p[2] * p[2] <= 16.0;
  });
}

// A solid torus gives one genus-1 surface, also after smoothing and decimation with every method;
// decimation reaches about the target face count.
TEST(ReconstructTopology, TorusIsGenusOneWithEveryMethodAndStep) {
  auto m = solid_torus();
  for (const std::string method : {"flying-edges", "discrete-flying-edges", "marching-cubes"}) {
    ReconstructOptions o = raw();
    o.method = method;
    const Mesh a = reconstruct_surface(m, o);
    expect_faithful(m, a, method);
    const TopologyReport ta = analyze_topology(a);
    ASSERT_TRUE(ta.genus);
    EXPECT_EQ(*ta.genus, 1) << method;
    o.smoothing_iterations = 30;
    o.target_faces = 800;
    ReconstructStats st;
    const Mesh b = reconstruct_surface(m, o, &st);
    const TopologyReport tb = analyze_topology(b);
    EXPECT_TRUE(tb.closed && tb.manifold && tb.consistently_oriented);
    ASSERT_TRUE(tb.genus);
    EXPECT_EQ(*tb.genus, 1) << method;
    EXPECT_EQ(tb.components.size(), 1u);
    EXPECT_TRUE(st.decimated);
    EXPECT_LE(b.n_faces(), 820u);
    EXPECT_GT(signed_volume(b), 0);
  }
}

// reconstruct_surface_into builds, in the caller's empty mesh, the surface reconstruct_surface
// returns (the same points, in order, and the same faces, smoothed and faired), and refuses a
// mesh that is not empty.
TEST(ReconstructTopology, SurfaceBuiltInTheCallersMeshIsTheReturnedOne) {
  auto m = solid_torus();
  const ReconstructOptions o;  // (no decimation: OpenMesh's multiple-choice decimater samples with rand())
  const Mesh a = reconstruct_surface(m, o);
  Mesh b;
  reconstruct_surface_into(b, m, nullptr, o);
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  ASSERT_GT(a.n_faces(), 0u);
  for (const auto v : a.vertices()) EXPECT_EQ(a.point(v), b.point(v));
  for (const auto f : a.faces()) {
    std::vector<int> fa, fb;
    for (const auto v : a.fv_range(f)) fa.push_back(v.idx());
    for (const auto v : b.fv_range(f)) fb.push_back(v.idx());
    EXPECT_EQ(fa, fb);
  }
  EXPECT_THROW(reconstruct_surface_into(b, m, nullptr, o), PreconditionError);
}

// The topology reconstruct hands on (ReconstructStats::topology: its final check's, read by the
// stages that orient the surface instead of analysing it again) is the surface's own, as
// analyze_topology of its triangle list gives it, field for field, and fits it (topology_fits).
TEST(ReconstructTopology, HandedOnTopologyIsTheSurfacesOwn) {
  auto m = solid_torus();
  ReconstructOptions o;
  o.target_faces = 800;
  ReconstructStats st;
  const Mesh a = reconstruct_surface(m, o, &st);
  ASSERT_TRUE(st.topology);
  const TriangleList list = to_triangle_list(a);
  const TopologyReport own = analyze_topology(list);
  const TopologyReport& h = *st.topology;
  EXPECT_TRUE(topology_fits(h, list));
  EXPECT_EQ(h.vertices, own.vertices);
  EXPECT_EQ(h.edges, own.edges);
  EXPECT_EQ(h.faces, own.faces);
  EXPECT_EQ(h.euler, own.euler);
  EXPECT_EQ(h.genus, own.genus);
  EXPECT_EQ(h.genus, std::optional<int>(1));
  EXPECT_EQ(h.closed && h.manifold && h.orientable && h.consistently_oriented,
            own.closed && own.manifold && own.orientable && own.consistently_oriented);
  EXPECT_EQ(h.face_component, own.face_component);
  ASSERT_EQ(h.components.size(), own.components.size());
  for (std::size_t c = 0; c < own.components.size(); ++c) {
    EXPECT_EQ(h.components[c].faces, own.components[c].faces);
    EXPECT_EQ(h.components[c].genus, own.components[c].genus);
  }
  EXPECT_EQ(h.bbox_min, own.bbox_min);
  EXPECT_EQ(h.bbox_max, own.bbox_max);
  EXPECT_EQ(h.mean_edge_length, own.mean_edge_length);
}

// The three VTK filters give the same surface (same faces and the same set of points).
TEST(ReconstructTopology, MethodsAgree) {
  MaskSpec s;
  s.size = {24, 20, 18};
  s.spacing = {0.9, 1.1, 1.4};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  auto m = rasterize(s, [&](const std::array<double, 3>& p) {
    return dist(p, {10, 11, 12}) <= 7 || u(rng) < 0.08;  // a ball in noise
  });
  std::vector<std::vector<std::array<double, 3>>> points;
  std::vector<std::size_t> faces;
  for (const std::string method : {"flying-edges", "discrete-flying-edges", "marching-cubes"}) {
    ReconstructOptions o = raw();
    o.method = method;
    const TriangleList t = to_triangle_list(reconstruct_surface(m, o));
    auto p = t.points;
    std::sort(p.begin(), p.end());
    points.push_back(p);
    faces.push_back(t.triangles.size());
  }
  EXPECT_EQ(faces[0], faces[1]);
  EXPECT_EQ(faces[0], faces[2]);
  EXPECT_EQ(points[0], points[1]);
  EXPECT_EQ(points[0], points[2]);
}

// Adversarial masks: single voxels, voxels touching only along an edge or at a corner, 2x2x2
// blocks with opposite corners, checkerboards, and random noise: always a closed oriented
// manifold, with chi and outer-surface count equal to the mask's (6,18) topology (independent
// count), for every method.
TEST(ReconstructTopology, AdversarialMasksGiveFaithfulManifolds) {
  std::vector<std::pair<std::string, MaskImage::Pointer>> cases;
  cases.push_back({"single voxel", voxels(3, {{1, 1, 1}})});
  cases.push_back({"voxel at the image corner", voxels(3, {{0, 0, 0}})});
  cases.push_back({"edge contact", voxels(4, {{1, 1, 1}, {2, 2, 1}})});
  cases.push_back({"corner contact", voxels(4, {{1, 1, 1}, {2, 2, 2}})});
  cases.push_back({"opposite corners of a block", voxels(4, {{1, 1, 1}, {2, 2, 2}, {1, 2, 2}, {2, 1, 1}})});
  {
    std::vector<std::array<int, 3>> six;  // a 2x2x2 block without two opposite corners
    for (int q = 0; q < 8; ++q)
      if (q != 0 && q != 7) six.push_back({1 + (q & 1), 1 + ((q >> 1) & 1), 1 + ((q >> 2) & 1)});
    cases.push_back({"block minus opposite corners", voxels(4, six)});
  }
  {
    std::vector<std::array<int, 3>> ring;  // chains of voxels joined only through edges
    for (int i = 0; i < 4; ++i) ring.push_back({2 + i, 2 + i, 3}), ring.push_back({5 - i, 8 - i, 3});
    cases.push_back({"diagonal voxel chains", voxels(10, ring)});
  }
  {
    std::vector<std::array<int, 3>> cb, cb2;
    for (int k = 0; k < 6; ++k)
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
          if ((i + j + k) % 2 == 0) cb.push_back({i, j, k});
          if ((i + j) % 2 == 0) cb2.push_back({i, j, k});
        }
    cases.push_back({"3D checkerboard", voxels(6, cb)});
    cases.push_back({"column checkerboard", voxels(6, cb2)});
  }
  std::mt19937 rng(7);
  for (double p : {0.2, 0.45, 0.6, 0.8}) {
    for (int r = 0; r < 6; ++r) {
      std::vector<std::array<int, 3>> on;
      std::bernoulli_distribution b(p);
      for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 7; ++j)
          for (int i = 0; i < 7; ++i)
            if (b(rng)) on.push_back({i, j, k});
      if (on.empty()) on.push_back({0, 0, 0});
      cases.push_back({"random p=" + std::to_string(p) + " #" + std::to_string(r), voxels(7, on)});
    }
  }
  for (const auto& [name, m] : cases)
    for (const std::string method : {"flying-edges", "discrete-flying-edges", "marching-cubes"}) {
      ReconstructOptions o = raw();
      o.method = method;
      ReconstructStats st;
      const Mesh s = reconstruct_surface(m, o, &st);
      expect_faithful(m, s, name + " / " + method);
      EXPECT_EQ(st.surface_euler, 2 * st.mask_euler_6_18) << name;
    }
  // Smoothing and decimation keep the guarantee on noise too.
  for (std::size_t i = cases.size() - 8; i < cases.size(); ++i) {
    ReconstructOptions o = raw();
    o.smoothing_iterations = 15;
    o.target_faces = 100;
    const Mesh s = reconstruct_surface(cases[i].second, o);
    const TopologyReport t = analyze_topology(s);
    EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented) << cases[i].first;
    EXPECT_EQ(t.euler, 2 * brute_euler_6_18(cases[i].second)) << cases[i].first;
  }
}

// A hollow ball gives two surfaces: the outer one (volume > 0) and the cavity wall (volume < 0,
// normals pointing into the cavity, i.e. out of the lumen).
TEST(ReconstructTopology, CavityHasItsOwnInwardFacingSurface) {
  MaskSpec s;
  s.size = {30, 30, 30};
  auto m = rasterize(s, [](const std::array<double, 3>& p) {
    const double r = dist(p, {14.5, 14.5, 14.5});
    return r <= 12 && r >= 6;
  });
  ReconstructStats st;
  reconstruct_surface(m, raw(), &st);
  ASSERT_EQ(st.kept.size(), 2u);
  EXPECT_GT(st.kept[0].volume_mm3, 0);
  EXPECT_LT(st.kept[1].volume_mm3, 0);
  EXPECT_NEAR(st.kept[1].volume_mm3, -4.0 / 3.0 * M_PI * 216, 0.15 * 4.0 / 3.0 * M_PI * 216);
}

// Components enclosing less than min-component-volume are dropped and reported; one surface
// component remains per large segment.
TEST(ReconstructComponents, SmallComponentsAreDroppedAndReported) {
  MaskSpec s;
  s.size = {48, 24, 24};
  s.spacing = {0.5, 0.5, 0.5};
  auto m = rasterize(s, [](const std::array<double, 3>& p) {
    return dist(p, {5.5, 5.5, 5.5}) <= 4.5 || dist(p, {17.5, 5.5, 5.5}) <= 4.5 || dist(p, {11.5, 9.0, 9.0}) <= 0.8;
  });
  ReconstructOptions o = raw();
  o.min_component_volume = 50;  // the balls enclose ~380 mm^3, the speck ~2 mm^3
  ReconstructStats st;
  const Mesh surf = reconstruct_surface(m, o, &st);
  EXPECT_EQ(st.components_found, 3u);
  EXPECT_EQ(st.kept.size(), 2u);
  ASSERT_EQ(st.dropped.size(), 1u);
  EXPECT_LT(std::abs(st.dropped[0].volume_mm3), 50);
  EXPECT_EQ(analyze_topology(surf).components.size(), 2u);
  const auto j = st.to_json();
  EXPECT_EQ(j["components"], 2);
  EXPECT_EQ(j["components_dropped"], 1);
  EXPECT_EQ(j["units"], "mm");
  EXPECT_EQ(j["coordinate_system"], "LPS");
  // Everything too small: a clear precondition error naming the parameter.
  o.min_component_volume = 1e6;
  try {
    reconstruct_surface(m, o);
    FAIL() << "expected PreconditionError";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("--min-component-volume"), std::string::npos) << e.what();
  }
}

// Any non-zero voxel value counts as lumen (a 0/255 mask gives the 0/1 result).
TEST(ReconstructInput, NonZeroIsLumen) {
  auto a = voxels(6, {{2, 2, 2}, {3, 2, 2}, {3, 3, 2}});
  auto b = voxels(6, {{2, 2, 2}, {3, 2, 2}, {3, 3, 2}});
  b->SetPixel({{2, 2, 2}}, 255);
  b->SetPixel({{3, 3, 2}}, 7);
  const Mesh ma = reconstruct_surface(a, raw()), mb = reconstruct_surface(b, raw());
  ASSERT_EQ(ma.n_vertices(), mb.n_vertices());
  for (auto v : ma.vertices()) EXPECT_EQ(ma.point(v), mb.point(v));
}

// An empty mask is a clear precondition error, not an empty surface.
TEST(ReconstructInput, EmptyMaskIsAnError) {
  auto m = voxels(5, {});
  try {
    reconstruct_surface(m, raw());
    FAIL() << "expected PreconditionError";
  } catch (const PreconditionError& e) {
    EXPECT_NE(std::string(e.what()).find("empty"), std::string::npos) << e.what();
  }
  EXPECT_THROW(reconstruct_surface(nullptr, raw()), PreconditionError);
}

// Invalid parameters are rejected with a UsageError naming the parameter.
TEST(ReconstructInput, InvalidParametersAreRejected) {
  auto m = voxels(3, {{1, 1, 1}});
  auto expect_usage = [&](ReconstructOptions o, const std::string& name) {
    try {
      reconstruct_surface(m, o);
      ADD_FAILURE() << "expected UsageError for " << name;
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("--" + name), std::string::npos) << e.what();
    }
  };
  ReconstructOptions o = raw();
  o.method = "dual-contouring";
  expect_usage(o, "method");
  o = raw();
  o.min_component_volume = -1;
  expect_usage(o, "min-component-volume");
  o = raw();
  o.smoothing_iterations = -1;
  expect_usage(o, "smoothing-iterations");
  o = raw();
  o.pass_band = 0;
  expect_usage(o, "pass-band");
  o = raw();
  o.target_faces = -5;
  expect_usage(o, "target-faces");
  o = raw();
  o.min_component_volume = std::nan("");
  expect_usage(o, "min-component-volume");
}

}  // namespace
}  // namespace cf
