#include "colonflat/register/pieces.h"

#include "branch_order.h"
#include "piece_split.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <tuple>

namespace cf {

double ColonPiece::s_of(double local_mm) const {
  double inserted = 0;  // branches inserted at necks before this point (reference bands)
  for (const auto& [neck, len] : inserts)
    if (neck < local_mm) inserted += len;
  const double linear = flipped ? start_mm + length_mm - local_mm : start_mm + local_mm + inserted;
  if (s_bin.empty()) return linear;
  const double x = local_mm / bin_mm - 0.5;  // bin k's centre is at (k + 0.5) bins
  const int n = int(s_bin.size());
  const double dir = flipped ? -1.0 : 1.0;
  if (x <= 0) return s_bin.front() + dir * x * bin_mm;  // beyond the last bin: the piece's own mm
  if (x >= n - 1) return s_bin.back() + dir * (x - (n - 1)) * bin_mm;
  const int k = int(x);
  return s_bin[size_t(k)] + (s_bin[size_t(k) + 1] - s_bin[size_t(k)]) * (x - k);
}

double ColonPiece::span_mm() const {
  double span = length_mm;
  for (const auto& ins : inserts) span += ins.second;
  return span;
}

void ColonPiece::move_by(double mm) {
  start_mm += mm;
  for (double& s : s_bin) s += mm;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + long(m), v.end());
  return v[m];
}

// Centroid of the piece's vertices per bin of their own centreline mm; empty bins interpolated.
std::vector<Eigen::Vector3d> piece_centre(const ColonScan& scan, int seg, double length, double bin) {
  const int bins = std::max(1, int(std::ceil(length / bin)));
  std::vector<Eigen::Vector3d> sum(size_t(bins), Eigen::Vector3d::Zero());
  std::vector<int> n(size_t(bins), 0);
  for (size_t v = 0; v < scan.lps.size(); ++v) {
    const double c = scan.centreline_mm[v];
    if (scan.segment[v] != seg || !std::isfinite(c) || c < 0) continue;
    const int k = std::clamp(int(c / bin), 0, bins - 1);
    sum[size_t(k)] += scan.lps[v], ++n[size_t(k)];
  }
  int last = -1;
  for (int k = 0; k < bins; ++k) {
    if (n[size_t(k)] == 0) continue;
    sum[size_t(k)] /= n[size_t(k)];
    for (int j = last + 1; j < k; ++j)  // fill the empty bins before k
      sum[size_t(j)] = last < 0 ? sum[size_t(k)] : sum[size_t(last)] + (sum[size_t(k)] - sum[size_t(last)]) * double(j - last) / double(k - last);
    last = k;
  }
  for (int j = last + 1; j < bins && last >= 0; ++j) sum[size_t(j)] = sum[size_t(last)];
  return sum;
}

// A reference branch piece starts at its neck's s on its band, after the branches inserted at the
// band's earlier necks (at one neck: in the order of branch_order.h); without its band it is unregistered.
void seat_branches(std::vector<ColonPiece>& ref) {
  for (auto& b : ref) {
    if (!b.branch) continue;
    b.registered = false;
    for (const auto& band : ref) {
      if (band.branch || band.segment != b.parent) continue;
      const double neck = std::min(b.attach_mm, band.length_mm);
      double before = 0;
      for (const auto& o : ref)
        if (o.branch && o.parent == b.parent && o.segment != b.segment &&
            std::make_tuple(std::min(o.attach_mm, band.length_mm), o.neck_rank, o.segment) < std::make_tuple(neck, b.neck_rank, b.segment))
          before += o.length_mm;
      b.start_mm = band.start_mm + neck + before, b.registered = true;
    }
  }
}

// Reference pieces: the bands in their order, each with its long branches inserted at their necks,
// each gap the straight line between the ends it joins; then the branches seated at their necks.
void chain(std::vector<ColonPiece>& ref) {
  for (auto& band : ref) {
    band.inserts.clear();
    if (band.branch) continue;
    for (const auto& b : ref)
      if (b.branch && b.parent == band.segment) band.inserts.push_back({std::min(b.attach_mm, band.length_mm), b.length_mm});
    std::sort(band.inserts.begin(), band.inserts.end());
  }
  double at = 0;
  const ColonPiece* prev = nullptr;
  for (auto& p : ref) {
    if (p.branch) continue;
    if (prev) at += (p.centre.front() - prev->centre.back()).norm();
    p.start_mm = at, p.flipped = false;
    at += p.span_mm();
    prev = &p;
  }
  seat_branches(ref);
}

struct RefPoint {
  Eigen::Vector3d p;
  double s;
  int piece;            // index of the reference piece
  bool branch = false;  // a centre point of one of its side branches (s = the neck's)
};

// Centre points of a piece that project onto the reference: own mm, reference s, reference piece.
struct Projection {
  std::vector<double> local, sref;
  std::vector<int> ref_piece;
};

// Side-branch band -> (colon band, mm on it where the branch's neck is); a branch of a branch
// resolves to its ancestor's neck, or to its parent's when that is one of `pieces`.
std::map<int, std::pair<int, double>> branch_necks(const ColonScan& scan, const std::set<int>& pieces = {}) {
  std::map<int, std::pair<int, double>> neck;
  for (const auto& seg : scan.segments) {
    if (!is_branch_entry(seg)) continue;
    int parent = seg.value("parent", -1);
    double attach = seg.value("attach_mm", 0.0);
    for (int guard = 0; guard < 16 && is_branch(scan, parent) && !pieces.count(parent); ++guard) {
      const auto* e = segment_entry(scan, parent);
      attach = e->value("attach_mm", 0.0), parent = e->value("parent", -1);
    }
    neck[seg.value("id", -1)] = {parent, attach};
  }
  return neck;
}

// A side-branch band's centre line and where it hangs on the colon.
struct BranchLine {
  int parent = -1;
  double attach_mm = 0;
  std::vector<Eigen::Vector3d> centre;
};

// The short side branches (not pieces) of a scan whose pieces are `pieces`.
std::vector<BranchLine> branch_lines(const ColonScan& scan, const std::vector<ColonPiece>& pieces, double bin) {
  std::set<int> ids;
  for (const auto& p : pieces) ids.insert(p.segment);
  std::map<int, double> length;
  for (size_t v = 0; v < scan.lps.size(); ++v)
    if (const double c = scan.centreline_mm[v]; std::isfinite(c) && c >= 0 && is_branch(scan, scan.segment[v]))
      length[scan.segment[v]] = std::max(length[scan.segment[v]], c);
  std::vector<BranchLine> out;
  for (const auto& [seg, neck] : branch_necks(scan, ids))
    if (const auto it = length.find(seg); it != length.end() && !ids.count(seg))
      out.push_back({neck.first, neck.second, piece_centre(scan, seg, std::max(it->second, bin), bin)});
  return out;
}

// The reference's centre points with their common s: its colon pieces', and its side branches' at
// their neck (where the registration puts the branch's vertices, common_s).
std::vector<RefPoint> ref_points(const std::vector<ColonPiece>& ref, const std::vector<BranchLine>& branches, double bin) {
  std::vector<RefPoint> pts;
  for (size_t i = 0; i < ref.size(); ++i)
    for (size_t k = 0; k < ref[i].centre.size(); ++k)
      pts.push_back({ref[i].centre[k], ref[i].s_of((double(k) + 0.5) * bin), int(i)});
  for (const auto& b : branches)
    for (size_t i = 0; i < ref.size(); ++i) {
      if (ref[i].segment != b.parent) continue;
      const double s = ref[i].s_of(std::min(b.attach_mm, ref[i].length_mm));
      for (const auto& c : b.centre) pts.push_back({c, s, int(i), true});
    }
  return pts;
}

// Common s per centre bin of a placed piece: running median (+-`follow_mm`) of its projections' offsets (sref - own
// mm; flipped: + own mm), their largest forward run kept, linear between, own mm beyond; then monotone along it.
std::vector<double> follow_projections(const ColonPiece& piece, const std::vector<double>& local,
                                       const std::vector<double>& sref, const PieceOptions& o) {
  const int n = int(piece.centre.size());
  const double dir = piece.flipped ? -1.0 : 1.0;
  std::vector<double> offset(size_t(n), kNaN);
  std::vector<int> bin(local.size());
  for (size_t i = 0; i < local.size(); ++i) bin[i] = std::clamp(int(local[i] / o.bin_mm), 0, n - 1);
  const int half = std::max(0, int(std::lround(o.follow_mm / o.bin_mm)));
  for (size_t i = 0; i < local.size(); ++i) {
    std::vector<double> near, before, after;
    for (size_t j = 0; j < local.size(); ++j) {
      if (std::abs(bin[j] - bin[i]) > half) continue;
      const double v = sref[j] - dir * local[j];
      near.push_back(v);
      if (bin[j] <= bin[i]) before.push_back(v);
      if (bin[j] >= bin[i]) after.push_back(v);
    }
    // A jump (a stretch inserted in one scan's course, skipped in the other's): keep the side of it
    // this bin's own projection lies on instead of ramping across it (each side a median of at least
    // half a half window: near a piece's end the short side is a few noisy projections).
    const double b = median(before), a = median(after), own = sref[i] - dir * local[i];
    const bool sides = 2 * std::min(before.size(), after.size()) >= size_t(half);
    offset[size_t(bin[i])] = sides && std::abs(b - a) > o.jump_mm ? (std::abs(b - own) <= std::abs(a - own) ? b : a) : median(near);
  }
  keep_forward_run(offset, piece.flipped, o.bin_mm);
  int last = -1;
  for (int k = 0; k < n; ++k) {
    if (std::isnan(offset[size_t(k)])) continue;
    for (int j = last + 1; j < k; ++j)  // before the first projecting bin: its offset; between: linear
      offset[size_t(j)] = last < 0 ? offset[size_t(k)] : offset[size_t(last)] + (offset[size_t(k)] - offset[size_t(last)]) * double(j - last) / double(k - last);
    last = k;
  }
  for (int j = last + 1; j < n; ++j) offset[size_t(j)] = offset[size_t(last)];
  std::vector<double> s(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) s[size_t(k)] = offset[size_t(k)] + dir * (double(k) + 0.5) * o.bin_mm;
  for (int k = 1; k < n; ++k)  // a colon does not run back along itself
    s[size_t(k)] = piece.flipped ? std::min(s[size_t(k)], s[size_t(k) - 1]) : std::max(s[size_t(k)], s[size_t(k) - 1]);
  return s;
}

// Places `piece` on the reference axis from the projections of its (shifted) centre points.
Projection place(ColonPiece& piece, const std::vector<RefPoint>& ref, const Eigen::Vector3d& shift, double bin,
                 const PieceOptions& o) {
  Projection pr;
  piece.s_bin.clear();
  piece.on_branch.assign(piece.centre.size(), 0);
  std::vector<double>& local = pr.local;
  std::vector<double>& sref = pr.sref;
  for (size_t k = 0; k < piece.centre.size(); ++k) {
    const Eigen::Vector3d q = piece.centre[k] + shift;
    double best = o.place_radius_mm * o.place_radius_mm, s = kNaN;
    int from = -1;
    bool branch = false;
    for (const auto& r : ref)
      if (const double d = (r.p - q).squaredNorm(); d <= best) best = d, s = r.s, from = r.piece, branch = r.branch;
    piece.on_branch[k] = branch;
    if (!std::isnan(s)) local.push_back((double(k) + 0.5) * bin), sref.push_back(s), pr.ref_piece.push_back(from);
  }
  piece.placed_fraction = piece.centre.empty() ? 0.0 : double(local.size()) / double(piece.centre.size());
  piece.registered = local.size() >= 3 && piece.placed_fraction >= o.min_placed_fraction;
  if (!piece.registered) return pr;
  const double ml = std::accumulate(local.begin(), local.end(), 0.0) / double(local.size());
  const double ms = std::accumulate(sref.begin(), sref.end(), 0.0) / double(sref.size());
  double cov = 0;
  for (size_t i = 0; i < local.size(); ++i) cov += (local[i] - ml) * (sref[i] - ms);
  piece.flipped = cov < 0;
  std::vector<double> start(local.size());
  for (size_t i = 0; i < local.size(); ++i)
    start[i] = piece.flipped ? sref[i] + local[i] - piece.length_mm : sref[i] - local[i];
  piece.start_mm = median(start);
  piece.bin_mm = bin;
  piece.s_bin = follow_projections(piece, local, sref, o);
  return pr;
}

// A reference gap is the straight line between the ends it joins, shorter than the colon missing
// there. A piece of the other scan that projects onto both sides of the gap measures it: the extra
// length (its own mm between the two sides minus the reference's) per gap k (before reference piece k).
std::vector<double> gap_extensions(const std::vector<ColonPiece>& other, const std::vector<Projection>& proj,
                                   const std::vector<ColonPiece>& ref) {
  const size_t ref_pieces = ref.size();
  std::vector<double> ext(ref_pieces, 0.0);
  for (size_t p = 0; p < other.size(); ++p) {
    if (!other[p].registered) continue;
    const Projection& pr = proj[p];
    for (size_t k = 1; k < ref_pieces; ++k) {
      if (ref[k].branch || ref[k - 1].branch) continue;  // the bands come first, in their order
      std::vector<double> before, after;  // own mm - reference s (flipped: own mm + reference s)
      for (size_t i = 0; i < pr.local.size(); ++i) {
        const double v = other[p].flipped ? pr.local[i] + pr.sref[i] : pr.local[i] - pr.sref[i];
        if (pr.ref_piece[i] == int(k) - 1) before.push_back(v);
        if (pr.ref_piece[i] == int(k)) after.push_back(v);
      }
      if (before.size() < 3 || after.size() < 3) continue;
      const double e = other[p].flipped ? median(before) - median(after) : median(after) - median(before);
      ext[k] = std::max(ext[k], e);
    }
  }
  return ext;
}

std::vector<Eigen::Vector3d> all_centres(const std::vector<ColonPiece>& pieces) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : pieces) out.insert(out.end(), p.centre.begin(), p.centre.end());
  return out;
}

// Trimmed nearest-point iterations from `t`; returns the trimmed mean distance.
double refine_shift(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, Eigen::Vector3d& t) {
  double residual = std::numeric_limits<double>::infinity();
  for (int it = 0; it < 10; ++it) {
    std::vector<std::pair<double, Eigen::Vector3d>> r;
    for (const auto& q : b) {
      const Eigen::Vector3d x = q + t;
      double best = std::numeric_limits<double>::infinity();
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      for (const auto& p : a)
        if (const double e = (p - x).squaredNorm(); e < best) best = e, d = p - x;
      r.push_back({std::sqrt(best), d});
    }
    std::sort(r.begin(), r.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    const size_t keep = std::max<size_t>(1, r.size() * 6 / 10);  // the best 60 %: pieces missing in one scan
    std::vector<double> c[3];
    residual = 0;
    for (size_t i = 0; i < keep; ++i) {
      residual += r[i].first / double(keep);
      for (int k = 0; k < 3; ++k) c[k].push_back(r[i].second[k]);
    }
    const Eigen::Vector3d step(median(c[0]), median(c[1]), median(c[2]));
    t += step;
    if (step.norm() < 0.1) break;
  }
  return residual;
}

// A band of the scan as a piece: its length, end labels and centre line.
ColonPiece band_piece(const ColonScan& scan, int seg, double length, double bin) {
  ColonPiece p;
  p.segment = seg;
  p.length_mm = std::max(length, bin);
  p.bin_mm = bin;
  if (const auto* e = segment_entry(scan, seg)) {
    if (e->contains("x0_end") && (*e)["x0_end"].is_string()) p.x0_end = (*e)["x0_end"];
    if (e->contains("x1_end") && (*e)["x1_end"].is_string()) p.x1_end = (*e)["x1_end"];
  }
  p.centre = piece_centre(scan, seg, p.length_mm, bin);
  return p;
}

// A side branch of colon length as a piece hanging at `neck` (band, mm): flipped when its own mm runs
// towards its neck (its last centre point nearer to the neck than its first). The neck is FlatSegments
// attach_lps_mm (the centre of the neck's vertices; flatten's "neck"/"tip" labels do not say which
// end its centreline mm starts at), else the band's centre point just before the neck (the band
// after it may continue next to the branch's tip where the branch is a loop of the colon).
ColonPiece branch_piece(const ColonScan& scan, int seg, double length, const std::pair<int, double>& neck,
                        const std::vector<ColonPiece>& bands, double bin) {
  ColonPiece p = band_piece(scan, seg, length, bin);
  p.branch = true, p.parent = neck.first, p.attach_mm = neck.second;
  p.on_band = segment_entry(scan, seg) && segment_entry(scan, seg)->value("parent", -1) == neck.first;
  Eigen::Vector3d at = p.centre.front();
  const auto* e = segment_entry(scan, seg);
  if (e && e->contains("attach_lps_mm") && (*e)["attach_lps_mm"].is_array() && (*e)["attach_lps_mm"].size() == 3) {
    for (int k = 0; k < 3; ++k) at[k] = (*e)["attach_lps_mm"][size_t(k)].get<double>();
  } else {
    for (const auto& b : bands)
      if (b.segment == neck.first) at = b.centre[std::min(b.centre.size() - 1, size_t(std::max(0.0, neck.second / bin - 1)))];
  }
  p.flipped = (p.centre.back() - at).norm() < (p.centre.front() - at).norm();
  return p;
}

// Cuts every placed piece whose projections turn back along the reference into its two runs
// (piece_split.h; each run at least a side branch of colon length). True when one was cut.
bool split_where_turning(std::vector<ColonPiece>& other, const std::vector<Projection>& proj, const PieceOptions& o) {
  std::vector<ColonPiece> out;
  for (size_t p = 0; p < other.size(); ++p) {
    const double cut = other[p].registered ? reversal_cut_mm(proj[p].local, proj[p].sref, o.min_branch_piece_mm) : kNaN;
    if (std::isnan(cut)) out.push_back(other[p]);
    else for (auto& piece : split_piece(other[p], cut)) out.push_back(std::move(piece));
  }
  const bool cut = out.size() > other.size();
  other = std::move(out);
  return cut;
}

}  // namespace

bool has_pieces(const ColonScan& scan) {
  if (scan.centreline_mm.size() != scan.lps.size()) return false;
  for (size_t v = 0; v < scan.lps.size(); ++v)
    if (std::isfinite(scan.centreline_mm[v]) && scan.centreline_mm[v] >= 0 && !is_branch(scan, scan.segment[v])) return true;
  return false;
}

std::vector<ColonPiece> colon_pieces(const ColonScan& scan, const PieceOptions& o) {
  std::map<int, double> length;
  for (size_t v = 0; v < scan.lps.size(); ++v) {
    const double c = scan.centreline_mm[v];
    if (!std::isfinite(c) || c < 0) continue;
    double& l = length[scan.segment[v]];
    l = std::max(l, c);
  }
  std::vector<std::pair<int, ColonPiece>> keyed;
  for (const auto& [seg, len] : length) {
    if (is_branch(scan, seg)) continue;
    ColonPiece p = band_piece(scan, seg, len, o.bin_mm);
    const auto* e = segment_entry(scan, seg);
    keyed.push_back({e ? e->value("order", seg) : seg, p});
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<ColonPiece> out;
  for (auto& [k, p] : keyed) out.push_back(std::move(p));
  for (const auto& [seg, neck] : branch_necks(scan))
    if (const auto it = length.find(seg); it != length.end() && it->second >= o.min_branch_piece_mm && !holds_tissue(scan, seg))
      out.push_back(branch_piece(scan, seg, it->second, neck, out, o.bin_mm));
  order_branches_at_necks(out, o.same_neck_mm);
  return out;
}

Eigen::Vector3d fit_shift(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, double* residual) {
  if (a.empty() || b.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (const auto& p : a) ca += p / double(a.size());
  for (const auto& p : b) cb += p / double(b.size());
  Eigen::Vector3d t0 = Eigen::Vector3d::Zero(), t1 = ca - cb;
  const double r0 = refine_shift(a, b, t0), r1 = refine_shift(a, b, t1);
  if (residual) *residual = std::min(r0, r1);
  return r0 <= r1 ? t0 : t1;
}

PieceLayout layout_pieces(const ColonScan& supine, const ColonScan& prone, const PieceOptions& o) {
  PieceLayout L;
  L.supine = colon_pieces(supine, o);
  L.prone = colon_pieces(prone, o);
  L.supine_is_reference = L.supine.size() <= L.prone.size();
  L.prone_to_supine = fit_shift(all_centres(L.supine), all_centres(L.prone), &L.fit_residual_mm);
  auto& ref = L.supine_is_reference ? L.supine : L.prone;
  auto& other = L.supine_is_reference ? L.prone : L.supine;
  const Eigen::Vector3d shift = L.supine_is_reference ? L.prone_to_supine : Eigen::Vector3d(-L.prone_to_supine);
  chain(ref);
  const std::vector<BranchLine> branches = branch_lines(L.supine_is_reference ? supine : prone, ref, o.bin_mm);
  for (int pass = 0;; ++pass) {  // place, lengthen the reference gaps the other scan spans, again
    const std::vector<RefPoint> pts = ref_points(ref, branches, o.bin_mm);
    std::vector<Projection> proj;
    for (auto& p : other) proj.push_back(place(p, pts, shift, o.bin_mm, o));
    if (pass == 0 && split_where_turning(other, proj, o)) {
      proj.clear();
      for (auto& p : other) proj.push_back(place(p, pts, shift, o.bin_mm, o));
    }
    for (size_t p = 0; p < other.size(); ++p) lay_along_branch(other[p], proj[p].ref_piece, ref, shift, o.place_radius_mm);
    if (pass == 3) break;
    const std::vector<double> ext = gap_extensions(other, proj, ref);
    double added = 0, largest = 0;
    for (size_t k = 0; k < ref.size(); ++k)
      if (!ref[k].branch) added += ext[k], largest = std::max(largest, ext[k]), ref[k].start_mm += added;
    seat_branches(ref);
    if (largest < 2 * o.bin_mm) break;
  }
  for (auto* side : {&ref, &other})
    std::stable_sort(side->begin(), side->end(), [](const ColonPiece& x, const ColonPiece& y) {
      return x.registered != y.registered ? x.registered : x.first_mm() < y.first_mm();
    });
  double lo = 0;  // the other scan may reach beyond the reference's first end (rectum cut short)
  for (const auto& p : other)
    if (p.registered) lo = std::min(lo, p.first_mm());
  for (auto* side : {&ref, &other})
    for (auto& p : *side) p.move_by(-lo);
  return L;
}

std::vector<double> common_s(const ColonScan& scan, const std::vector<ColonPiece>& pieces) {
  std::multimap<int, const ColonPiece*> by_segment;
  std::set<int> ids;
  for (const auto& p : pieces) by_segment.insert({p.segment, &p}), ids.insert(p.segment);
  const std::map<int, std::pair<int, double>> neck = branch_necks(scan, ids);  // short branch -> (piece, attach mm)
  std::vector<double> s(scan.lps.size(), kNaN);
  for (size_t v = 0; v < s.size(); ++v) {
    int seg = scan.segment[v];
    double local = scan.centreline_mm[v];
    if (auto it = neck.find(seg); it != neck.end() && !ids.count(seg)) seg = it->second.first, local = it->second.second;
    const ColonPiece* p = piece_at(by_segment, seg, local);
    if (!p || !p->registered || !std::isfinite(local) || local < 0) continue;
    s[v] = p->s_of(std::clamp(local - p->from_mm, 0.0, p->length_mm));
  }
  return s;
}

std::vector<char> held_at_neck(const ColonScan& scan, const std::vector<ColonPiece>& pieces) {
  std::multimap<int, const ColonPiece*> by_segment;
  for (const auto& p : pieces)
    if (p.registered && !p.s_bin.empty()) by_segment.insert({p.segment, &p});
  std::vector<char> held(scan.lps.size(), 0);
  for (size_t v = 0; v < held.size(); ++v) {
    const double own = v < scan.centreline_mm.size() ? scan.centreline_mm[v] : kNaN;
    const ColonPiece* p = std::isfinite(own) ? piece_at(by_segment, scan.segment[v], own) : nullptr;
    if (!p) continue;
    const double c = own - p->from_mm, h = p->bin_mm;  // a colon stretch does not halve its length between the positions
    const size_t k = std::min(p->on_branch.size() - 1, size_t(std::max(0.0, c / h)));
    held[v] = std::abs(p->s_of(c + h) - p->s_of(c - h)) < 0.5 * 2 * h || (!p->on_branch.empty() && p->on_branch[k]);
  }
  return held;
}

}  // namespace cf
