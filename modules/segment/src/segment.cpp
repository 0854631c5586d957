#include "colonflat/segment/segment.h"

#include <itkConnectedComponentImageFilter.h>

#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <iomanip>
#include <sstream>
#include <mutex>
#include <numeric>
#include <thread>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "colonflat/core/run_stats.h"

namespace cf {

nlohmann::json SegmentStats::to_json() const {
  return {{"segments", segments},
          {"segment_volumes_ml", segment_volumes_ml},
          {"lumen_volume_ml", lumen_volume_ml},
          {"fluid_volume_ml", fluid_volume_ml},
          {"class_means_hu", {{"air", air_hu}, {"tissue", tissue_hu}, {"fluid", fluid_hu}}},
          {"band_voxels", band_voxels},
          {"graph_edges", graph_edges},
          {"max_flow", flow},
          {"removed_components", removed_components},
          {"rejected_fluid_components", rejected_fluid_components},
          {"time_s", time_s},
          {"graph_cut_time_s", graph_cut_time_s},
          {"peak_memory_mib", peak_memory_mib},
          {"timings_s", timings}};
}

void validate(const SegmentOptions& o) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw UsageError(what);
  };
  check(o.air_threshold >= -1000 && o.air_threshold <= -200, "--air-threshold must be in [-1000, -200] HU (got " + format_number(o.air_threshold) + ")");
  check(o.fluid_threshold >= 50 && o.fluid_threshold <= 1000, "--fluid-threshold must be in [50, 1000] HU (got " + format_number(o.fluid_threshold) + ")");
  check(o.fluid_max > o.fluid_threshold && o.fluid_max <= 4000, "--fluid-max must be above --fluid-threshold and <= 4000 HU (got " + format_number(o.fluid_max) + ")");
  check(o.interface_width >= 0 && o.interface_width <= 20, "--interface-width must be in [0, 20] mm (got " + format_number(o.interface_width) + ")");
  check(o.level_tolerance >= 0.5 && o.level_tolerance <= 50, "--level-tolerance must be in [0.5, 50] mm (got " + format_number(o.level_tolerance) + ")");
  check(o.band_width >= 0.5 && o.band_width <= 10, "--band-width must be in [0.5, 10] mm (got " + format_number(o.band_width) + ")");
  check(o.smoothness >= 0 && o.smoothness <= 10, "--smoothness must be in [0, 10] (got " + format_number(o.smoothness) + ")");
  check(o.edge_sigma >= 1 && o.edge_sigma <= 2000, "--edge-sigma must be in [1, 2000] HU (got " + format_number(o.edge_sigma) + ")");
  check(o.min_segment_volume >= 0 && o.min_segment_volume <= 5000, "--min-segment-volume must be in [0, 5000] mL (got " + format_number(o.min_segment_volume) + ")");
  check(o.min_colon_volume >= 0 && o.min_colon_volume <= 10000, "--min-colon-volume must be in [0, 10000] mL (got " + format_number(o.min_colon_volume) + ")");
  check(o.min_segment_fraction >= 0 && o.min_segment_fraction <= 1, "--min-segment-fraction must be in [0, 1] (got " + format_number(o.min_segment_fraction) + ")");
  check(o.max_segments >= 1 && o.max_segments <= 100, "--max-segments must be in [1, 100] (got " + std::to_string(o.max_segments) + ")");
}

namespace {

using LabelImage = itk::Image<std::uint32_t, 3>;

struct Dims {
  std::size_t n[3];
  std::size_t stride[3];
  std::size_t total;
  double sp[3];
  std::size_t idx(std::size_t i, std::size_t j, std::size_t k) const { return i + n[0] * (j + n[1] * k); }
  void coords(std::size_t q, std::size_t& i, std::size_t& j, std::size_t& k) const {
    i = q % n[0];
    j = (q / n[0]) % n[1];
    k = q / (n[0] * n[1]);
  }
};

void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body) {
  const std::size_t threads = std::max<std::size_t>(1, std::min<std::size_t>(2, std::thread::hardware_concurrency()));
  if (threads == 1 || n < 2) return body(0, n);
  std::vector<std::thread> ts;
  for (std::size_t t = 0; t < threads; ++t) ts.emplace_back([&, t] { body(n * t / threads, n * (t + 1) / threads); });
  for (auto& t : ts) t.join();
}

// Face-connected components of a 0/1 image; returns labels 1..n (0 background) and n.
LabelImage::Pointer components(const MaskImage* m, std::uint32_t& count) {
  using CC = itk::ConnectedComponentImageFilter<MaskImage, LabelImage>;
  auto cc = CC::New();
  cc->SetInput(m);
  cc->SetFullyConnected(false);
  cc->SetNumberOfWorkUnits(2);
  cc->Update();
  count = cc->GetObjectCount();
  LabelImage::Pointer out = cc->GetOutput();
  out->DisconnectPipeline();
  return out;
}

MaskImage::Pointer new_mask(const CtImage* like) {
  auto m = MaskImage::New();
  m->CopyInformation(like);
  m->SetRegions(like->GetLargestPossibleRegion());
  m->Allocate();
  m->FillBuffer(0);
  return m;
}

// In-place binary dilation of `v` (0/1) by a box of half-widths r[3] voxels (separable).
void dilate_box(std::vector<unsigned char>& v, const Dims& d, const int r[3]) {
  std::vector<unsigned char> tmp(v.size());
  const std::size_t nx = d.n[0], ny = d.n[1], nz = d.n[2];
  for (int ax = 0; ax < 3; ++ax) {
    if (r[ax] <= 0) continue;
    const long R = r[ax];
    // Rows (x lines) are contiguous: along y and z whole rows are OR-ed (cache friendly).
    parallel_for(nz, [&](std::size_t k0, std::size_t k1) {
      for (std::size_t k = k0; k < k1; ++k)
        for (std::size_t j = 0; j < ny; ++j) {
          unsigned char* out = tmp.data() + (k * ny + j) * nx;
          if (ax == 0) {
            const unsigned char* in = v.data() + (k * ny + j) * nx;
            long last = -1000000;
            for (long i = 0; i < long(nx); ++i) {
              if (in[i]) last = i;
              out[i] = (i - last <= R) ? 1 : 0;
            }
            last = 1000000;
            for (long i = long(nx) - 1; i >= 0; --i) {
              if (in[i]) last = i;
              if (last - i <= R) out[i] = 1;
            }
            continue;
          }
          std::memset(out, 0, nx);
          const long c = ax == 1 ? long(j) : long(k), n = ax == 1 ? long(ny) : long(nz);
          for (long o = std::max(0L, c - R); o <= std::min(n - 1, c + R); ++o) {
            const unsigned char* in = v.data() + (ax == 1 ? (k * ny + std::size_t(o)) : (std::size_t(o) * ny + j)) * nx;
            for (std::size_t i = 0; i < nx; ++i) out[i] |= in[i];
          }
        }
    });
    v.swap(tmp);
  }
}

// Erosion = complement of the dilation of the complement.
void erode_box(std::vector<unsigned char>& v, const Dims& d, const int r[3]) {
  for (auto& x : v) x = !x;
  dilate_box(v, d, r);
  for (auto& x : v) x = !x;
}

// Index axis closest to an LPS axis (0 = x, 1 = y, 2 = z), and whether it runs along +LPS.
void axis_for(const CtImage* ct, int lps, int& axis, bool& positive) {
  const auto D = ct->GetDirection();
  axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(D[lps][a]) > std::abs(D[lps][axis])) axis = a;
  positive = D[lps][axis] > 0;
}



MaskImage::Pointer mask_of_size(const std::size_t n[3]) {
  auto m = MaskImage::New();
  MaskImage::SizeType sz{{n[0], n[1], n[2]}};
  m->SetRegions(sz);
  m->Allocate();
  return m;
}

Dims make_dims(const std::size_t n[3], const double sp[3]) {
  Dims d;
  for (int a = 0; a < 3; ++a) {
    d.n[a] = n[a];
    d.sp[a] = sp[a];
  }
  d.stride[0] = 1;
  d.stride[1] = d.n[0];
  d.stride[2] = d.n[0] * d.n[1];
  d.total = d.n[0] * d.n[1] * d.n[2];
  return d;
}

// Base index of line `l` along axis `ax`.
std::size_t line_base(const Dims& d, int ax, std::size_t l) {
  if (ax == 0) return l * d.n[0];
  if (ax == 1) return (l % d.n[0]) + (l / d.n[0]) * d.n[0] * d.n[1];
  return l;
}

using Csr = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                               boost::no_property, std::uint32_t, std::uint32_t>;
using CsrEdge = boost::graph_traits<Csr>::edge_descriptor;

// Min-cut of one slab of the band. `state`: 0 fixed wall, 1 fixed lumen, 2 free (band).
// Writes 1/0 into `result` for band voxels with slice index in [c0, c1); returns the flow.
struct SlabOut {
  long flow = 0;
  std::size_t edges = 0;
  double build_s = 0, flow_s = 0;
};
SlabOut solve_slab(const Dims& d, const unsigned char* state, const std::function<void(std::size_t, long&, long&)>& data,
                   const std::function<long(std::size_t, std::size_t, int)>& pair_w, std::size_t k0, std::size_t k1,
                   std::size_t c0, std::size_t c1, std::vector<unsigned char>& result) {
  const std::size_t slice = d.n[0] * d.n[1];
  std::vector<std::size_t> vox;
  for (std::size_t q = k0 * slice; q < k1 * slice; ++q)
    if (state[q] == 2) vox.push_back(q);
  SlabOut out;
  if (vox.empty()) return out;
  Stopwatch sw;
  const std::uint32_t n = std::uint32_t(vox.size());
  const std::uint32_t S = n, T = n + 1;
  // Node index of every voxel of the slab (dense map: faster than searching `vox`).
  const std::size_t base = k0 * slice;
  std::vector<std::uint32_t> node(k1 * slice - base, UINT32_MAX);
  for (std::uint32_t i = 0; i < std::uint32_t(vox.size()); ++i) node[vox[i] - base] = i;
  auto node_of = [&](std::size_t q) -> std::int64_t {
    const std::uint32_t v = node[q - base];
    return v == UINT32_MAX ? -1 : std::int64_t(v);
  };
  // Out-edges per node, sorted by target: band neighbours (ascending), then S, then T.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  std::vector<long> cap;
  edges.reserve(std::size_t(n) * 8 + 2 * std::size_t(n));
  cap.reserve(edges.capacity());
  std::vector<long> src(n), snk(n);
  std::vector<std::uint32_t> first(n + 3, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    first[i] = std::uint32_t(edges.size());
    const std::size_t q = vox[i];
    long s_cap = 0, t_cap = 0;
    data(q, s_cap, t_cap);
    std::size_t c[3];
    d.coords(q, c[0], c[1], c[2]);
    // Neighbours in ascending voxel order: -z, -y, -x, +x, +y, +z.
    static const int order[6][2] = {{2, -1}, {1, -1}, {0, -1}, {0, 1}, {1, 1}, {2, 1}};
    for (const auto& od : order) {
      const int ax = od[0], dir = od[1];
      if ((dir < 0 && c[ax] == 0) || (dir > 0 && c[ax] + 1 == d.n[ax])) continue;
      if (ax == 2 && (std::int64_t(c[2]) + dir < std::int64_t(k0) || std::int64_t(c[2]) + dir >= std::int64_t(k1))) continue;
      const std::size_t r = dir < 0 ? q - d.stride[ax] : q + d.stride[ax];
      const long w = pair_w(q, r, ax);
      if (state[r] == 1) s_cap += w;
      else if (state[r] == 0) t_cap += w;
      else {
        const std::int64_t j = node_of(r);
        if (j < 0) continue;
        edges.emplace_back(i, std::uint32_t(j));
        cap.push_back(w);
      }
    }
    const long m = std::min(s_cap, t_cap);
    src[i] = s_cap - m;
    snk[i] = t_cap - m;
    edges.emplace_back(i, S);
    cap.push_back(0);
    edges.emplace_back(i, T);
    cap.push_back(snk[i]);
  }
  first[S] = std::uint32_t(edges.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    edges.emplace_back(S, i);
    cap.push_back(src[i]);
  }
  first[T] = std::uint32_t(edges.size());
  for (std::uint32_t i = 0; i < n; ++i) {
    edges.emplace_back(T, i);
    cap.push_back(0);
  }
  first[T + 1] = std::uint32_t(edges.size());
  Csr g(boost::edges_are_sorted, edges.begin(), edges.end(), n + 2);
  // Reverse edges by position.
  std::vector<CsrEdge> rev(edges.size());
  for (std::uint32_t e = 0; e < edges.size(); ++e) {
    const auto [u, v] = edges[e];
    std::uint32_t r;
    if (u == S) r = first[v] + (first[v + 1] - first[v]) - 2;       // v -> S
    else if (u == T) r = first[v] + (first[v + 1] - first[v]) - 1;  // v -> T
    else if (v == S) r = first[S] + u;
    else if (v == T) r = first[T] + u;
    else {
      auto b = edges.begin() + first[v], en = edges.begin() + first[v + 1] - 2;
      auto it = std::lower_bound(b, en, std::make_pair(v, u));
      r = std::uint32_t(it - edges.begin());
    }
    rev[e] = CsrEdge(v, r);
  }
  std::vector<long> res(cap.size(), 0);
  std::vector<boost::default_color_type> color(n + 2);
  std::vector<CsrEdge> pred(n + 2);
  std::vector<long> dist(n + 2, 0);
  auto eim = boost::get(boost::edge_index, g);
  auto vim = boost::get(boost::vertex_index, g);
  out.build_s = sw.seconds();
  sw.restart();
  out.flow = boost::boykov_kolmogorov_max_flow(
      g, boost::make_iterator_property_map(cap.begin(), eim), boost::make_iterator_property_map(res.begin(), eim),
      boost::make_iterator_property_map(rev.begin(), eim), boost::make_iterator_property_map(pred.begin(), vim),
      boost::make_iterator_property_map(color.begin(), vim), boost::make_iterator_property_map(dist.begin(), vim), vim,
      S, T);
  out.edges = cap.size();
  out.flow_s = sw.seconds();
  const auto black = boost::color_traits<boost::default_color_type>::black();
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t q = vox[i];
    const std::size_t k = q / slice;
    if (k >= c0 && k < c1) result[q] = color[i] == black ? 1 : 0;
  }
  return out;
}

}  // namespace

MaskImage::Pointer segment_colon(const CtImage* ct, const SegmentOptions& opts, SegmentStats* stats_out) {
  validate(opts);
  Stopwatch clock, step;
  SegmentStats st;
  nlohmann::json timings = nlohmann::json::object();
  auto lap = [&](const char* name) {
    timings[name] = step.seconds();
    step.restart();
  };
  if (!ct) throw PreconditionError("segment: no volume");
  const auto size = ct->GetLargestPossibleRegion().GetSize();
  std::size_t fn[3];
  double fsp[3];
  for (int a = 0; a < 3; ++a) {
    fn[a] = size[a];
    // Rounded so that the same volume read from DICOM or NRRD gives the same weights.
    fsp[a] = std::round(ct->GetSpacing()[a] * 1e4) / 1e4;
  }
  const Dims full = make_dims(fn, fsp);
  for (int a = 0; a < 3; ++a) {
    if (full.n[a] < 8)
      throw PreconditionError("volume is too small for colon segmentation (" + std::to_string(full.n[0]) + " x " +
                              std::to_string(full.n[1]) + " x " + std::to_string(full.n[2]) +
                              " voxels; need at least 8 per axis)");
    if (!(full.sp[a] >= 0.1 && full.sp[a] <= 10))
      throw PreconditionError("absurd voxel spacing " + format_number(ct->GetSpacing()[0]) + " x " +
                              format_number(ct->GetSpacing()[1]) + " x " + format_number(ct->GetSpacing()[2]) +
                              " mm (expected 0.1 to 10 mm per axis)");
  }
  const float* fhu = ct->GetBufferPointer();
  const double voxel_ml = full.sp[0] * full.sp[1] * full.sp[2] / 1000.0;

  // CT-likeness: air and soft tissue must both be present.
  {
    std::size_t air = 0, soft = 0;
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (std::size_t q = 0; q < full.total; ++q) {
      const float v = fhu[q];
      air += v < -800;
      soft += v > -200 && v < 200;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (air < full.total / 1000 + 1 || soft < full.total / 50)
      throw PreconditionError("not a CT volume in HU: no air (< -800 HU) and soft-tissue (-200..200 HU) ranges "
                              "(values " + format_number(lo) + " .. " + format_number(hi) + ")");
  }
  int grav_axis, sup_axis;
  bool grav_pos, sup_pos;
  axis_for(ct, 1, grav_axis, grav_pos);
  axis_for(ct, 2, sup_axis, sup_pos);
  lap("checks");

  // 1. Gas bodies; remove those touching the lateral faces (outside air) and the superior face (lungs).
  std::size_t blo[3] = {full.n[0], full.n[1], full.n[2]}, bhi[3] = {0, 0, 0};
  {
    MaskImage::Pointer work = mask_of_size(full.n);
    unsigned char* w = work->GetBufferPointer();
    for (std::size_t q = 0; q < full.total; ++q) w[q] = fhu[q] < opts.air_threshold;
    std::uint32_t ngas = 0;
    LabelImage::Pointer gl = components(work, ngas);
    const std::uint32_t* glb = gl->GetBufferPointer();
    std::vector<unsigned char> drop(ngas + 1, 0);
    auto face = [&](int a, bool hi_side) {
      // Every label on this face is dropped, except on the inferior face.
      if (a == sup_axis && hi_side != sup_pos) return;
      std::size_t c[3];
      const std::size_t u = (a + 1) % 3, v = (a + 2) % 3;
      c[a] = hi_side ? full.n[a] - 1 : 0;
      for (c[v] = 0; c[v] < full.n[v]; ++c[v])
        for (c[u] = 0; c[u] < full.n[u]; ++c[u]) drop[glb[full.idx(c[0], c[1], c[2])]] = 1;
    };
    for (int a = 0; a < 3; ++a) {
      face(a, false);
      face(a, true);
    }
    drop[0] = 1;
    for (std::uint32_t l = 1; l <= ngas; ++l) st.removed_components += drop[l];
    std::size_t gas_vox = 0;
    for (std::size_t k = 0; k < full.n[2]; ++k)
      for (std::size_t j = 0; j < full.n[1]; ++j) {
        const std::size_t row = full.idx(0, j, k);
        for (std::size_t i = 0; i < full.n[0]; ++i) {
          const bool keep = !drop[glb[row + i]];
          w[row + i] = keep;
          if (keep) {
            ++gas_vox;
            blo[0] = std::min(blo[0], i), bhi[0] = std::max(bhi[0], i);
            blo[1] = std::min(blo[1], j), bhi[1] = std::max(bhi[1], j);
            blo[2] = std::min(blo[2], k), bhi[2] = std::max(bhi[2], k);
          }
        }
      }
    if (gas_vox == 0)
      throw PreconditionError("no colon found: no gas inside the body (below " + format_number(opts.air_threshold) + " HU)");
    lap("gas_components");
    // Crop to the candidate gas with a margin (fluid pools below the gas, the band, the shell).
    const double margin_mm = opts.interface_width + opts.band_width + 40.0;
    for (int a = 0; a < 3; ++a) {
      const std::size_t m = std::size_t(std::ceil(margin_mm / full.sp[a]));
      blo[a] = blo[a] > m ? blo[a] - m : 0;
      bhi[a] = std::min(full.n[a] - 1, bhi[a] + m);
    }
    std::size_t cn[3] = {bhi[0] - blo[0] + 1, bhi[1] - blo[1] + 1, bhi[2] - blo[2] + 1};
    // Keep the candidate-gas flags for the crop.
    st.removed_components += 0;
    std::vector<unsigned char> gas_crop(cn[0] * cn[1] * cn[2]);
    for (std::size_t k = 0; k < cn[2]; ++k)
      for (std::size_t j = 0; j < cn[1]; ++j)
        std::copy_n(w + full.idx(blo[0], blo[1] + j, blo[2] + k), cn[0], gas_crop.data() + (k * cn[1] + j) * cn[0]);
    // Hand over through a static-like capture below.
    work = nullptr;
    gl = nullptr;
    // Continue in the crop.
    const Dims d = make_dims(cn, full.sp);
    std::vector<float> hub(d.total);
    for (std::size_t k = 0; k < cn[2]; ++k)
      for (std::size_t j = 0; j < cn[1]; ++j)
        std::copy_n(fhu + full.idx(blo[0], blo[1] + j, blo[2] + k), cn[0], hub.data() + (k * cn[1] + j) * cn[0]);
    const float* hu = hub.data();
    MaskImage::Pointer cwork = mask_of_size(cn);
    unsigned char* cw = cwork->GetBufferPointer();
    std::vector<unsigned char> lab(std::move(gas_crop));  // 1 gas, 2 fluid, 3 layer
    lap("crop");

    // 2. Tagged fluid: bright voxels in contact (along gravity, across the partial-volume layer) with gas.
    // Fluid is classified on a 3x3x3 box average so that noise spikes in soft tissue are not fluid.
    {
      std::vector<float> sm(hub), tmp(d.total);
      const std::size_t nx = d.n[0], ny = d.n[1], nz = d.n[2];
      for (int ax = 0; ax < 3; ++ax) {
        parallel_for(nz, [&](std::size_t k0, std::size_t k1) {
          for (std::size_t k = k0; k < k1; ++k)
            for (std::size_t j = 0; j < ny; ++j) {
              float* out = tmp.data() + (k * ny + j) * nx;
              const float* mid = sm.data() + (k * ny + j) * nx;
              if (ax == 0) {
                for (std::size_t i = 0; i < nx; ++i)
                  out[i] = (mid[i > 0 ? i - 1 : i] + mid[i] + mid[i + 1 < nx ? i + 1 : i]) * (1.0f / 3.0f);
                continue;
              }
              const std::size_t rs = ax == 1 ? nx : nx * ny;  // row stride along the axis
              const std::size_t c = ax == 1 ? j : k, n = ax == 1 ? ny : nz;
              const float* lo = c > 0 ? mid - rs : mid;
              const float* hi = c + 1 < n ? mid + rs : mid;
              for (std::size_t i = 0; i < nx; ++i) out[i] = (lo[i] + mid[i] + hi[i]) * (1.0f / 3.0f);
            }
        });
        sm.swap(tmp);
      }
      for (std::size_t q = 0; q < d.total; ++q)
        if (!lab[q] && sm[q] >= opts.fluid_threshold && sm[q] <= opts.fluid_max) lab[q] = 2;
    }
    const int wvox = int(std::ceil(opts.interface_width / d.sp[grav_axis]));
    const std::size_t st_g = d.stride[grav_axis], glen = d.n[grav_axis];
    // Scans every line along gravity for gas and fluid at most wvox voxels apart. contact: 1 where
    // a fluid voxel has gas on its lower-index side, 2 on its higher-index side. With `mark_layer`,
    // the voxels between become layer (3) in `lab`.
    auto scan_lines = [&](std::vector<unsigned char>* contact, bool mark_layer) {
      parallel_for(d.total / glen, [&](std::size_t l0, std::size_t l1) {
        for (std::size_t l = l0; l < l1; ++l) {
          const std::size_t base = line_base(d, grav_axis, l);
          int last_kind = 0, last_pos = -1000000;
          for (int p = 0; p < int(glen); ++p) {
            const std::size_t q = base + std::size_t(p) * st_g;
            const unsigned char k = lab[q];
            if (k != 1 && k != 2) continue;
            if (last_kind && last_kind != k && p - last_pos - 1 <= wvox) {
              if (mark_layer)
                for (int r = last_pos + 1; r < p; ++r) lab[base + std::size_t(r) * st_g] = 3;
              if (contact) {
                if (k == 2) (*contact)[q] = 1;  // gas below in index, fluid here
                else (*contact)[base + std::size_t(last_pos) * st_g] = 2;
              }
            }
            last_kind = k;
            last_pos = p;
          }
        }
      });
    };
    {
      std::vector<unsigned char> contact(d.total, 0);
      scan_lines(&contact, false);
      for (std::size_t q = 0; q < d.total; ++q) cw[q] = lab[q] == 2;
      std::uint32_t nf = 0;
      LabelImage::Pointer fl = components(cwork, nf);
      const std::uint32_t* flb = fl->GetBufferPointer();
      // A tagged-fluid pool meets the gas above it along a horizontal level: the contacts of one
      // side must be many and at (nearly) one height. Bone touching gas here and there is not.
      std::vector<std::vector<float>> levels[2];
      levels[0].resize(nf + 1);
      levels[1].resize(nf + 1);
      for (std::size_t q = 0; q < d.total; ++q)
        if (contact[q]) {
          std::size_t c[3];
          d.coords(q, c[0], c[1], c[2]);
          levels[contact[q] - 1][flb[q]].push_back(float(double(c[grav_axis]) * d.sp[grav_axis]));
        }
      std::vector<unsigned char> keep(nf + 1, 0);
      const std::size_t min_columns =
          std::max<std::size_t>(8, std::size_t(std::ceil(100.0 / (d.total / double(d.n[grav_axis]) > 0
                                                                        ? d.sp[0] * d.sp[1] * d.sp[2] / d.sp[grav_axis]
                                                                        : 1.0))));
      std::size_t rejected = 0;
      for (std::uint32_t l = 1; l <= nf; ++l) {
        for (int side = 0; side < 2; ++side) {
          auto& v = levels[side][l];
          if (v.size() < min_columns) continue;
          std::sort(v.begin(), v.end());
          const double spread = v[v.size() * 9 / 10] - v[v.size() / 10];
          if (spread <= std::max(opts.level_tolerance, 1.5 * d.sp[grav_axis])) keep[l] = 1;
        }
        if (!keep[l] && (!levels[0][l].empty() || !levels[1][l].empty())) ++rejected;
      }
      st.rejected_fluid_components = rejected;
      double fsum = 0;
      std::size_t fcount = 0;
      for (std::size_t q = 0; q < d.total; ++q) {
        if (lab[q] == 2 && !keep[flb[q]]) lab[q] = 0;
        if (lab[q] == 2) {
          fsum += hu[q];
          ++fcount;
        }
      }
      st.fluid_hu = fcount ? fsum / double(fcount) : 0.0;
    }
    // The layer between gas and the kept fluid joins the lumen.
    scan_lines(nullptr, true);
    lap("tagged_fluid");

    // 3. Colon segments: components of gas + fluid + layer, kept by volume.
    auto select_segments = [&](std::vector<unsigned char>& in, std::vector<double>& vols) -> std::size_t {
      for (std::size_t q = 0; q < d.total; ++q) cw[q] = in[q] != 0;
      std::uint32_t n = 0;
      LabelImage::Pointer cl = components(cwork, n);
      const std::uint32_t* clb = cl->GetBufferPointer();
      std::vector<std::size_t> cnt(n + 1, 0);
      for (std::size_t q = 0; q < d.total; ++q) ++cnt[clb[q]];
      std::vector<std::uint32_t> order(n);
      std::iota(order.begin(), order.end(), 1u);
      std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return cnt[a] > cnt[b]; });
      std::vector<unsigned char> keep(n + 1, 0);
      vols.clear();
      for (std::uint32_t l : order) {
        const double ml = double(cnt[l]) * voxel_ml;
        if (int(vols.size()) >= opts.max_segments || ml < opts.min_segment_volume) break;
        if (!vols.empty() && ml < opts.min_segment_fraction * vols.front()) break;
        keep[l] = 1;
        vols.push_back(ml);
      }
      for (std::size_t q = 0; q < d.total; ++q)
        if (in[q] && !keep[clb[q]]) in[q] = 0;
      return n - vols.size();
    };
    std::vector<double> vols;
    st.removed_components += select_segments(lab, vols);
    if (vols.empty())
      throw PreconditionError("no colon found: no gas/fluid body inside the body of at least " +
                              format_number(opts.min_segment_volume) + " mL");
    {
      const double total = std::accumulate(vols.begin(), vols.end(), 0.0);
      if (total < opts.min_colon_volume) {
        std::ostringstream m;
        m << "no colon found: the gas/fluid bodies inside the body total " << std::fixed << std::setprecision(1)
          << total << " mL, less than --min-colon-volume " << format_number(opts.min_colon_volume)
          << " mL (an insufflated colon holds several hundred mL)";
        throw PreconditionError(m.str());
      }
    }
    lap("segments");

    // Class means.
    {
      double as = 0;
      std::size_t an = 0;
      for (std::size_t q = 0; q < d.total; ++q)
        if (lab[q] == 1 && hu[q] < -800) {
          as += hu[q];
          ++an;
        }
      st.air_hu = an ? as / double(an) : -1000.0;
    }
    std::vector<unsigned char> lumen0(d.total);
    for (std::size_t q = 0; q < d.total; ++q) lumen0[q] = lab[q] != 0;
    {
      std::vector<unsigned char> shell = lumen0;
      const int r2[3] = {int(std::ceil(2.5 / d.sp[0])), int(std::ceil(2.5 / d.sp[1])), int(std::ceil(2.5 / d.sp[2]))};
      dilate_box(shell, d, r2);
      double ts = 0;
      std::size_t tn = 0;
      for (std::size_t q = 0; q < d.total; ++q)
        if (shell[q] && !lumen0[q] && hu[q] > -150 && hu[q] < 150) {
          ts += hu[q];
          ++tn;
        }
      st.tissue_hu = tn ? ts / double(tn) : 40.0;
    }
    if (st.fluid_hu <= st.tissue_hu + 50) st.fluid_hu = std::max(st.tissue_hu + 300, 450.0);
    lap("class_means");

    // 4. Graph cut on a band around the initial boundary.
    std::vector<unsigned char> state(d.total);  // 0 fixed wall, 1 fixed lumen, 2 band
    if (!opts.graph_cut) {
      for (std::size_t q = 0; q < d.total; ++q) state[q] = lumen0[q];
    } else {
      Stopwatch gc_clock;
      const int rb[3] = {std::max(1, int(std::round(opts.band_width / d.sp[0]))),
                         std::max(1, int(std::round(opts.band_width / d.sp[1]))),
                         std::max(1, int(std::round(opts.band_width / d.sp[2])))};
      {
        std::vector<unsigned char> outer = lumen0, inner = lumen0;
        dilate_box(outer, d, rb);
        erode_box(inner, d, rb);
        for (std::size_t q = 0; q < d.total; ++q) state[q] = inner[q] || lab[q] == 3 ? 1 : (outer[q] ? 2 : 0);
      }
      std::vector<unsigned char> near_fluid(d.total);
      for (std::size_t q = 0; q < d.total; ++q) near_fluid[q] = lab[q] == 2;
      const int rf[3] = {rb[0] + 1, rb[1] + 1, rb[2] + 1};
      dilate_box(near_fluid, d, rf);
      const double air = st.air_hu, tis = st.tissue_hu, flu = st.fluid_hu;
      constexpr double kScale = 1000.0;
      // Data terms from the partial-volume lumen fraction: the cut passes where it is one half.
      auto data = [&](std::size_t q, long& src, long& snk) {
        const double v = hu[q];
        double a = 0;
        if (v < tis) a = std::clamp((tis - v) / (tis - air), 0.0, 1.0);
        else if (near_fluid[q]) a = std::clamp((v - tis) / (flu - tis), 0.0, 1.0);
        src = std::lround(kScale * a);          // paid when q becomes wall
        snk = std::lround(kScale * (1.0 - a));  // paid when q becomes lumen
      };
      std::size_t band = 0;
      for (std::size_t q = 0; q < d.total; ++q) band += state[q] == 2;
      st.band_voxels = band;
      const double inv2s2 = 1.0 / (2.0 * opts.edge_sigma * opts.edge_sigma);
      const double hmin = std::min({d.sp[0], d.sp[1], d.sp[2]});
      double wax[3];
      for (int a = 0; a < 3; ++a) wax[a] = kScale * opts.smoothness * hmin / d.sp[a];
      // exp(-dv^2 / 2 sigma^2) tabulated per 1/4 HU up to 8 sigma (0 beyond).
      const double step = 0.25;
      std::vector<double> gauss(std::size_t(8 * opts.edge_sigma / step) + 2);
      for (std::size_t t = 0; t < gauss.size(); ++t) gauss[t] = std::exp(-(t * step) * (t * step) * inv2s2);
      gauss.back() = 0;
      auto pair_w = [&](std::size_t p, std::size_t q, int a) -> long {
        const std::size_t t = std::min(gauss.size() - 1, std::size_t(std::abs(double(hu[p]) - double(hu[q])) / step + 0.5));
        return std::lround(wax[a] * gauss[t]);
      };
      const std::size_t nz = d.n[2], core = 32, margin = 6;
      const std::size_t nslabs = (nz + core - 1) / core;
      std::atomic<std::size_t> next{0};
      std::mutex mu;
      std::vector<unsigned char> result(d.total, 0);
      std::exception_ptr failure;
      double build_cpu = 0, flow_cpu = 0;
      parallel_for(2, [&](std::size_t, std::size_t) {
        try {
          for (std::size_t s; (s = next.fetch_add(1)) < nslabs;) {
            const std::size_t c0 = s * core, c1 = std::min(nz, c0 + core);
            const std::size_t k0 = c0 > margin ? c0 - margin : 0, k1 = std::min(nz, c1 + margin);
            SlabOut so = solve_slab(d, state.data(), data, pair_w, k0, k1, c0, c1, result);
            std::lock_guard<std::mutex> lock(mu);
            st.flow += double(so.flow) / kScale;
            st.graph_edges += so.edges;
            build_cpu += so.build_s;
            flow_cpu += so.flow_s;
          }
        } catch (...) {
          std::lock_guard<std::mutex> lock(mu);
          failure = std::current_exception();
        }
      });
      if (failure) std::rethrow_exception(failure);
      timings["graph_build_cpu"] = build_cpu;
      timings["maxflow_cpu"] = flow_cpu;
      for (std::size_t q = 0; q < d.total; ++q)
        if (state[q] == 2) state[q] = result[q];
      st.graph_cut_time_s = gc_clock.seconds();
    }
    std::vector<unsigned char>().swap(lumen0);
    lap("graph_cut");

    // 5. Final segments.
    std::vector<double> fv;
    select_segments(state, fv);
    if (fv.empty()) throw PreconditionError("no colon found after graph-cut refinement");
    st.segments = int(fv.size());
    st.segment_volumes_ml = fv;
    st.lumen_volume_ml = std::accumulate(fv.begin(), fv.end(), 0.0);
    std::size_t flv = 0;
    for (std::size_t q = 0; q < d.total; ++q) flv += state[q] && hu[q] >= opts.fluid_threshold;
    st.fluid_volume_ml = double(flv) * voxel_ml;
    // Paste the crop into a full-size mask.
    MaskImage::Pointer out = new_mask(ct);
    unsigned char* om = out->GetBufferPointer();
    for (std::size_t k = 0; k < cn[2]; ++k)
      for (std::size_t j = 0; j < cn[1]; ++j)
        std::copy_n(state.data() + (k * cn[1] + j) * cn[0], cn[0], om + full.idx(blo[0], blo[1] + j, blo[2] + k));
    lap("final_segments");
    st.time_s = clock.seconds();
    st.peak_memory_mib = peak_memory_mib();
    st.timings = timings;
    if (stats_out) *stats_out = st;
    return out;
  }
}

}  // namespace cf
