// After the lumen is chosen: class means, the band graph cut, the final segments and the paste
// of the crop into a mask of the CT's geometry.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "colonflat/core/error.h"
#include "segment_internal.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kExcluded = 5;  // rectal tube channel and wall
// Dependent films are looked for only at voxels up to kMaxFilmVoxelMm along every axis: a film about
// one voxel thick is then at most 2 mm, a film of fluid; at coarser voxels a bright layer one voxel
// thick under gas is as thick as the bone plates lining air spaces (the shared head CT, 3.2 mm
// pixels: sinus walls under the sinus gas), and the same 2 mm limit stops the fluid split (step 4).
constexpr double kMaxFilmVoxelMm = 2.0;
}

// Gas (kept gas below -800 HU), tissue (0-2.5 mm outside the lumen, -150..150 HU), fluid (pools).
void ColonSegmenter::class_means() {
  double as = 0, fs = 0;
  std::size_t an = 0, fn = 0;
  lumen0_.assign(d_.total, 0);
  for (std::size_t q = 0; q < d_.total; ++q) {
    lumen0_[q] = lab_[q] != 0 && lab_[q] != kExcluded;
    if (lab_[q] == 1 && hu_[q] < -800) as += hu_[q], ++an;
    if (lab_[q] == 2 && hu_[q] >= opts_.fluid_threshold) fs += hu_[q], ++fn;
  }
  st_.air_hu = an ? as / double(an) : -1000.0;
  st_.fluid_hu = fn ? fs / double(fn) : 0.0;
  Bytes shell = lumen0_;
  const int r2[3] = {int(std::ceil(2.5 / d_.sp[0])), int(std::ceil(2.5 / d_.sp[1])), int(std::ceil(2.5 / d_.sp[2]))};
  dilate_box(shell, d_, r2);
  double ts = 0;
  std::size_t tn = 0;
  for (std::size_t q = 0; q < d_.total; ++q)
    if (shell[q] && !lumen0_[q] && hu_[q] > -150 && hu_[q] < 150) ts += hu_[q], ++tn;
  st_.tissue_hu = tn ? ts / double(tn) : 40.0;
  if (st_.fluid_hu <= st_.tissue_hu + 50) st_.fluid_hu = std::max(st_.tissue_hu + 300, 450.0);
}

// Band of band-width around the initial boundary: eroded lumen and the gas/fluid layer fixed lumen,
// everything else outside the band fixed wall; the graph cut decides the band.
void ColonSegmenter::refine_boundary() {
  state_.assign(d_.total, 0);
  if (!opts_.graph_cut) {
    state_ = lumen0_;
    return;
  }
  Stopwatch clock;
  const int rb[3] = {std::max(1, int(std::round(opts_.band_width / d_.sp[0]))),
                     std::max(1, int(std::round(opts_.band_width / d_.sp[1]))),
                     std::max(1, int(std::round(opts_.band_width / d_.sp[2])))};
  {
    Bytes outer = lumen0_, inner = lumen0_;
    dilate_box(outer, d_, rb);
    erode_box(inner, d_, rb);
    for_each_voxel(d_.total, [&](std::size_t q) { state_[q] = lab_[q] == kExcluded ? 0 : (inner[q] || lab_[q] == 3 ? 1 : (outer[q] ? 2 : 0)); });
  }
  step_time("band");
  Bytes near_fluid(d_.total);
  for_each_voxel(d_.total, [&](std::size_t q) { near_fluid[q] = lab_[q] == 2; });
  const int rf[3] = {rb[0] + 1, rb[1] + 1, rb[2] + 1};
  dilate_box(near_fluid, d_, rf);
  st_.band_voxels = std::size_t(std::count(state_.begin(), state_.end(), 2));
  GraphCutInput in;
  in.d = &d_;
  in.hu = &hu_;
  in.near_fluid = &near_fluid;
  in.air = st_.air_hu;
  in.tissue = st_.tissue_hu;
  in.fluid = st_.fluid_hu;
  in.smoothness = opts_.smoothness;
  in.edge_sigma = opts_.edge_sigma;
  step_time("near_fluid");
  const GraphCutOutput out = graph_cut_band(in, state_);
  release_kept_blocks();  // the workers' slab arrays: no later request has their sizes
  st_.flow = out.flow;
  st_.graph_edges = out.edges;
  timings_["graph_build_cpu"] = out.build_cpu_s;
  timings_["maxflow_cpu"] = out.flow_cpu_s;
  st_.graph_cut_time_s = clock.seconds();
}

// Dependent films (docs/segment.md step 9): a voxel directly below kept gas along gravity (a lumen
// voxel darker than tissue, < kTissueLowHu: gas or its partial volume), brighter than tissue
// (> kTissueHighHu) and not above fluid-max, lying on wall (the voxel below it is not fluid,
// < fluid-threshold: bone under gas continues brighter), is lumen - a film of tagged fluid about one
// voxel thick on the colon's dependent wall, too thin to be bright in the 3 x 3 x 3 mean (the gas
// above darkens it). Order-free: a voxel set here is brighter than tissue, so it never qualifies another.
void ColonSegmenter::add_dependent_films() {
  if (std::max({d_.sp[0], d_.sp[1], d_.sp[2]}) > kMaxFilmVoxelMm) return;
  const long up = -long(grav_sign_) * long(d_.stride[grav_axis_]);
  const std::size_t n = d_.n[grav_axis_];  // the voxels above and below must exist
  parallel_for(d_.n[2], [&](std::size_t k0, std::size_t k1) {  // a voxel set here is gas to no one: any order
    for (std::size_t k = k0; k < k1; ++k)
      for (std::size_t j = 0; j < d_.n[1]; ++j)
        for (std::size_t i = 0; i < d_.n[0]; ++i) {
          const std::size_t c[3] = {i, j, k}, q = d_.idx(i, j, k);
          if (c[grav_axis_] < 1 || c[grav_axis_] + 1 >= n || state_[q] || lab_[q] == kExcluded) continue;
          if (hu_[q] <= kTissueHighHu || hu_[q] > opts_.fluid_max) continue;
          const std::size_t a = std::size_t(long(q) + up), b = std::size_t(long(q) - up);
          if (state_[a] == 1 && hu_[a] < kTissueLowHu && hu_[b] < opts_.fluid_threshold) state_[q] = 1;
        }
  });
}

// Gas/fluid interfaces of any slope (docs/segment.md step 10): along gravity, the voxels between a
// lumen voxel of gas (< air-threshold) above and a lumen voxel of fluid (>= fluid-threshold) below at
// most interface-width apart are lumen when the profile between them is open (no run of kOpenWallMm in
// the tissue range: one lumen, no fold or wall between). Step 4's layer is marked only under pools;
// where the level slopes or curves, or the fluid was kept later (an open interface, a link), the
// partial-volume voxels (-600..+200 HU) read as gas/tissue or tissue/fluid edges in the graph cut and
// stayed out as a membrane. Gas rests on fluid: gas below fluid is another lumen, however thin the wall
// between (two loops stacked along gravity). The anchors are the lumen before this step, so the
// result does not depend on the order of the lines (any thread count gives the same mask).
void ColonSegmenter::add_gas_fluid_interfaces() {
  const Bytes lumen = state_;
  const int wvox = int(std::ceil(opts_.interface_width / d_.sp[grav_axis_]));
  const std::size_t stride = d_.stride[grav_axis_], len = d_.n[grav_axis_];
  parallel_for(d_.total / len, [&](std::size_t l0, std::size_t l1) {
    for (std::size_t l = l0; l < l1; ++l) fill_interface_line(lumen, line_base(d_, grav_axis_, l), stride, len, wvox, d_.sp[grav_axis_]);
  });
}

// One line along gravity of add_gas_fluid_interfaces: the anchors are lumen voxels of gas or fluid;
// every voxel between a gas anchor and the fluid anchor below it is filled (fluid voxels the graph cut
// left out too: 200-320 HU read as tissue/fluid edges); a rectal tube voxel breaks the line.
void ColonSegmenter::fill_interface_line(const Bytes& lumen, std::size_t base, std::size_t stride, std::size_t len, int wvox, double h) {
  const int upper = grav_sign_ > 0 ? 1 : 2;  // the kind met first along increasing index: gas when gravity points there
  int last_kind = 0, last_pos = -1;
  for (int p = 0; p < int(len); ++p) {
    const std::size_t q = base + std::size_t(p) * stride;
    const int kind = hu_[q] < opts_.air_threshold ? 1 : (hu_[q] >= opts_.fluid_threshold ? 2 : 0);
    if (lab_[q] == kExcluded) {
      last_kind = 0;
      continue;
    }
    if (!kind || !lumen[q]) continue;
    if (last_kind == upper && kind != upper && p - last_pos > 1 && p - last_pos - 1 <= wvox &&
        tissue_run_mm(base, stride, last_pos, p, h) < kOpenWallMm)
      for (int r = last_pos + 1; r < p; ++r) state_[base + std::size_t(r) * stride] = 1;
    last_kind = kind;
    last_pos = p;
  }
}

// Components of the refined lumen that hold initial lumen and at least min(1 mL, half the
// smallest body the options allow) stay; they are the final segments.
void ColonSegmenter::final_segments() {
  add_dependent_films();
  add_gas_fluid_interfaces();
  step_time("films and interfaces");
  const RunLabels cl = component_runs(state_.data(), d_);
  const std::uint32_t n = cl.count();
  std::vector<std::size_t> count(n + 1, 0), core(n + 1, 0);
  for (std::uint32_t l = 1; l <= n; ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r) {
      count[l] += r->length;
      for (std::size_t q = r->start; q < r->start + r->length; ++q) core[l] += lumen0_[q];
    }
  const double min_ml = std::min(1.0, 0.5 * std::min(opts_.min_segment_volume, opts_.min_tagged_volume));
  std::vector<unsigned char> keep(n + 1, 0);
  std::vector<double> vols;
  for (std::uint32_t l = 1; l <= n; ++l)
    if (core[l] > 0 && double(count[l]) * voxel_ml_ >= min_ml) keep[l] = 1, vols.push_back(double(count[l]) * voxel_ml_);
  std::size_t fluid = 0;
  for (std::uint32_t l = 1; l <= n; ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r) {
      if (!keep[l]) std::fill_n(state_.data() + r->start, r->length, 0);
      else
        for (std::size_t q = r->start; q < r->start + r->length; ++q) fluid += hu_[q] >= opts_.fluid_threshold;
    }
  if (vols.empty()) throw PreconditionError("no colon found after graph-cut refinement");
  std::sort(vols.rbegin(), vols.rend());
  st_.segments = int(vols.size());
  st_.segment_volumes_ml = vols;
  st_.lumen_volume_ml = std::accumulate(vols.begin(), vols.end(), 0.0);
  st_.fluid_volume_ml = double(fluid) * voxel_ml_;
  Bytes().swap(lumen0_);
}

MaskImage::Pointer ColonSegmenter::paste() const {
  release_kept_blocks();  // the output is ITK's (heap): freed crop buffers must not add to its peak
  auto out = MaskImage::New();
  out->CopyInformation(ct_);
  out->SetRegions(ct_->GetLargestPossibleRegion());
  out->Allocate();
  out->FillBuffer(0);
  unsigned char* om = out->GetBufferPointer();
  for (std::size_t k = 0; k < d_.n[2]; ++k)
    for (std::size_t j = 0; j < d_.n[1]; ++j)
      std::copy_n(state_.data() + (k * d_.n[1] + j) * d_.n[0], d_.n[0], om + full_.idx(blo_[0], blo_[1] + j, blo_[2] + k));
  return out;
}

}  // namespace cf::segment_detail
