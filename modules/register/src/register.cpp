#include "colonflat/register/register.h"

#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticPointLocator.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <thread>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "along_slabs.h"
#include "piece_split.h"

namespace cf {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 6.283185307179586;

vtkSmartPointer<vtkStaticPointLocator> make_locator(const std::vector<Eigen::Vector3d>& pts) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(vtkIdType(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) points->SetPoint(vtkIdType(i), pts[i].data());
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(points);
  auto loc = vtkSmartPointer<vtkStaticPointLocator>::New();
  loc->SetDataSet(pd);
  loc->SetNumberOfPointsPerBucket(4);
  loc->BuildLocator();
  return loc;
}
}  // namespace

// Point locators of one scan: its wall in LPS, and its registered vertices in the cylinder
// embedding (s, R cos theta, R sin theta), R = the scan's mean radius. A query with no vertex
// within kFarAlongMm along s (the image of a stretch the other scan lacks) goes to the slabs
// (along_slabs.h): the bucket locator's shell search costs the cube of the distance there.
struct ColonRegistration::Index {
  static constexpr double kFarAlongMm = 10;  // a few locator buckets (about 4 vertices each)
  static constexpr double kSlabMm = 1;       // slab thickness along s
  vtkSmartPointer<vtkStaticPointLocator> lps, cylinder;
  std::vector<Eigen::Vector3d> embedded;
  std::vector<int> cylinder_vertex;  // locator point -> scan vertex
  double radius = 1;
  std::unique_ptr<AlongSlabs> slabs;
  Index(const ColonScan& scan, const ScanCoordinates& c) : radius(std::max(1.0, c.mean_radius_mm)) {
    lps = make_locator(scan.lps);
    for (size_t v = 0; v < c.s.size(); ++v) {
      if (std::isnan(c.s[v])) continue;
      embedded.push_back(embed(c.s[v], c.theta[v]));
      cylinder_vertex.push_back(int(v));
    }
    cylinder = make_locator(embedded);
    slabs = std::make_unique<AlongSlabs>(embedded, kSlabMm);
  }
  Eigen::Vector3d embed(double s, double theta) const {
    return {s, radius * std::cos(theta), radius * std::sin(theta)};
  }
  int nearest(double s, double theta) const {
    const Eigen::Vector3d q = embed(s, theta);
    const vtkIdType id = slabs->gap_mm(s) > kFarAlongMm ? slabs->nearest(q) : cylinder->FindClosestPoint(q.data());
    return id < 0 ? -1 : cylinder_vertex[size_t(id)];
  }
};

ColonRegistration::ColonRegistration(const ColonScan& supine, const ColonScan& prone, RegisterOptions opts)
    : supine_(supine), prone_(prone), opts_(std::move(opts)) {
  if (opts_.orientation != "auto" && opts_.orientation != "same" && opts_.orientation != "reverse")
    throw UsageError("--orientation must be one of auto, same, reverse (got '" + opts_.orientation + "')");
}

ColonRegistration::~ColonRegistration() = default;

void ColonRegistration::run() {
  Stopwatch t;
  compute_coordinates();
  timing_["coordinates_s"] = t.seconds();
  align_along();
  timing_["length_alignment_s"] = t.seconds() - timing_["coordinates_s"].get<double>();
  align_around();
  assess_support();
  const double before = t.seconds();
  correspond_vertices();
  timing_["vertex_correspondence_s"] = t.seconds() - before;
  match_candidates();
  anchor_on_candidates();
  if (!anchors_.empty()) {  // second pass through the matched candidates
    const double again = t.seconds();
    align_along();
    align_around();
    assess_support();
    correspond_vertices();
    match_candidates();
    timing_["anchored_pass_s"] = t.seconds() - again;
  }
  timing_["total_s"] = t.seconds();
}

namespace {
// Centres of the bins that hold wall.
std::vector<Eigen::Vector3d> present_centres(const LengthProfile& p) {
  std::vector<Eigen::Vector3d> out;
  for (int k = 0; k < p.bins(); ++k)
    if (p.count[size_t(k)] > 0) out.push_back(p.centre[size_t(k)]);
  return out;
}

// s of the rectal / cecal end of a laid-out scan (NaN when its end band is not labelled so).
double end_s(const std::vector<ColonPiece>& pieces, const std::string& name) {
  for (const auto& p : pieces) {
    if (!p.registered) continue;
    if (p.x0_end == name) return p.s_of(0);
    if (p.x1_end == name) return p.s_of(p.length_mm);
  }
  return kNaN;
}
}  // namespace

void ColonRegistration::compute_coordinates() {
  piecewise_ = has_pieces(supine_) && has_pieces(prone_);
  if (piecewise_) {
    opts_.pieces.bin_mm = opts_.profile.bin_mm;
    layout_ = layout_pieces(supine_, prone_, opts_.pieces);
    auto s_sup = common_s(supine_, layout_.supine), s_pro = common_s(prone_, layout_.prone);
    double extent = 0;
    for (const auto* v : {&s_sup, &s_pro})
      for (double x : *v)
        if (!std::isnan(x)) extent = std::max(extent, x);
    const bool rectum = !std::isnan(end_s(layout_.supine, "rectum")) || !std::isnan(end_s(layout_.prone, "rectum"));
    sup_ = colon_coordinates_from_s(supine_, std::move(s_sup), opts_.profile, extent, "pieces (centreline_mm)", rectum);
    pro_ = colon_coordinates_from_s(prone_, std::move(s_pro), opts_.profile, extent, "pieces (centreline_mm)", rectum);
    b_to_a_ = layout_.prone_to_supine;
    sup_held_ = cf::held_at_neck(supine_, layout_.supine), pro_held_ = cf::held_at_neck(prone_, layout_.prone);
  } else {
    sup_ = colon_coordinates(supine_, opts_.profile);
    pro_ = colon_coordinates(prone_, opts_.profile, opts_.orientation == "reverse");
    const bool labelled = sup_.from_rectum && pro_.from_rectum;
    if (opts_.orientation == "auto" && !labelled) {
      const double same = align_length(sup_.profile, pro_.profile, opts_.align).cost;
      const double reverse = align_length(sup_.profile, reversed_profile(pro_.profile), opts_.align).cost;
      if (reverse < same) pro_ = colon_coordinates(prone_, opts_.profile, true);
    }
    b_to_a_ = fit_shift(present_centres(sup_.profile), present_centres(pro_.profile));
  }
  anchors_.clear();
  sup_index_ = std::make_unique<Index>(supine_, sup_);
  pro_index_ = std::make_unique<Index>(prone_, pro_);
}

void ColonRegistration::align_along() {
  AlignContext ctx;
  ctx.use_position = piecewise_;
  ctx.b_to_a = b_to_a_;
  ctx.anchors = anchors_;
  length_ = align_length(sup_.profile, pro_.profile, opts_.align, ctx);
}

void ColonRegistration::assess_support() {
  sup_marks_ = find_landmarks(sup_.profile, end_s(layout_.supine, "rectum"), end_s(layout_.supine, "cecum"), opts_.landmarks);
  pro_marks_ = find_landmarks(pro_.profile, end_s(layout_.prone, "rectum"), end_s(layout_.prone, "cecum"), opts_.landmarks);
  shared_ = share_landmarks(sup_marks_, pro_marks_, length_, opts_.landmark_tolerance_mm);
  std::vector<double> at;
  for (const auto& l : shared_)
    if (l.consistent) at.push_back(l.supine_mm);
  for (const auto& a : anchors_) at.push_back(a.a_mm);
  support_ = alignment_support(sup_.profile, pro_.profile, length_, b_to_a_, opts_.support_radius_mm, at);
}

double ColonRegistration::support_gap_mm(bool supine_scan, double s) const {
  if (std::isnan(s)) return std::numeric_limits<double>::infinity();
  const auto& gap = supine_scan ? support_.supine_gap_mm : support_.prone_gap_mm;
  if (gap.empty()) return 0;
  return gap[size_t((supine_scan ? sup_ : pro_).profile.bin_of(s))];
}

void ColonRegistration::anchor_on_candidates() {
  std::vector<AlignAnchor> found;
  for (const auto& m : matching_.pairs) {
    if (!m.unique || m.along_mm > opts_.anchor_along_mm || m.around_deg > opts_.anchor_around_deg) continue;
    if (m.supine_gap_mm > 0 || m.prone_gap_mm > 0) continue;
    const ScanCandidate *a = nullptr, *b = nullptr;
    for (const auto& c : supine_.candidates) if (c.id == m.supine_id) a = &c;
    for (const auto& c : prone_.candidates) if (c.id == m.prone_id) b = &c;
    const double sa = locate(a->lps, Direction::kSupineToProne).first, sb = locate(b->lps, Direction::kProneToSupine).first;
    found.push_back({sa, sb, opts_.anchor_tolerance_mm, "candidate"});
  }
  std::sort(found.begin(), found.end(), [](const AlignAnchor& x, const AlignAnchor& y) { return x.a_mm < y.a_mm; });
  anchors_ = found;
}

void ColonRegistration::align_around() {
  twist_ = estimate_twist(sup_, pro_, length_, opts_.twist, &twist_windows_);
}

void ColonRegistration::map_coordinates(Direction d, double s, double theta, double& s_out, double& theta_out) const {
  const bool forward = d == Direction::kSupineToProne;
  s_out = forward ? length_.a_to_b(s) : length_.b_to_a(s);
  const double s_supine = forward ? s : s_out;
  const double tw = twist_.empty() ? 0.0 : twist_[size_t(sup_.profile.bin_of(s_supine))];
  theta_out = std::fmod(theta + (forward ? tw : -tw) + 2 * kTwoPi, kTwoPi);
}

int ColonRegistration::map_vertex(Direction d, double s, double theta) const {
  if (std::isnan(s) || std::isnan(theta)) return -1;
  double s2, t2;
  map_coordinates(d, s, theta, s2, t2);
  return (d == Direction::kSupineToProne ? pro_index_ : sup_index_)->nearest(s2, t2);
}

void ColonRegistration::correspond_vertices() {
  auto fill = [this](Direction d, const ScanCoordinates& c, std::vector<int>& out) {
    out.assign(c.s.size(), -1);
    const size_t n = c.s.size(), half = n / 2;
    auto part = [&](size_t lo, size_t hi) {
      for (size_t v = lo; v < hi; ++v) out[v] = map_vertex(d, c.s[v], c.theta[v]);
    };
    std::thread other(part, half, n);  // static locators answer queries concurrently
    part(0, half);
    other.join();
  };
  fill(Direction::kSupineToProne, sup_, sup_to_pro_);
  fill(Direction::kProneToSupine, pro_, pro_to_sup_);
}

int ColonRegistration::vertex_at(bool supine_scan, double s, double theta) const {
  return (supine_scan ? sup_index_ : pro_index_)->nearest(s, theta);
}

namespace {
struct Axis {
  Eigen::Vector3d centre, direction;  // LPS mm; unit, towards increasing common s
};

// The axis of the piece wall vertex w lies on, at its own centreline mm: the mean of the piece's centre
// points within +-half_mm and their direction towards increasing common s. At a neck the common
// profile's centre is the centroid of every wall laid at that s (the band's and the branches' inserted
// or held there, smoothed), which differs between the scans; the piece's own centre line is the lumen
// the point stands in, in both. False when w lies on no piece (a short side branch, no pieces).
bool piece_axis(const ColonScan& scan, const std::vector<ColonPiece>& pieces, size_t w, double half_mm, Axis& axis) {
  if (w >= scan.centreline_mm.size() || !std::isfinite(scan.centreline_mm[w])) return false;
  std::multimap<int, const ColonPiece*> by_segment;
  for (const auto& q : pieces)
    if (q.registered) by_segment.insert({q.segment, &q});
  const ColonPiece* p = piece_at(by_segment, scan.segment[w], scan.centreline_mm[w]);
  if (!p || p->centre.size() < 2) return false;
  const int n = int(p->centre.size()), h = std::max(1, int(std::lround(half_mm / p->bin_mm)));
  const int k = std::clamp(int((scan.centreline_mm[w] - p->from_mm) / p->bin_mm), 0, n - 1);
  const int lo = std::max(0, k - h), hi = std::min(n - 1, k + h);
  const Eigen::Vector3d d = p->centre[size_t(hi)] - p->centre[size_t(lo)];
  if (d.norm() < 1e-9) return false;
  axis.centre.setZero();
  for (int j = lo; j <= hi; ++j) axis.centre += p->centre[size_t(j)];
  axis.centre /= double(hi - lo + 1);
  axis.direction = (p->flipped ? -d : d).normalized();
  return true;
}

// (s, theta) of the point p at its wall vertex w: s of w and the angle of p itself about the centre line
// there: a point off the wall (the head of a pedunculated polyp, up to 15 mm across and reaching the
// colon's axis) is surrounded by its own surface at about the same distance, so its nearest vertex may
// lie on any side of it. About `axis` (with the profile's reference direction) where the profile's
// centre lies more than `off_mm` across from it: the common centre has left the point's own lumen.
// NaN when w is not registered.
std::pair<double, double> place_at(const ScanCoordinates& c, size_t w, const Eigen::Vector3d& p,
                                   const Axis* axis = nullptr, double off_mm = 0) {
  if (std::isnan(c.s[w])) return {kNaN, kNaN};
  double radial = 0, theta = kNaN;
  const size_t k = size_t(c.profile.bin_of(c.s[w]));
  if (axis) {
    Eigen::Vector3d off = axis->centre - c.profile.centre[k];
    off -= off.dot(axis->direction) * axis->direction;
    if (off.norm() > off_mm) theta = angle_about_axis(axis->centre, axis->direction, c.profile.reference[k], p, &radial);
  }
  if (std::isnan(theta)) theta = angle_about_centre(c.profile, c.s[w], p, &radial);
  return {c.s[w], radial > 0 ? theta : c.theta[w]};
}
}  // namespace

std::pair<double, double> ColonRegistration::locate(const Eigen::Vector3d& p, Direction from) const {
  const bool sup = from == Direction::kSupineToProne;
  const vtkIdType v = (sup ? *sup_index_ : *pro_index_).lps->FindClosestPoint(p.data());
  return v < 0 ? std::pair{kNaN, kNaN} : place_at(sup ? sup_ : pro_, size_t(v), p);
}

std::vector<std::pair<double, double>> ColonRegistration::locations(const Eigen::Vector3d& p, Direction from,
                                                                   double reach_mm) const {
  const bool sup = from == Direction::kSupineToProne;
  const Index& idx = sup ? *sup_index_ : *pro_index_;
  const ScanCoordinates& c = sup ? sup_ : pro_;
  const std::vector<Eigen::Vector3d>& wall = (sup ? supine_ : prone_).lps;
  const std::vector<ColonPiece>& pieces = sup ? layout_.supine : layout_.prone;
  auto place = [&](size_t w) {  // a candidate's angle about its own piece's centre line where the common one left it
    Axis axis;
    return piece_axis(sup ? supine_ : prone_, pieces, w, opts_.profile.smooth_mm, axis)
               ? place_at(c, w, p, &axis, opts_.own_axis_off_radii * c.mean_radius_mm)
               : place_at(c, w, p);
  };
  const vtkIdType v = idx.lps->FindClosestPoint(p.data());  // locate()'s place first
  std::vector<std::pair<double, double>> out{v < 0 ? std::pair{kNaN, kNaN} : place(size_t(v))};
  if (v < 0 || std::isnan(out[0].first)) return out;
  vtkNew<vtkIdList> near;
  idx.lps->FindPointsWithinRadius((wall[size_t(v)] - p).norm() + reach_mm, p.data(), near);
  std::vector<std::pair<double, size_t>> by_distance;  // registered vertices within reach, nearest first
  for (vtkIdType k = 0; k < near->GetNumberOfIds(); ++k)
    if (const size_t w = size_t(near->GetId(k)); !std::isnan(c.s[w])) by_distance.push_back({(wall[w] - p).squaredNorm(), w});
  std::sort(by_distance.begin(), by_distance.end());
  for (const auto& [d2, w] : by_distance) {
    bool known = false;
    for (const auto& place : out) known |= std::abs(c.s[w] - place.first) <= opts_.match_along_mm;
    if (!known) out.push_back(place(w));
  }
  return out;
}

Eigen::Vector3d ColonRegistration::map_lps(const Eigen::Vector3d& p, Direction d) const {
  const auto [s, theta] = locate(p, d);
  const int v = map_vertex(d, s, theta);
  if (v < 0) return Eigen::Vector3d::Constant(kNaN);
  return (d == Direction::kSupineToProne ? prone_ : supine_).lps[size_t(v)];
}

bool ColonRegistration::held_at_neck(const Eigen::Vector3d& p, Direction from) const {
  const bool sup = from == Direction::kSupineToProne;
  const std::vector<char>& own = sup ? sup_held_ : pro_held_;
  const std::vector<char>& other = sup ? pro_held_ : sup_held_;
  if (own.empty() || other.empty()) return false;
  const vtkIdType v = (sup ? *sup_index_ : *pro_index_).lps->FindClosestPoint(p.data());
  if (v >= 0 && own[size_t(v)]) return true;
  const auto [s, theta] = locate(p, from);
  const int w = map_vertex(from, s, theta);
  return w >= 0 && other[size_t(w)];
}

}  // namespace cf
