// The sub-voxel surface (docs/reconstruct.md, "Sub-voxel surface"): on tilted planes and spheres the
// smoothed-mask surface is closer to the analytic surface than the staircase and no vertex leaves
// its lattice edge by half a voxel; constrained fairing makes a tilted wall flat; with a partial-volume CT the surface lies on the true boundary;
// tagged fluid falls back to the mask; bad CTs and parameters are rejected.
#include <gtest/gtest.h>

#include <itkImageRegionIteratorWithIndex.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "synthetic_masks.h"

namespace cf {
namespace {

using namespace testing::masks;
using P3 = std::array<double, 3>;
using Distance = std::function<double(const P3&)>;  // signed distance to the analytic surface, mm

// Signed distance to the sphere of centre c and radius r (mm).
Distance sphere_distance(const P3& c, double r) {
  return [c, r](const P3& p) {
    return std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2])) - r;
  };
}

ReconstructOptions with_subvoxel(const std::string& mode, int sinc_iterations = ReconstructOptions{}.smoothing_iterations,
                                 const std::string& smoothing = ReconstructOptions{}.mask_smoothing,
                                 int fairing = ReconstructOptions{}.fairing_iterations) {
  ReconstructOptions o;
  o.subvoxel = mode;
  o.fairing_iterations = fairing;
  o.mask_smoothing = smoothing;
  o.smoothing_iterations = sinc_iterations;
  o.min_component_volume = 0;
  return o;
}

// The sub-voxel variants compared with the staircase: windowed sinc with and without constrained
// fairing (the default has it), the anti-alias field alone, and anti-alias + sinc + fairing.
struct Variant {
  std::string smoothing;
  int sinc;
  int fairing;
};
const int kFairing = ReconstructOptions{}.fairing_iterations;
const std::vector<Variant> kVariants = {{"sinc", 20, 0}, {"sinc", 20, kFairing}, {"antialias", 0, 0}, {"antialias", 20, kFairing}};

// RMS angle (degrees) between the unit normals of the faces whose three corners `where` accepts and
// the direction n: how far a wall that should be flat is from flat (its ripples).
double normal_rms_degrees(const Mesh& m, const P3& n, const std::function<bool(const P3&)>& where) {
  double sum = 0;
  std::size_t count = 0;
  for (auto f : m.faces()) {
    std::array<P3, 3> c;
    int k = 0;
    for (auto v : m.fv_range(f)) c[std::size_t(k++)] = {m.point(v)[0], m.point(v)[1], m.point(v)[2]};
    if (!where(c[0]) || !where(c[1]) || !where(c[2])) continue;
    const P3 a{c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]}, b{c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
    const P3 x{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    const double len = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (len <= 0) continue;
    const double cosine = std::abs(x[0] * n[0] + x[1] * n[1] + x[2] * n[2]) / len;
    const double degrees = std::acos(std::min(1.0, cosine)) * 180.0 / M_PI;
    sum += degrees * degrees;
    ++count;
  }
  return count ? std::sqrt(sum / double(count)) : 0.0;
}

// Max and RMS |distance| to the analytic surface over the vertices accepted by `where`.
struct Fit {
  double max = 0, rms = 0;
  std::size_t count = 0;
};
Fit fit(const Mesh& m, const Distance& d, const std::function<bool(const P3&)>& where) {
  Fit f;
  double sum = 0;
  for (auto v : m.vertices()) {
    const auto& q = m.point(v);
    const P3 p{q[0], q[1], q[2]};
    if (!where(p)) continue;
    const double e = std::abs(d(p));
    f.max = std::max(f.max, e);
    sum += e * e;
    ++f.count;
  }
  if (f.count) f.rms = std::sqrt(sum / double(f.count));
  return f;
}

// The largest move of a vertex between two surfaces with the same triangles (the raw staircase and
// a sub-voxel one), in voxels along each axis (identity direction): the largest |dx_a| / spacing_a.
double largest_move_voxels(const Mesh& raw, const Mesh& smooth, const P3& spacing) {
  EXPECT_EQ(raw.n_vertices(), smooth.n_vertices());
  EXPECT_EQ(raw.n_faces(), smooth.n_faces());
  if (raw.n_vertices() != smooth.n_vertices()) return 1e9;
  double worst = 0;
  for (auto v : raw.vertices()) {
    const auto a = raw.point(v), b = smooth.point(v);
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(a[k] - b[k]) / spacing[k]);
  }
  return worst;
}

void expect_same_triangles(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.n_faces(), b.n_faces());
  for (auto f : a.faces()) {
    auto ia = a.cfv_begin(f);
    auto ib = b.cfv_begin(Mesh::FaceHandle(f.idx()));
    for (int k = 0; k < 3; ++k, ++ia, ++ib) ASSERT_EQ(ia->idx(), ib->idx());
  }
}

void expect_closed_manifold(const Mesh& m, int genus, const std::string& what) {
  const TopologyReport t = analyze_topology(m);
  EXPECT_TRUE(t.closed && t.manifold && t.consistently_oriented) << what;
  ASSERT_TRUE(t.genus) << what;
  EXPECT_EQ(*t.genus, genus) << what;
}

// A gently tilted plane (the worst staircase: wide terraces): away from the box's edges, every
// variant except windowed sinc alone is much closer to the plane than the staircase; with constrained
// fairing the wall is flat (its normals within a few degrees of the plane's, a fraction of sinc
// alone); all keep the staircase's triangles and no vertex moves half a voxel.
TEST(ReconstructSubvoxel, TiltedPlaneIsFlatterAndWithinHalfAVoxel) {
  MaskSpec s;
  s.size = {48, 44, 30};
  s.spacing = {0.8, 0.8, 1.25};
  const P3 n0{0.11, -0.07, 1.0};
  const double len = std::sqrt(n0[0] * n0[0] + n0[1] * n0[1] + 1.0);
  const P3 n{n0[0] / len, n0[1] / len, n0[2] / len};
  const double offset = 18.3;
  const Distance plane = [&](const P3& p) { return n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - offset; };
  auto mask = rasterize(s, [&](const P3& p) { return plane(p) <= 0 && p[2] > 1.0; });
  // Only the tilted wall, 10 mm (12 voxels) away from the box's sides and floor.
  auto on_wall = [&](const P3& p) { return p[0] > 10 && p[0] < 28 && p[1] > 10 && p[1] < 25 && p[2] > 8; };
  ReconstructOptions raw_options = with_subvoxel("off", 0);
  const Mesh raw = reconstruct_surface(mask, raw_options);
  const Fit staircase = fit(raw, plane, on_wall);
  ASSERT_GT(staircase.count, 200u);
  const double sinc_only_degrees =
      normal_rms_degrees(reconstruct_surface(mask, with_subvoxel("mask", 20, "sinc", 0)), n, on_wall);
  for (const auto& [smoothing, sinc, fairing] : kVariants) {
    ReconstructStats st;
    const Mesh smooth = reconstruct_surface(mask, with_subvoxel("mask", sinc, smoothing, fairing), &st);
    const Fit f = fit(smooth, plane, on_wall);
    const double degrees = normal_rms_degrees(smooth, n, on_wall);
    const std::string what = smoothing + " sinc " + std::to_string(sinc) + " fairing " + std::to_string(fairing);
    if (smoothing == "sinc" && fairing == 0) {  // windowed sinc alone keeps the wide terraces
      EXPECT_LT(f.rms, 1.05 * staircase.rms) << what;
    } else {
      EXPECT_LT(f.max, 0.6 * staircase.max) << what << ": staircase max " << staircase.max;
      EXPECT_LT(f.rms, 0.7 * staircase.rms) << what << ": staircase rms " << staircase.rms;
    }
    if (fairing > 0) {
      EXPECT_LT(degrees, 0.35 * sinc_only_degrees) << what;
      EXPECT_LT(degrees, 5.5) << what;
      EXPECT_EQ(st.fairing_iterations, fairing) << what;
      EXPECT_LT(st.fairing_energy_after, st.fairing_energy_before) << what;
    }
    EXPECT_LT(largest_move_voxels(raw, smooth, s.spacing), 0.5) << what;
    EXPECT_LE(distance_to_mask_boundary(smooth, mask).max_voxels, 0.5) << what;
    expect_same_triangles(raw, smooth);
    expect_closed_manifold(smooth, 0, what);
    EXPECT_EQ(st.field_source, "mask (" + smoothing + ")");
    std::cout << "[ plane ] " << what << ": max " << f.max << " rms " << f.rms << " mm, normals " << degrees
              << " deg (staircase " << staircase.max << " / " << staircase.rms << " mm, "
              << normal_rms_degrees(raw, n, on_wall) << " deg)\n";
  }
}

// A small sphere (radius ~8 voxels) in an anisotropic grid: every variant keeps it genus 0 and
// within half a voxel of the raw surface; windowed sinc brings it much closer to the sphere than
// the staircase; Whitaker's curvature flow may pull a small convex surface slightly inwards (its
// known bias, bounded by the constraint): never more than 25 % worse than the staircase.
TEST(ReconstructSubvoxel, SphereIsCloserAndWithinHalfAVoxel) {
  MaskSpec s;
  s.size = {30, 30, 22};
  s.spacing = {0.82, 0.82, 1.25};
  const P3 c{12.1, 11.9, 13.4};
  const double R = 8.7;
  const Distance sphere = sphere_distance(c, R);
  auto mask = rasterize(s, [&](const P3& p) { return sphere(p) <= 0; });
  const auto everywhere = [](const P3&) { return true; };
  const Mesh raw = reconstruct_surface(mask, with_subvoxel("off", 0));
  const Fit staircase = fit(raw, sphere, everywhere);
  for (const auto& [smoothing, sinc, fairing] : kVariants) {
    const Mesh smooth = reconstruct_surface(mask, with_subvoxel("mask", sinc, smoothing, fairing));
    const Fit f = fit(smooth, sphere, everywhere);
    if (smoothing == "sinc") {
      EXPECT_LT(f.rms, 0.6 * staircase.rms) << smoothing;
    } else {
      EXPECT_LT(f.rms, 1.25 * staircase.rms) << smoothing << sinc;
    }
    EXPECT_LT(largest_move_voxels(raw, smooth, s.spacing), 0.5) << smoothing;
    expect_closed_manifold(smooth, 0, smoothing);
    std::cout << "[ sphere ] " << smoothing << " sinc " << sinc << " fairing " << fairing << ": max " << f.max << " rms " << f.rms << " mm (staircase "
              << staircase.max << " / " << staircase.rms << ")\n";
  }
}

// A CT of a ball of air (-1000 HU) in soft tissue (40 HU) with exact partial volume (each voxel
// averaged over 5^3 sub-samples), optionally with tagged fluid (500 HU) below z_fluid.
struct SyntheticCt {
  CtImage::Pointer ct;
  MaskImage::Pointer mask;  // voxels more than half air or fluid
};
SyntheticCt partial_volume_ball(const MaskSpec& s, const P3& c, double R, double z_fluid = -1e9) {
  SyntheticCt out{make_image<CtImage>(s), make_mask(s)};
  itk::ImageRegionIteratorWithIndex<CtImage> it(out.ct, out.ct->GetBufferedRegion());
  const int sub = 5;
  for (; !it.IsAtEnd(); ++it) {
    double hu = 0, lumen = 0;
    for (int a = 0; a < sub; ++a)
      for (int b = 0; b < sub; ++b)
        for (int d = 0; d < sub; ++d) {
          itk::ContinuousIndex<double, 3> ci;
          const int q[3] = {a, b, d};
          for (int k = 0; k < 3; ++k) ci[k] = double(it.GetIndex()[k]) - 0.5 + (q[k] + 0.5) / sub;
          CtImage::PointType p;
          out.ct->TransformContinuousIndexToPhysicalPoint(ci, p);
          const double r2 = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
          const bool in = r2 <= R * R;
          hu += in ? (p[2] < z_fluid ? 500.0 : -1000.0) : 40.0;
          lumen += in;
        }
    const double n = double(sub * sub * sub);
    it.Set(float(hu / n));
    out.mask->SetPixel(it.GetIndex(), lumen / n > 0.5 ? 1 : 0);
  }
  return out;
}

// With the partial-volume CT the surface lies on the true sphere within 0.2 voxel, much closer than
// the mask-only surfaces, and still within half a voxel of the mask's staircase.
TEST(ReconstructSubvoxel, CtBoundaryWithinAFifthOfAVoxel) {
  MaskSpec s;
  s.size = {24, 24, 24};
  s.spacing = {1.0, 1.0, 1.0};
  const P3 c{11.3, 11.6, 11.45};
  const double R = 7.3;
  const SyntheticCt data = partial_volume_ball(s, c, R);
  const Distance sphere = sphere_distance(c, R);
  const auto everywhere = [](const P3&) { return true; };
  ReconstructStats st;
  const Mesh surf = reconstruct_surface(data.mask, data.ct, with_subvoxel("auto"), &st);
  EXPECT_EQ(st.field_source, "ct");
  EXPECT_EQ(st.fluid_voxels, 0u);
  const Fit f = fit(surf, sphere, everywhere);
  EXPECT_LE(f.max, 0.2);
  const Fit mask_only = fit(reconstruct_surface(data.mask, with_subvoxel("mask")), sphere, everywhere);
  const Fit staircase = fit(reconstruct_surface(data.mask, with_subvoxel("off", 0)), sphere, everywhere);
  EXPECT_LT(f.rms, 0.7 * staircase.rms);
  EXPECT_LE(distance_to_mask_boundary(surf, data.mask).max_voxels, 0.5);
  expect_closed_manifold(surf, 0, "ct");
  std::cout << "[ ct ball ] ct max " << f.max << " rms " << f.rms << "; mask max " << mask_only.max << " rms "
            << mask_only.rms << "; staircase max " << staircase.max << " rms " << staircase.rms << " (voxels)\n";
}

// Tagged fluid fills the bottom of the ball: there the smoothed mask is used (the CT's -500 HU
// level would lie inside the fluid-tissue ramp), the air part still follows the CT within 0.2
// voxel, and the whole surface stays within half a voxel of the staircase.
TEST(ReconstructSubvoxel, TaggedFluidFallsBackToTheMask) {
  MaskSpec s;
  s.size = {24, 24, 24};
  const P3 c{11.3, 11.6, 11.45};
  const double R = 7.3, z_fluid = 9.0;
  const SyntheticCt data = partial_volume_ball(s, c, R, z_fluid);
  const Distance sphere = sphere_distance(c, R);
  ReconstructStats st;
  const Mesh surf = reconstruct_surface(data.mask, data.ct, with_subvoxel("ct"), &st);
  EXPECT_GT(st.fluid_voxels, 100u);
  const Fit air = fit(surf, sphere, [&](const P3& p) { return p[2] > z_fluid + 3.5; });
  EXPECT_GT(air.count, 100u);
  EXPECT_LE(air.max, 0.2);
  const Fit all = fit(surf, sphere, [](const P3&) { return true; });
  EXPECT_LT(all.max, 0.8);  // the fluid part: the smoothed mask, within a voxel of the sphere
  EXPECT_LE(distance_to_mask_boundary(surf, data.mask).max_voxels, 0.5);
  expect_closed_manifold(surf, 0, "fluid");
}

// The field's slabs on worker threads (CT field, fluid dilation, mask field, constraint) give the
// sequential result: the same vertex positions bit for bit and the same voxel counts, 1 vs 3 threads.
TEST(ReconstructSubvoxel, FieldIsTheSameForAnyThreadCount) {
  MaskSpec s;
  s.size = {24, 24, 24};
  const SyntheticCt data = partial_volume_ball(s, {11.3, 11.6, 11.45}, 7.3, 9.0);
  for (const std::string mode : {"ct", "mask"}) {
    const ReconstructOptions o = with_subvoxel(mode, 0, mode == "ct" ? "sinc" : "antialias", 0);
    ReconstructStats one, three;
    set_thread_count(1);
    const Mesh a = reconstruct_surface(data.mask, data.ct, o, &one);
    set_thread_count(3);
    const Mesh b = reconstruct_surface(data.mask, data.ct, o, &three);
    set_thread_count(0);
    EXPECT_EQ(one.fluid_voxels, three.fluid_voxels) << mode;
    EXPECT_EQ(one.field_clamped_voxels, three.field_clamped_voxels) << mode;
    if (mode == "ct") EXPECT_GT(one.fluid_voxels, 100u);  // the fluid dilation is taken
    expect_same_triangles(a, b);
    ASSERT_EQ(a.n_vertices(), b.n_vertices()) << mode;
    for (auto v : a.vertices()) ASSERT_EQ(a.point(v), b.point(Mesh::VertexHandle(v.idx()))) << mode << " vertex " << v.idx();
  }
}

// The CT in 16 bits (`colonflat run` holds it so from segment's crop on) gives the surface of the
// float CT it holds, vertex for vertex: the partial-volume ball with tagged fluid, rounded to whole HU.
TEST(ReconstructSubvoxel, CtInSixteenBitsGivesTheSameSurface) {
  MaskSpec s;
  s.size = {24, 24, 24};
  const SyntheticCt data = partial_volume_ball(s, {11.3, 11.6, 11.45}, 7.3, 9.0);
  auto ct16 = CompactCtImage::New();
  ct16->CopyInformation(data.ct);
  ct16->SetRegions(data.ct->GetLargestPossibleRegion());
  ct16->Allocate();
  float* hu = data.ct->GetBufferPointer();
  std::size_t fractions = 0;
  for (std::size_t q = 0, n = ct16->GetLargestPossibleRegion().GetNumberOfPixels(); q < n; ++q) {
    fractions += hu[q] != std::round(hu[q]);
    hu[q] = std::round(hu[q]);
    ct16->GetBufferPointer()[q] = short(hu[q]);
  }
  EXPECT_GT(fractions, 100u);  // rounding changed the partial-volume voxels: the CT field is used
  ReconstructStats f, c;
  Mesh a, b;
  reconstruct_surface_into(a, data.mask, data.ct.GetPointer(), with_subvoxel("ct"), &f);
  reconstruct_surface_into(b, data.mask, ct16.GetPointer(), with_subvoxel("ct"), &c);
  EXPECT_EQ(f.field_source, "ct");
  EXPECT_EQ(c.field_source, "ct");
  EXPECT_GT(f.fluid_voxels, 100u);
  EXPECT_EQ(f.fluid_voxels, c.fluid_voxels);
  EXPECT_EQ(f.field_clamped_voxels, c.field_clamped_voxels);
  expect_same_triangles(a, b);
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  for (auto v : a.vertices()) ASSERT_EQ(a.point(v), b.point(Mesh::VertexHandle(v.idx()))) << "vertex " << v.idx();
}

// Noise voxels and edge/corner contacts: the sub-voxel surface has exactly the staircase's
// triangles, so the (6,18) topology is kept (chi = 2 chi(lumen)) whatever the smoothing.
TEST(ReconstructSubvoxel, TopologyIsTheMasksOnNoise) {
  MaskSpec s;
  s.size = {20, 18, 16};
  unsigned state = 12345;
  auto mask = rasterize(s, [&](const P3& p) {
    state = state * 1103515245u + 12345u;
    const double dx = p[0] - 9.5, dy = p[1] - 8.5, dz = p[2] - 7.5;
    return dx * dx + dy * dy + dz * dz < 30 || (state >> 16) % 100 < 12;
  });
  const Mesh raw = reconstruct_surface(mask, with_subvoxel("off", 0));
  for (const auto& [smoothing, sinc, fairing] : kVariants) {
    ReconstructStats st;
    const Mesh smooth = reconstruct_surface(mask, with_subvoxel("mask", sinc, smoothing, fairing), &st);
    expect_same_triangles(raw, smooth);
    EXPECT_EQ(st.surface_euler, 2 * mask_euler_characteristic_6_18(mask)) << smoothing;
    EXPECT_LT(largest_move_voxels(raw, smooth, s.spacing), 0.5) << smoothing;
  }
}

// A CT on another grid, or subvoxel ct without a CT, is a precondition error; the CT is ignored
// with subvoxel mask/off.
TEST(ReconstructSubvoxel, CtMustMatchTheMask) {
  MaskSpec s;
  s.size = {16, 16, 16};
  const SyntheticCt data = partial_volume_ball(s, {7.5, 7.5, 7.5}, 5.0);
  EXPECT_THROW(reconstruct_surface(data.mask, with_subvoxel("ct")), PreconditionError);
  MaskSpec other = s;
  other.spacing = {1.0, 1.0, 1.1};
  auto shifted = make_image<CtImage>(other);
  EXPECT_THROW(reconstruct_surface(data.mask, shifted, with_subvoxel("auto")), PreconditionError);
  ReconstructStats st;
  reconstruct_surface(data.mask, shifted, with_subvoxel("mask"), &st);
  EXPECT_EQ(st.field_source, "mask (sinc)");  // the mask-only default
}

// Invalid sub-voxel parameters are rejected with a UsageError naming the parameter.
TEST(ReconstructSubvoxel, InvalidParametersAreRejected) {
  MaskSpec s;
  s.size = {5, 5, 5};
  auto mask = rasterize(s, [](const P3& p) { return std::abs(p[0] - 2) + std::abs(p[1] - 2) + std::abs(p[2] - 2) < 2; });
  auto expect_usage = [&](const ReconstructOptions& o, const std::string& name) {
    try {
      reconstruct_surface(mask, o);
      ADD_FAILURE() << "expected UsageError for " << name;
    } catch (const UsageError& e) {
      EXPECT_NE(std::string(e.what()).find("--" + name), std::string::npos) << e.what();
    }
  };
  ReconstructOptions o = with_subvoxel("sometimes");
  expect_usage(o, "subvoxel");
  o = with_subvoxel("mask", 20, "median");
  expect_usage(o, "mask-smoothing");
  o = with_subvoxel("mask");
  o.antialias_iterations = 0;
  expect_usage(o, "antialias-iterations");
  o = with_subvoxel("mask");
  o.antialias_rms = -1;
  expect_usage(o, "antialias-rms");
  o = with_subvoxel("ct");
  o.air_tissue_hu = 0;
  expect_usage(o, "air-tissue-hu");
  o = with_subvoxel("ct");
  o.fluid_hu = std::nan("");
  expect_usage(o, "fluid-hu");
  o = with_subvoxel("mask");
  o.fairing_iterations = -1;
  expect_usage(o, "fairing-iterations");
  o = with_subvoxel("mask");
  o.method = "discrete-flying-edges";
  expect_usage(o, "subvoxel");
}

}  // namespace
}  // namespace cf
