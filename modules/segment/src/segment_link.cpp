// Colon segments and fully tagged stretches: components of gas + pools + layer are colon segments
// when they hold enough gas; fluid bodies without gas above them (and fluid-dominated bodies with a
// little gas: small bowel) are kept only as fully tagged colon stretches: they continue the path of
// a colon segment from its end across a short gap (a collapsed or fluid-filled neck). The linking
// runs on the coarse cells of a LinkGrid (segment_linkgrid.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iomanip>
#include <map>
#include <numeric>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/params.h"
#include "segment_internal.h"
#include "segment_linkgrid.h"

namespace cf::segment_detail {
namespace {
constexpr unsigned char kGas = 1, kPool = 2, kLayer = 3, kCandidate = 4;
constexpr double kLinkCellMm = 2.5;     // coarse cell of the linking step
constexpr double kShapeRadiusMm = 75;   // path length inside a body over which its end is judged (fronts at 25, 50, 75 mm)
constexpr double kMinChord = 0.7;       // last front's distance from the contact / its path length
constexpr double kSameEndMm = 30;       // a used end within this path length of a new contact: the same end
constexpr double kMinCalibreRatio = 0.3; // cross-sections (front sizes) of the two bodies within this ratio
constexpr std::size_t kContactsPerPair = 3;
constexpr double kMinFluidSampleMl = 0.5;  // fluid near a contact measured from this much on
// Fat (adipose tissue, -190..-30 HU) along a gap: a collapsed neck of colon is its own wall pressed
// together (soft tissue, 20-60 HU, perhaps a thread of gas or fluid), never fat; a layer of at least
// kFatRunMm (and at least one voxel's diagonal, beyond the partial volume of a gas/tissue edge) means
// the two bodies are separate bowels with pericolic or mesenteric fat between them.
constexpr double kFatLowHu = -190, kFatHighHu = -30, kFatRunMm = 3;
constexpr double kContactSeparationMm = 20;
// A body across a gap from a colon end continues the colon only at the colon's calibre: the small
// bowel is at most about 3 cm wide (wider is obstruction), the distended colon at CT colonography at
// least about 4 cm, so a candidate whose diameter is under 3/4 of the colon end's is a small-bowel
// loop lying end-on against the colon, not the colon beyond a collapsed neck - unless it is itself of
// colon calibre (>= kColonMinDiameterMm: a poorly distended stretch beside a wide one). One-sided: a
// candidate wider than the colon end is never refused by it (docs/segment.md step 6). Both bodies'
// calibres are read beyond the cap (calibre_front).
constexpr double kMinDiameterRatio = 0.75;
constexpr double kColonMinDiameterMm = 40;
// How far a body narrows toward a contact: its nearest front's cross-section (cells) over its widest
// front's within the shape radius (1: full calibre up to the contact). At a collapsed neck the colon
// narrows into the neck from both sides (one tube, its wall folded in), so both bodies narrow alike.
// Cells of a body's widest front within the shape radius (0 without fronts).
std::size_t widest_front(const LocalShape& s) {
  std::size_t widest = 0;
  for (const Front& f : s.fronts) widest = std::max(widest, f.cells);
  return widest;
}
double narrowing(const LocalShape& s) {
  const std::size_t widest = widest_front(s);
  return widest ? double(s.fronts.front().cells) / double(widest) : 1.0;
}
// Cells of a body's calibre front near a contact: the wider of its fronts beyond the nearest (at 2/3
// and 3/3 of the shape radius, 50 and 75 mm), or its only front. The nearest front (25 mm) lies
// within a wide body's own radius of the contact, so it is a cap around the contact that reads the
// width there (a small-bowel loop's bulb pressed on a colon end, 45 mm, read as colon calibre);
// beyond the cap a front is the body's cross-section. The wider of the two, because the farther may
// be the body's tip (a stretch ending 75 mm from the contact).
std::size_t calibre_front(const LocalShape& s) {
  if (s.fronts.size() < 2) return widest_front(s);
  std::size_t widest = 0;
  for (std::size_t t = 1; t < s.fronts.size(); ++t) widest = std::max(widest, s.fronts[t].cells);
  return widest;
}
// Ratio of the candidate's equivalent diameter to the colon end's near a contact (> 1: the candidate
// is wider): each body's calibre front is its cross-section times the front's width, so the square
// root of the cell counts' ratio is the diameters'.
double diameter_ratio(const LocalShape& colon, const LocalShape& cand) {
  const std::size_t wg = calibre_front(colon), wf = calibre_front(cand);
  if (wg == 0 || wf == 0) return 0;
  return std::sqrt(double(wf) / double(wg));
}
bool colon_kind(unsigned char v) { return v == kGas || v == kPool || v == kLayer; }
std::string fixed1(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << v;
  return s.str();
}
}  // namespace

ColonSegmenter::ColonSegmenter(const CtImage* ct, const SegmentOptions& opts, std::function<void()> voxels_read)
    : ct_(ct), voxels_read_(std::move(voxels_read)), opts_(opts) {}
ColonSegmenter::~ColonSegmenter() = default;

// Components of gas + pools + layer, largest first: kept while they hold >= min-segment-volume of
// gas, reach min-segment-fraction of the largest and max-segments is not reached. Rejected bodies
// with enough fluid become candidates for fully tagged stretches (lab 4). Kept segments are marked
// on the link grid.
void ColonSegmenter::select_segments() {
  Bytes colon(d_.total);
  for_each_voxel(d_.total, [&](std::size_t q) { colon[q] = colon_kind(lab_[q]); });
  const RunLabels cl = component_runs(colon.data(), d_);
  Bytes().swap(colon);
  const std::uint32_t n = cl.count();
  const std::vector<BodyStats> bodies = body_stats(cl, [&](std::size_t q) { return lab_[q] == kGas; });
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 1u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return bodies[a].voxels > bodies[b].voxels; });
  std::vector<unsigned char> fate(n + 1, 0);  // 1 kept, 2 candidate, 0 rejected
  std::vector<double> vols;
  for (std::uint32_t l : order) {
    const BodyStats& b = bodies[l];
    const double ml = double(b.voxels) * voxel_ml_, gas_ml = double(b.gas) * voxel_ml_;
    const double c[3] = {b.sum[0] / double(b.voxels), b.sum[1] / double(b.voxels), b.sum[2] / double(b.voxels)};
    std::string reason;
    if (gas_ml < opts_.min_segment_volume) reason = "less gas than --min-segment-volume";
    else if (int(vols.size()) >= opts_.max_segments) reason = "more segments than --max-segments";
    else if (!vols.empty() && ml < opts_.min_segment_fraction * vols.front()) reason = "below --min-segment-fraction of the largest";
    if (reason.empty()) {
      fate[l] = 1;
      vols.push_back(ml);
      decide("segment", ml, c, true, "colon segment (" + fixed1(gas_ml) + " mL gas)");
    } else if (ml - gas_ml >= opts_.min_tagged_volume || gas_ml >= opts_.min_segment_volume) {
      fate[l] = 2;  // decided with the fully tagged candidates: kept if it continues the colon
    } else {
      ++st_.removed_components;
      decide(b.gas == b.voxels ? "gas body" : "segment", ml, c, false, reason);
    }
  }
  grid_ = std::make_unique<LinkGrid>(d_, kLinkCellMm);
  std::vector<unsigned char> kept(n + 1, 0);
  for (std::uint32_t l = 1; l <= n; ++l) {
    kept[l] = fate[l] == 1;
    if (!kept[l])
      for (const Run* r = cl.begin(l); r != cl.end(l); ++r) std::fill_n(lab_.data() + r->start, r->length, fate[l] == 2 ? kCandidate : 0);
  }
  mark_grid(cl.raster(kept), true);
  check_colon_found(vols);
}

void ColonSegmenter::check_colon_found(const std::vector<double>& vols) const {
  if (vols.empty())
    throw PreconditionError("no colon found: no gas/fluid body inside the body of at least " +
                            format_number(opts_.min_segment_volume) + " mL");
  const double total = std::accumulate(vols.begin(), vols.end(), 0.0);
  if (total < opts_.min_colon_volume)
    throw PreconditionError("no colon found: the gas/fluid bodies inside the body total " + fixed1(total) +
                            " mL, less than --min-colon-volume " + format_number(opts_.min_colon_volume) +
                            " mL (an insufflated colon holds several hundred mL)");
}

// Per-label voxel count, `gas` count, coordinate sums and whether the body touches the crop's faces.
std::vector<BodyStats> ColonSegmenter::body_stats(const RunLabels& labels, const std::function<bool(std::size_t)>& gas) const {
  std::vector<BodyStats> bodies(labels.count() + 1);
  for (std::uint32_t l = 1; l <= labels.count(); ++l) {
    BodyStats& b = bodies[l];
    for (const Run* r = labels.begin(l); r != labels.end(l); ++r) {
      std::size_t i, j, k;
      d_.coords(r->start, i, j, k);
      const double len = double(r->length);
      b.voxels += r->length;
      for (std::size_t q = r->start; q < r->start + r->length; ++q) b.gas += gas(q);
      b.sum[0] += len * double(i) + len * (len - 1) / 2, b.sum[1] += len * double(j), b.sum[2] += len * double(k);
      const bool face_row = j == 0 || k == 0 || j + 1 == d_.n[1] || k + 1 == d_.n[2];
      b.touches_face = b.touches_face || face_row || i == 0 || i + r->length == d_.n[0];
    }
  }
  return bodies;
}

// Marks the link grid with the voxels of `runs` (raster order: where bodies share a cell, the
// last voxel in raster order names it), as segment (`segment`) or candidate ids.
void ColonSegmenter::mark_grid(const std::vector<std::pair<Run, std::uint32_t>>& runs, bool segment) {
  for (const auto& [run, label] : runs) {
    std::size_t i, j, k;
    d_.coords(run.start, i, j, k);
    for (std::size_t t = 0; t < run.length; ++t) grid_->mark(i + t, j, k, segment ? label : 0, segment ? 0 : label);
  }
}

// Candidates (lab 4): kept when they continue a colon segment's end within link-gap, in passes (a
// body kept in one pass is colon for the next: chains of stretches and small gas pieces between
// them); then every other candidate is rejected with its reason.
void ColonSegmenter::link_tagged_stretches() {
  Bytes candidate(d_.total);
  for_each_voxel(d_.total, [&](std::size_t q) { candidate[q] = lab_[q] == kCandidate; });
  const RunLabels cl = candidate_bodies(candidate);
  step_time("candidate_bodies");
  Bytes().swap(candidate);
  RawBuffer<std::uint32_t>().swap(fluid_label_);  // the pieces' last use: the graph cut reuses these pages
  const std::uint32_t n = cl.count();
  const std::vector<BodyStats> bodies = body_stats(cl, [&](std::size_t q) { return hu_[q] < opts_.air_threshold; });
  mark_grid(cl.raster(std::vector<unsigned char>(n + 1, 1)), false);
  std::vector<unsigned char> eligible(n + 1, 0);
  std::vector<std::string> why(n + 1);
  for (std::uint32_t l = 1; l <= n; ++l) {
    if (double(bodies[l].voxels) * voxel_ml_ < opts_.min_tagged_volume) why[l] = "smaller than --min-tagged-volume";
    else if (bodies[l].touches_face) why[l] = "reaches beyond the colon's region (bone, vessel, bladder)";
    else eligible[l] = 1, why[l] = "no colon segment end within --link-gap";
  }
  if (std::getenv("COLONFLAT_SEGMENT_LINKS")) sample_candidates(cl, bodies);
  step_time("candidate stats");
  interfaces_ = gas_fluid_interfaces(RunLookup(cl));
  step_time("gas_fluid_interfaces");
  if (std::getenv("COLONFLAT_SEGMENT_DEBUG")) debug_interfaces(bodies);
  std::vector<double> kept_gap(n + 1, -1);
  kept_id_.assign(n + 1, 0);
  ends_.clear();
  for (int pass = 0; pass < 7; ++pass)
    if (link_pass(eligible, why, kept_gap) == 0) break;
  std::vector<unsigned char> keep(n + 1, 0);
  for (std::uint32_t l = 1; l <= n; ++l) {
    keep[l] = kept_gap[l] >= 0;
    if (std::getenv("COLONFLAT_SEGMENT_DEBUG") && bodies[l].voxels * voxel_ml_ > 3) {
      const double c[3] = {bodies[l].sum[0] / double(bodies[l].voxels), bodies[l].sum[1] / double(bodies[l].voxels), bodies[l].sum[2] / double(bodies[l].voxels)};
      const auto p = lps_of(c);
      std::fprintf(stderr, "cand %u %.1f mL at LPS (%.0f %.0f %.0f) %s %s\n", l, bodies[l].voxels * voxel_ml_, p[0], p[1], p[2], keep[l] ? "KEPT" : "rejected", why[l].c_str());
    }
    report_candidate(bodies[l], kept_gap[l], why[l]);
  }
  interfaces_.clear();
  for (std::uint32_t l = 1; l <= n; ++l)
    for (const Run* r = cl.begin(l); r != cl.end(l); ++r)
      for (std::size_t q = r->start; q < r->start + r->length; ++q) lab_[q] = keep[l] ? (hu_[q] < opts_.air_threshold ? kGas : kPool) : 0;
  grid_.reset();
}

// Per candidate its volume and the LPS of up to about 24 of its voxels (run middles), for the link log.
void ColonSegmenter::sample_candidates(const RunLabels& cl, const std::vector<BodyStats>& bodies) {
  const std::uint32_t n = cl.count();
  cand_samples_.assign(n + 1, {});
  cand_ml_.assign(n + 1, 0);
  for (std::uint32_t l = 1; l <= n; ++l) {
    cand_ml_[l] = double(bodies[l].voxels) * voxel_ml_;
    const std::size_t runs = std::size_t(cl.end(l) - cl.begin(l)), step = std::max<std::size_t>(1, runs / 24);
    for (const Run* r = cl.begin(l); r < cl.end(l); r += step) {
      std::size_t i, j, k;
      d_.coords(r->start + r->length / 2, i, j, k);
      const double v[3] = {double(i), double(j), double(k)};
      cand_samples_[l].push_back(lps_of(v));
    }
  }
}

// One pass over the contacts, nearest first: a candidate whose contact passes continues_colon at a
// free end of the segment is kept and becomes colon. Returns the number kept.
std::size_t ColonSegmenter::link_pass(std::vector<unsigned char>& eligible, std::vector<std::string>& why,
                                      std::vector<double>& kept_gap) {
  std::size_t kept = join_open_bodies(eligible, why, kept_gap);  // one lumen with a colon body: joins it, uses no end
  std::vector<Contact> contacts = grid_->contacts(eligible, opts_.link_gap, kContactsPerPair, kContactSeparationMm);
  std::stable_sort(contacts.begin(), contacts.end(), [](const Contact& a, const Contact& b) { return a.gap_mm < b.gap_mm; });
  std::vector<unsigned char> tried(eligible.size(), 0);
  for (const Contact& c : contacts) {
    const std::uint32_t l = c.candidate;
    if (!eligible[l]) continue;  // kept earlier in this pass
    std::string reason;
    if (continues_colon(c, reason)) {
      kept_gap[l] = c.gap_mm;
      eligible[l] = 0;
      const std::uint32_t id = kKeptCandidateId + l;
      kept_id_[l] = id;
      grid_->absorb(l, id);
      ends_[c.segment].push_back(c.to);
      ends_[id].push_back(c.from);
      for (const Contact& t : contacts)  // where it touches other colon bodies (gap 0) those ends continue each other
        if (t.candidate == l && t.gap_mm <= 0 && t.segment != c.segment) ends_[t.segment].push_back(t.to), ends_[id].push_back(t.from);
      ++kept;
      continue;
    }
    if (!tried[l]) why[l] = reason, tried[l] = 1;  // the nearest contact's reason is reported
  }
  return kept + join_open_bodies(eligible, why, kept_gap);
}

// A body continues at most two others (a tube has two ends), and not twice at the same end: no
// end already used lies within kSameEndMm of path from the new contact (`near`).
bool ColonSegmenter::end_is_free(std::uint32_t segment, const LocalShape& near) const {
  auto it = ends_.find(segment);
  if (it == ends_.end()) return true;
  if (it->second.size() >= 2) return false;
  for (std::size_t cell : it->second)
    if (near.within(cell, kSameEndMm)) return false;
  return true;
}

// The candidate continues the colon at this contact: seen along paths inside each body, both end
// there (no front splits into two pieces, as it does on a tube's side, and the farthest front lies a
// chord of at least 0.7 of its path length away: the body runs away from the contact), they point
// the same way, their cross-sections (front sizes at the same path length) agree within a factor
// of 1 / kMinCalibreRatio, and, across a gap, the candidate lies beyond the segment's end, not beside
// it. Bodies touching in one cell (gap 0) are one lumen where gas gives way to fluid, and a colon
// may turn at any angle there (the flexures and the sigmoid turn 90-180 degrees): no direction test.
bool ColonSegmenter::continues_colon(const Contact& c, std::string& why) const {
  const LocalShape sg = grid_->segment_shape(c.segment, c.to, kShapeRadiusMm);
  const LocalShape sf = grid_->candidate_shape(c.candidate, c.from, kShapeRadiusMm);
  if (std::getenv("COLONFLAT_SEGMENT_DEBUG")) debug_link(c, sg, sf);
  const bool ok = judge_link(c, sg, sf, why);
  if (std::getenv("COLONFLAT_SEGMENT_LINKS")) log_link(c, sg, sf, ok, ok ? std::string("linked") : why);
  return ok;
}

bool ColonSegmenter::judge_link(const Contact& c, const LocalShape& sg, const LocalShape& sf, std::string& why) const {
  const Eigen::Vector3d link = grid_->mm(c.from) - grid_->mm(c.to);
  if (sg.fronts.empty() || sf.fronts.empty()) return why = "too small near the link", false;
  for (const Front& f : sg.fronts)
    if (f.pieces >= 2) return why = "lies beside a colon segment, not at its end", false;
  for (const Front& f : sf.fronts)
    if (f.pieces >= 2) return why = "meets the colon with its side (not tube-shaped there)", false;
  const Front &fg = sg.fronts.front(), &ff = sf.fronts.front();
  const Front &lg = sg.fronts.back(), &lf = sf.fronts.back();
  if (lg.centroid.norm() < kMinChord * lg.radius_mm) return why = "touches the colon's side, not an end", false;
  if (lf.centroid.norm() < kMinChord * lf.radius_mm) return why = "meets the colon with its side (not tube-shaped there)", false;
  const std::size_t common = std::min(sg.fronts.size(), sf.fronts.size()) - 1;  // the farthest front both reach
  const double cg = double(sg.fronts[common].cells), cf = double(sf.fronts[common].cells);
  if (std::min(cg, cf) < kMinCalibreRatio * std::max(cg, cf)) return why = "not at the colon's calibre there", false;
  if (!end_is_free(c.segment, sg)) return why = "the colon end it meets already continues into another body", false;
  if (c.gap_mm <= 0) return true;  // touching in one cell: one lumen, which may turn at any angle there
  const double diagonal = std::sqrt(d_.sp[0] * d_.sp[0] + d_.sp[1] * d_.sp[1] + d_.sp[2] * d_.sp[2]);
  if (gap_fat_mm(c) >= std::max(kFatRunMm, diagonal)) return why = "separated from the colon by fat (not a collapsed neck)", false;
  if (diameter_ratio(sg, sf) < kMinDiameterRatio && grid_->front_diameter_mm(calibre_front(sf)) < kColonMinDiameterMm)
    return why = "narrower than the colon end across the gap (a small-bowel loop, not the colon)", false;
  const double ng = narrowing(sg), nf = narrowing(sf);
  if (std::min(ng, nf) < kMinCalibreRatio * std::max(ng, nf)) return why = "a blunt end beside a tapering colon end (not a collapsed neck)", false;
  const Eigen::Vector3d ug = -fg.centroid.normalized(), uf = ff.centroid.normalized();  // out of the colon; into the candidate
  if (ug.dot(uf) < 0.3) return why = "does not continue the colon's direction", false;
  const double cell = std::max({grid_->dims().sp[0], grid_->dims().sp[1], grid_->dims().sp[2]});
  if (link.norm() > 1.5 * cell && ug.dot(link.normalized()) < 0.3) return why = "does not continue the colon's direction", false;
  return true;
}

// Longest run (mm) of fat on the straight line between the contact's two cells (cell centres),
// each sample the mean of its voxel and 6 face neighbours (a single noisy voxel is not fat).
double ColonSegmenter::gap_fat_mm(const Contact& c) const {
  const Eigen::Vector3d a = grid_->fine_centre(c.to), b = grid_->fine_centre(c.from);
  const Eigen::Vector3d sp(d_.sp[0], d_.sp[1], d_.sp[2]);
  const double len = (b - a).cwiseProduct(sp).norm();
  const int n = int(std::ceil(len / (0.25 * sp.minCoeff())));
  double run = 0, best = 0;
  for (int t = 0; t <= n && n > 0; ++t) {
    const Eigen::Vector3d p = a + (b - a) * (double(t) / n);
    long x[3];
    for (int k = 0; k < 3; ++k) x[k] = std::clamp(std::lround(p[k]), 0L, long(d_.n[k]) - 1);
    static constexpr int kSeven[7][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
    double sum = 0;
    int cnt = 0;
    for (const auto& o : kSeven) {
      const long y[3] = {x[0] + o[0], x[1] + o[1], x[2] + o[2]};
      if (y[0] < 0 || y[1] < 0 || y[2] < 0 || y[0] >= long(d_.n[0]) || y[1] >= long(d_.n[1]) || y[2] >= long(d_.n[2])) continue;
      sum += hu_[d_.idx(std::size_t(y[0]), std::size_t(y[1]), std::size_t(y[2]))], ++cnt;
    }
    const double v = sum / cnt;
    run = v >= kFatLowHu && v <= kFatHighHu ? run + len / n : 0;
    best = std::max(best, run);
  }
  return best;
}

// Each body's cells (its shape region near the contact) within gap + one cell of the other body's
// (link log): a neck meets tip to tip, a loop lying along an end cap faces it over a larger area.
std::pair<std::size_t, std::size_t> ColonSegmenter::facing_cells(const Contact& c, const LocalShape& sg, const LocalShape& sf) const {
  const double cell = std::max({grid_->dims().sp[0], grid_->dims().sp[1], grid_->dims().sp[2]});
  const double reach = c.gap_mm + cell + 1e-6;
  const Eigen::Vector3d a = grid_->mm(c.to), b = grid_->mm(c.from);
  std::vector<Eigen::Vector3d> ps, pf;
  for (const auto& e : sg.region)
    if ((grid_->mm(e.first) - a).norm() <= reach + 25) ps.push_back(grid_->mm(e.first));
  for (const auto& e : sf.region)
    if ((grid_->mm(e.first) - b).norm() <= reach + 25) pf.push_back(grid_->mm(e.first));
  auto facing = [&](const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y) {
    std::size_t n = 0;
    for (const auto& p : x)
      n += std::any_of(y.begin(), y.end(), [&](const Eigen::Vector3d& q) { return (p - q).norm() <= reach; });
    return n;
  };
  return {facing(ps, pf), facing(pf, ps)};
}

// Median HU of the tagged fluid (own value in [fluid-threshold, fluid-max)) in the fine voxels of the
// cells of `s` (a body's region near a contact); NaN when it holds fewer than kMinFluidSampleMl.
double ColonSegmenter::fluid_hu_near(const LocalShape& s) const {
  std::vector<float> v;
  for (const auto& cell : s.region) {
    std::size_t lo[3], hi[3];
    grid_->fine_box(cell.first, d_, lo, hi);
    for (std::size_t k = lo[2]; k < hi[2]; ++k)
      for (std::size_t j = lo[1]; j < hi[1]; ++j)
        for (std::size_t i = lo[0]; i < hi[0]; ++i) {
          const float h = hu_[d_.idx(i, j, k)];
          if (h >= opts_.fluid_threshold && h < opts_.fluid_max) v.push_back(h);
        }
  }
  if (double(v.size()) * voxel_ml_ < kMinFluidSampleMl) return std::nan("");
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// HU (nearest voxel) at 25 points on the straight line between the contact's two cell centres (link log).
nlohmann::json ColonSegmenter::gap_profile(const Contact& c) const {
  const Eigen::Vector3d fa = grid_->fine_centre(c.to), fb = grid_->fine_centre(c.from);
  nlohmann::json prof = nlohmann::json::array();
  for (int t = 0; t <= 24; ++t) {
    const Eigen::Vector3d p = fa + (fb - fa) * (double(t) / 24);
    long x[3];
    for (int k = 0; k < 3; ++k) x[k] = std::clamp(std::lround(p[k]), 0L, long(d_.n[k]) - 1);
    prof.push_back(std::lround(hu_[d_.idx(std::size_t(x[0]), std::size_t(x[1]), std::size_t(x[2]))]));
  }
  return prof;
}

// The link log (COLONFLAT_SEGMENT_LINKS=1, stats.links): every judged contact with the measures
// considered for telling a collapsed neck from a loop pressed on a colon end (issue 25, session 14).
void ColonSegmenter::log_link(const Contact& c, const LocalShape& sg, const LocalShape& sf, bool ok, const std::string& why) const {
  nlohmann::json j;
  j["candidate"] = c.candidate;
  j["segment"] = c.segment;
  j["segment_is_candidate"] = c.segment >= kKeptCandidateId;
  j["gap_mm"] = c.gap_mm;
  j["ok"] = ok;
  j["why"] = why;
  j["fat_mm"] = gap_fat_mm(c);
  auto fronts = [](const LocalShape& s) {
    nlohmann::json a = nlohmann::json::array();
    for (const Front& f : s.fronts) a.push_back({f.cells, f.pieces, f.centroid.norm() / f.radius_mm});
    return a;
  };
  j["seg_fronts"] = fronts(sg);
  j["cand_fronts"] = fronts(sf);
  const Eigen::Vector3d a = grid_->mm(c.to), b = grid_->mm(c.from);
  const double pa[3] = {grid_->fine_centre(c.to)[0], grid_->fine_centre(c.to)[1], grid_->fine_centre(c.to)[2]};
  const double pb[3] = {grid_->fine_centre(c.from)[0], grid_->fine_centre(c.from)[1], grid_->fine_centre(c.from)[2]};
  j["seg_lps"] = lps_of(pa);
  j["cand_lps"] = lps_of(pb);
  if (!sg.fronts.empty() && !sf.fronts.empty()) {
    const Eigen::Vector3d ug = -sg.fronts[0].centroid.normalized(), uf = sf.fronts[0].centroid.normalized();
    j["dir"] = ug.dot(uf);
    j["diameter_ratio"] = diameter_ratio(sg, sf);
    j["seg_diameter_mm"] = grid_->front_diameter_mm(calibre_front(sg));
    j["cand_diameter_mm"] = grid_->front_diameter_mm(calibre_front(sf));
    if ((b - a).norm() > 0) j["seg_axis_link"] = ug.dot((b - a).normalized()), j["cand_axis_link"] = uf.dot((b - a).normalized());
  }
  const auto [facing_seg, facing_cand] = facing_cells(c, sg, sf);
  j["facing_seg"] = facing_seg;
  j["facing_cand"] = facing_cand;
  j["profile"] = gap_profile(c);
  const double hu_seg = fluid_hu_near(sg), hu_cand = fluid_hu_near(sf);  // NaN: no fluid near (null)
  j["seg_fluid_hu"] = std::isnan(hu_seg) ? nlohmann::json() : nlohmann::json(hu_seg);
  j["cand_fluid_hu"] = std::isnan(hu_cand) ? nlohmann::json() : nlohmann::json(hu_cand);
  if (c.candidate < cand_ml_.size()) j["cand_ml"] = cand_ml_[c.candidate];
  if (c.candidate < cand_samples_.size()) j["cand_samples"] = cand_samples_[c.candidate];
  if (c.segment >= kKeptCandidateId && c.segment - kKeptCandidateId < cand_samples_.size())
    j["seg_samples"] = cand_samples_[c.segment - kKeptCandidateId];
  link_log_.push_back(j);
}

void ColonSegmenter::debug_link(const Contact& c, const LocalShape& sg, const LocalShape& sf) const {
  const Eigen::Vector3d a = grid_->mm(c.to);
  std::fprintf(stderr, "link cand %u seg %x at (%.0f %.0f %.0f) gap %.1f fat %.1f |", c.candidate, c.segment, a[0], a[1], a[2], c.gap_mm, gap_fat_mm(c));
  for (const LocalShape* s : {&sg, &sf}) {
    std::fprintf(stderr, " reach %.0f:", s->reach_mm);
    for (const Front& f : s->fronts)
      std::fprintf(stderr, " r%.0f n%zu p%d chord %.2f", f.radius_mm, f.cells, f.pieces, f.centroid.norm() / f.radius_mm);
    std::fprintf(stderr, " |");
  }
  if (!sg.fronts.empty() && !sf.fronts.empty())
    std::fprintf(stderr, " dir %.2f", -sg.fronts[0].centroid.normalized().dot(sf.fronts[0].centroid.normalized()));
  std::fprintf(stderr, " fluid HU %.0f / %.0f\n", fluid_hu_near(sg), fluid_hu_near(sf));
}

void ColonSegmenter::report_candidate(const BodyStats& b, double kept_gap, const std::string& why) {
  const double ml = double(b.voxels) * voxel_ml_;
  const double c[3] = {b.sum[0] / double(b.voxels), b.sum[1] / double(b.voxels), b.sum[2] / double(b.voxels)};
  const std::string what = 2 * b.gas > b.voxels ? "gas body" : (b.gas > 0 ? "fluid body with gas" : "fluid body");
  if (kept_gap < 0) {
    ++st_.rejected_fluid_components;
    return decide(what, ml, c, false, why);
  }
  if (what != "gas body") ++st_.tagged_stretches, st_.tagged_stretch_volume_ml += ml;
  if (why == kOpenFluidReason || why == kOpenGasReason) return decide(what, ml, c, true, why);
  decide(what, ml, c, true,
         (what == "gas body" ? "colon segment continuing a segment's end (gap " : "fully tagged colon stretch continuing a segment's end (gap ") +
             fixed1(kept_gap) + " mm)");
}

}  // namespace cf::segment_detail
