#pragma once
// Internal pieces of segment_colon (docs/segment.md): voxel-grid helpers, the band graph cut, and
// the ColonSegmenter holding the state of one segmentation with one method per step.
#include <itkImage.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/default_init_allocator.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/segment/segment.h"
#include "hu_crop.h"
#include "segment_buffers.h"

namespace cf::segment_detail {

class LinkGrid;
struct Contact;
struct LocalShape;


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

Dims make_dims(const std::size_t n[3], const double sp[3]);
// COLONFLAT_SEGMENT_TIMES=1: prints "segment step NAME: wall W s, cpu C s" to stderr, the wall and
// process CPU seconds since the previous call (the sub-steps of the report's phases).
void step_time(const char* name);
using cf::process_cpu_seconds;  // core/threads.h
// Splits [0, n) into one chunk per cf::thread_count() thread (core parallel_for).
void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& body);
// f(q) for every q in [0, n), in chunks over the worker threads (parallel_for): for passes where each
// voxel's result depends on nothing written by the pass, so any thread count gives the same result.
template <class F>
void for_each_voxel(std::size_t n, F&& f) {
  parallel_for(n, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) f(q);
  });
}
// Post: v.size() == n and every element == value, written in chunks over the workers (no serial
// pass over v; when the size changes, the old block is freed before the new one is taken).
template <class T>
void fill_parallel(RawBuffer<T>& v, std::size_t n, T value) {
  if (v.size() != n) {
    RawBuffer<T>().swap(v);
    v.resize(n);
  }
  parallel_for(n, [&](std::size_t q0, std::size_t q1) { std::fill(v.data() + q0, v.data() + q1, value); });
}
// A run of voxels along axis 0: linear index of its first voxel and its length.
struct Run {
  std::size_t start;
  std::size_t length;
};
// Face-connected components of a 0/1 voxel array as runs along axis 0, without a dense label
// image: runs of label l (1..count()) are runs[first[l - 1] .. first[l]), in raster order. Labels
// are numbered as itk::ConnectedComponentImageFilter numbers them (the same scanline union-find of
// itk::BinaryImageToLabelMapFilter, 2 work units).
struct RunLabels {
  std::vector<std::size_t> first{0};
  std::vector<Run> runs;
  std::uint32_t count() const { return std::uint32_t(first.size() - 1); }
  const Run* begin(std::uint32_t l) const { return runs.data() + first[l - 1]; }
  const Run* end(std::uint32_t l) const { return runs.data() + first[l]; }
  // All runs of the labels with keep[l] != 0 as (run, label), in raster order (ascending start).
  std::vector<std::pair<Run, std::uint32_t>> raster(const std::vector<unsigned char>& keep) const;
};
RunLabels component_runs(const unsigned char* mask, const Dims& d);
// Voxel -> label of a RunLabels (0: in no run), by binary search over its runs in raster order.
class RunLookup {
 public:
  RunLookup() = default;
  explicit RunLookup(const RunLabels& labels);
  std::uint32_t at(std::size_t q) const;

 private:
  std::vector<std::size_t> start_, length_;
  std::vector<std::uint32_t> label_;
};
// In-place binary dilation / erosion of `v` (0/1) by a box of half-widths r[3] voxels (separable).
void dilate_box(Bytes& v, const Dims& d, const int r[3]);
void erode_box(Bytes& v, const Dims& d, const int r[3]);
// Inputs of gather_level_heights: the crop, the axis, interface-width in voxels, the contact marks of
// ColonSegmenter::scan_contacts (1: gas at lower index, 2: higher; 0 none), the crop labels, the
// fluid pieces and the crop's gas bodies (all arrays of d->total voxels).
struct LevelGatherInput {
  const Dims* d;
  int axis;
  int wvox;
  const unsigned char* contact;
  const unsigned char* lab;
  const std::uint32_t* fluid_label;
  const RunLookup* gas;
};
// (fluid piece, gas body the contact faces within wvox + 1 voxels, 0 if none) -> contact heights (mm).
using LevelHeights = std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<float>>;
// Appends to heights[side] (side = contact - 1) each contact voxel's height along the axis. Slabs of
// z over the workers, merged in z order: every list equals the serial raster scan's, for any thread
// count. Returns the number of slabs used (min(thread_count(), slices)).
std::size_t gather_level_heights(const LevelGatherInput& in, LevelHeights heights[2]);
// Voxels below -800 HU (air) and in (-200, 200) HU (soft tissue), lowest and highest value of hu[0 .. n),
// in chunks over the workers (ColonSegmenter::check_input: is this a CT in HU?).
struct HuTally {
  std::size_t air = 0, soft = 0;
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
};
HuTally tally_hu(const float* hu, std::size_t n);
// The growth of the fluid pieces (ColonSegmenter::grow_pieces): the crop, the bright mask (0/1),
// the CT and fluid-threshold (HU), the labels grown (d->total; 0 = none yet).
struct GrowInput {
  const Dims* d;
  const unsigned char* bright;
  const HuCrop* hu;
  double fluid_threshold;
  std::uint32_t* label;
};
// The worker (0 .. workers - 1) owning each voxel of `mask` (0/1), found on cells of cell^3 voxels:
// a cell is set when it holds a voxel of the mask, and each face-connected component of set cells
// (a union of the mask's components: two face neighbours lie in one cell or in face-neighbouring
// cells) goes, largest first (mask voxels), to the least-loaded worker (ties: the lower index; LPT).
// The owners depend only on the mask, `workers` and `cell`. Pre: 1 <= workers <= 255, cell >= 1.
class ComponentOwners {
 public:
  ComponentOwners(const Bytes& mask, const Dims& d, std::size_t workers, std::size_t cell);
  unsigned char at(std::size_t q) const;  // pre: q in the mask
  std::size_t workers() const { return workers_; }

 private:
  const Dims* d_;
  Dims cells_{};
  std::size_t cell_, workers_;
  std::vector<unsigned char> owner_;  // per cell
};
// Breadth-first from `queue` (bright voxels, labelled): first through fluid voxels (own HU >=
// fluid-threshold), then from the voxels with an unlabelled bright non-fluid neighbour into the rest
// of the mask; each voxel takes the label of the voxel that reaches it first. The queue is split by
// `owners` into one queue per worker (each in the queue's order) grown concurrently: a component's
// growth reads and writes only its own voxels and its queue is the subsequence of the whole queue, so
// the labels equal one serial growth's for any worker count. Returns the number of non-empty queues.
// Post: queue is empty.
std::size_t grow_labels(const GrowInput& in, const ComponentOwners& owners, std::vector<std::size_t>& queue);
// Erosion of `m` (0/1) by a ball of radius r_mm (voxels outside the volume count as set).
Bytes erode_ball(const Bytes& m, const Dims& d, double r_mm);
// 3 x 3 x 3 box mean (edges clamped; separable x, y, z passes) streamed slice by slice: calls
// slice(k, mean of slice k) for every k, from two workers (each slice once, slices of one worker
// in order); only a few slices are held in memory.
void box_mean3_slices(const float* in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice);
// The same on 16-bit values (an integer CT): the same means, as the sums are exact either way.
void box_mean3_slices(const std::int16_t* in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice);
// The same on the crop's CT, whichever its width.
void box_mean3_slices(const HuCrop& in, const Dims& d, const std::function<void(std::size_t, const float*)>& slice);
// Calls f(r) for each face neighbour r of voxel q (inside the volume).
template <class F>
void for_face_neighbours(const Dims& d, std::size_t q, F&& f) {
  std::size_t c[3];
  d.coords(q, c[0], c[1], c[2]);
  for (int a = 0; a < 3; ++a)
    for (int dir = -1; dir <= 1; dir += 2) {
      if ((dir < 0 && c[a] == 0) || (dir > 0 && c[a] + 1 == d.n[a])) continue;
      f(dir < 0 ? q - d.stride[a] : q + d.stride[a]);
    }
}
// Base index of line `l` along axis `ax` (lines enumerate the other two axes).
std::size_t line_base(const Dims& d, int ax, std::size_t l);

// Graph cut on the band: state 0 fixed wall, 1 fixed lumen, 2 free; free voxels get 0/1.
struct GraphCutInput {
  const Dims* d = nullptr;
  const HuCrop* hu = nullptr;
  const Bytes* near_fluid = nullptr;  // where bright voxels count as lumen
  double air = -1000, tissue = 40, fluid = 450;            // class means (HU)
  double smoothness = 0.5, edge_sigma = 60;
};
struct GraphCutOutput {
  double flow = 0;
  std::size_t edges = 0;
  double build_cpu_s = 0, flow_cpu_s = 0;
};
GraphCutOutput graph_cut_band(const GraphCutInput& in, Bytes& state);

// Face pairs across the boundary of two fluid pieces inside one candidate component
// (candidate_bodies, segment_split.cpp): key (component, smaller piece, larger piece), the pairs
// counted and those fluid in both voxels' own values.
struct PiecePair {
  std::array<std::uint32_t, 3> key;
  std::size_t pairs, fluid;
};

// One decision about a gas or fluid body, for the report.
struct Decision {
  std::string what;    // "gas body", "fluid body", "segment", "rectal tube"
  double volume_ml = 0;
  std::array<double, 3> position_lps_mm{};
  bool kept = false;
  std::string reason;
};

// Per-label voxel count, centroid (crop voxel coordinates) and whether it touches the crop's faces.
struct BodyStats {
  std::size_t voxels = 0, gas = 0;
  double sum[3] = {0, 0, 0};
  bool touches_face = false;
};

// Tissue: fat (-190 HU) up to enhanced bowel wall (150 HU). Brighter than kTissueHighHu inside the
// body is tagged material, bone or an enhanced vessel (segment_open.cpp, dependent films).
inline constexpr double kTissueLowHu = -190, kTissueHighHu = 150;
// A gas/fluid profile is walled when it stays in the tissue range for >= kOpenWallMm (tissue_run_mm): two
// lumens pressed together are separated by two bowel walls (each 1-3 mm), >= 2 mm; a direct gas/fluid
// interface stays in the range for 0.6 blur sigma, plus up to about one voxel where a partial-volume
// voxel lies near 0 HU (measured on the painted cases at 1.64 mm pixels: 0.5-1.5 mm). Used by the open
// interfaces (segment_open.cpp) and the gas/fluid interface layer (segment_refine.cpp).
inline constexpr double kOpenWallMm = 1.5;

// Reasons of candidates kept by an open interface (segment_open.cpp): its fluid meets a colon body's
// gas, or its gas meets a colon body's fluid, with no wall between.
inline constexpr const char* kOpenFluidReason = "colon fluid: meets a colon segment's gas with no wall between (one lumen)";
inline constexpr const char* kOpenGasReason = "colon gas: meets a colon body's fluid with no wall between (one lumen)";

// Gas/fluid columns between one candidate and one gas owner (segment_open.cpp), per image axis:
// all columns and those without a tissue layer between gas and fluid.
struct InterfaceTally {
  std::size_t columns[3] = {0, 0, 0}, open[3] = {0, 0, 0};
  std::size_t bins[6] = {0, 0, 0, 0, 0, 0};  // tissue run lengths in 0.5 mm bins (debug output)
  void add(const InterfaceTally& t) {
    for (int a = 0; a < 3; ++a) columns[a] += t.columns[a], open[a] += t.open[a];
    for (int b = 0; b < 6; ++b) bins[b] += t.bins[b];
  }
};

class ColonSegmenter {
 public:
  ColonSegmenter(const CtImage* ct, const SegmentOptions& opts, std::function<void()> voxels_read = {});
  ~ColonSegmenter();
  MaskImage::Pointer run(SegmentStats* stats);

 private:
  // Steps (segment.cpp).
  void check_input();
  void gravity_from_metadata();
  void find_gas_bodies();
  // Rectal tube (segment_tube.cpp).
  std::vector<unsigned char> outside_gas(const RunLabels& gas_labels);
  std::vector<unsigned char> inferior_face_dropped(const RunLabels& gas_labels, const std::vector<unsigned char>& drop) const;
  void trim_rectal_tube(const std::vector<unsigned char>& face_dropped, unsigned char* gas);
  std::size_t track_tube(std::vector<std::pair<long, long>> channel, unsigned char* gas, double sum[3]);
  std::size_t slice_index(std::size_t s, long a, long b) const;
  std::vector<std::pair<long, long>> slice_component(std::size_t s, const std::vector<std::pair<long, long>>& seeds,
                                                     const unsigned char* gas, std::size_t limit) const;
  std::vector<std::pair<long, long>> gas_in_disc(std::size_t s, double ca, double cb, double r_px, const unsigned char* gas) const;
  void exclude_disc(std::size_t s, double ca, double cb, double r_px);
  double ring_mean_hu(std::size_t s, double ca, double cb, double r0_px, double r1_px) const;
  void crop_to_gas(const unsigned char* gas);
  void class_means();
  void refine_boundary();
  void add_dependent_films();
  void add_gas_fluid_interfaces();
  void fill_interface_line(const Bytes& lumen, std::size_t base, std::size_t stride, std::size_t len, int wvox, double h);
  void final_segments();
  MaskImage::Pointer paste() const;
  // Tagged fluid (segment_fluid.cpp).
  void find_fluid_bodies();
  void split_fluid_bodies(const Bytes& bright);  // segment_split.cpp
  void grow_pieces(const Bytes& bright, const ComponentOwners& owners, std::vector<std::size_t>& queue);
  std::vector<std::size_t> seed_cores(const RunLabels& cl);
  std::vector<float> core_levels(const RunLabels& cl) const;
  float mean3_at(std::size_t q) const;
  std::vector<std::vector<std::size_t>> other_level_cores(const Bytes& bright, const Bytes& core, const RunLabels& cl) const;
  std::vector<std::vector<std::size_t>> plateaus_beyond_bridge(const std::vector<std::size_t>& region, std::uint32_t p, double own,
                                                              const Bytes& core, Bytes& seen) const;
  void debug_other_level(const std::vector<std::size_t>& region, std::size_t plateau, float level) const;
  RunLabels candidate_bodies(const Bytes& candidate) const;
  std::vector<PiecePair> piece_pairs(const RunLabels& cl, const Bytes& candidate, std::vector<std::uint64_t>& units) const;
  void scan_contacts(int axis, Bytes* contact, bool layer);
  std::vector<std::array<std::size_t, 2>> level_contacts(int axis, std::size_t min_gas_voxels);
  void gravity_from_levels();
  void keep_level_pools();
  void debug_pieces(const std::vector<std::array<std::size_t, 2>>& lv, int side) const;
  void mark_layer();
  // Segments and fully tagged stretches (segment_link.cpp).
  void select_segments();
  void check_colon_found(const std::vector<double>& vols) const;
  std::vector<BodyStats> body_stats(const RunLabels& labels, const std::function<bool(std::size_t)>& gas) const;
  void mark_grid(const std::vector<std::pair<Run, std::uint32_t>>& runs, bool segment);
  void link_tagged_stretches();
  std::size_t link_pass(std::vector<unsigned char>& eligible, std::vector<std::string>& why, std::vector<double>& kept_gap);
  bool continues_colon(const Contact& c, std::string& why) const;
  bool judge_link(const Contact& c, const LocalShape& sg, const LocalShape& sf, std::string& why) const;
  void sample_candidates(const RunLabels& cl, const std::vector<BodyStats>& bodies);
  void log_link(const Contact& c, const LocalShape& sg, const LocalShape& sf, bool ok, const std::string& why) const;
  std::pair<std::size_t, std::size_t> facing_cells(const Contact& c, const LocalShape& sg, const LocalShape& sf) const;
  nlohmann::json gap_profile(const Contact& c) const;
  double fluid_hu_near(const LocalShape& s) const;
  bool end_is_free(std::uint32_t segment, const LocalShape& near) const;
  double gap_fat_mm(const Contact& c) const;
  void debug_link(const Contact& c, const LocalShape& sg, const LocalShape& sf) const;
  // Open interfaces (segment_open.cpp).
  double tissue_run_mm(std::size_t base, std::size_t stride, int a, int b, double h) const;
  std::map<std::pair<std::uint32_t, std::uint32_t>, InterfaceTally> gas_fluid_interfaces(const RunLookup& cand) const;
  bool one_lumen(const InterfaceTally& t) const;
  std::uint32_t colon_body_of(std::uint32_t owner) const;
  std::uint32_t meets_colon_gas(std::uint32_t l) const;
  std::uint32_t gas_meets_colon_fluid(std::uint32_t l) const;
  std::size_t join_open_bodies(std::vector<unsigned char>& eligible, std::vector<std::string>& why, std::vector<double>& kept_gap);
  void debug_interfaces(const std::vector<BodyStats>& bodies) const;
  void report_candidate(const BodyStats& b, double kept_gap, const std::string& why);
  // Helpers.
  std::array<double, 3> lps_of(const double crop_voxel[3]) const;
  void decide(const std::string& what, double ml, const double centroid_crop[3], bool kept, const std::string& reason);
  void lap(const char* name);
  void summarize_decisions();
  void release_ct_voxels();

  BlockReuse reuse_;  // first member: released after every buffer below is freed into it
  const CtImage* ct_;                  // the CT; from the crop on its geometry_ only (release_ct_voxels)
  std::function<void()> voxels_read_;  // segment_colon's voxels_read
  CtImage::Pointer geometry_;
  SegmentOptions opts_;
  SegmentStats st_;
  nlohmann::json timings_ = nlohmann::json::object();
  nlohmann::json cpu_timings_ = nlohmann::json::object();
  double cpu_start_ = 0, cpu_lap_ = 0;
  Stopwatch clock_, step_;
  Dims full_{}, d_{};
  double voxel_ml_ = 0;
  int grav_axis_ = 1, sup_axis_ = 2;
  int grav_sign_ = 1;  // +1: gravity towards increasing index along grav_axis_
  bool sup_pos_ = true;
  bool gravity_known_ = false;
  std::string gravity_source_;
  std::size_t blo_[3] = {0, 0, 0}, bhi_[3] = {0, 0, 0};
  HuCrop hu_;                          // CT in the crop (16 bits when the CT holds integers)
  std::vector<std::size_t> tube_;      // full volume: rectal tube channel and wall voxels (until the crop)
  Bytes lab_;                          // crop: 1 gas, 2 fluid (pool or kept stretch), 3 layer, 4 candidate, 5 rectal tube (never lumen)
  RawBuffer<std::uint32_t> fluid_label_;  // fluid pieces in the crop (split_fluid_bodies .. candidate_bodies; then released)
  std::uint32_t fluid_count_ = 0;
  std::vector<unsigned char> pool_;    // per fluid label: 1 = level pool
  RunLookup gas_lookup_;                 // crop gas components
  std::vector<std::size_t> gas_voxels_;  // per crop gas component: its voxels
  std::map<std::uint32_t, std::vector<std::size_t>> ends_;  // per linked body: the link-grid cells of the ends its links use
  std::map<std::pair<std::uint32_t, std::uint32_t>, InterfaceTally> interfaces_;  // (candidate, gas body) -> columns (linking)
  mutable nlohmann::json link_log_ = nlohmann::json::array();  // COLONFLAT_SEGMENT_LINKS
  std::vector<std::vector<std::array<double, 3>>> cand_samples_;
  std::vector<double> cand_ml_;  // per candidate: LPS of some of its voxels (link log)
  std::vector<std::uint32_t> kept_id_;     // per candidate: link-grid id of the colon body it belongs to (0: not kept)
  std::unique_ptr<LinkGrid> grid_;         // coarse cells of the linking step (select_segments .. link_tagged_stretches)
  Bytes state_;                        // crop: final 0/1 (after the graph cut)
  Bytes lumen0_;                       // crop: initial lumen
  std::vector<Decision> decisions_;
};

}  // namespace cf::segment_detail
