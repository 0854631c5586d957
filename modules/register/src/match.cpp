// Candidate matching and the registration summary of cf::ColonRegistration.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "colonflat/register/register.h"

namespace cf {
namespace {

constexpr double kPi = 3.141592653589793;

double angle_difference(double a, double b) {
  double d = std::fmod(std::abs(a - b), 2 * kPi);
  return d > kPi ? 2 * kPi - d : d;
}

nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

}  // namespace

void ColonRegistration::match_candidates() { matching_ = match(supine_.candidates, prone_.candidates); }

// The places of a candidate on its scan's course (locations(): more than one where the course passes
// it twice, reach: its radius, at least min_place_reach_mm) with their support gaps.
std::vector<ColonRegistration::Place> ColonRegistration::places(const ScanCandidate& c, Direction from) const {
  constexpr double kHeld = std::numeric_limits<double>::infinity();  // held at a neck: no support along
  const bool held = held_at_neck(c.lps, from);
  std::vector<Place> out;
  for (const auto& [s, t] : locations(c.lps, from, std::max(opts_.min_place_reach_mm, c.size_mm / 2)))
    out.push_back({s, t, held || std::isnan(s) ? kHeld : support_gap_mm(from == Direction::kSupineToProne, s)});
  return out;
}

size_t ColonRegistration::shown_place(const std::vector<Place>& pl) const {
  for (size_t k = 0; k < pl.size(); ++k)
    if (pl[k].gap <= opts_.max_unsupported_mm) return k;
  return 0;
}

std::pair<double, double> CandidateMatching::place(int id, bool supine) const {
  for (const auto& m : pairs)
    if ((supine ? m.supine_id : m.prone_id) == id)
      return supine ? std::pair{m.supine_s_mm, m.supine_theta} : std::pair{m.prone_s_mm, m.prone_theta};
  for (const auto& c : supine ? supine_shown : prone_shown)
    if (c.id == id) return {c.s_mm, c.theta};
  return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
}

std::pair<double, double> ColonRegistration::candidate_place(int id, Direction from) const {
  return matching_.place(id, from == Direction::kSupineToProne);
}

Eigen::Vector3d ColonRegistration::map_place(const CandidateMatching& m, int id, Direction d) const {
  const auto [s, theta] = m.place(id, d == Direction::kSupineToProne);
  const int v = std::isnan(s) ? -1 : map_vertex(d, s, theta);
  if (v < 0) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  return (d == Direction::kSupineToProne ? prone_ : supine_).lps[size_t(v)];
}

Eigen::Vector3d ColonRegistration::map_candidate(int id, Direction d) const { return map_place(matching_, id, d); }

// Supine candidate `a` (at one of its places `pa`) and prone `b` (`pb`): the combination of places
// within the match limits that uses the fewest places other than a candidate's nearest (places()[0]),
// then the lowest cost (along^2 + around^2 + log-size^2, each over its limit), in `best` and `cost`;
// false when none is within them or a place has no support. A finding stands on its own wall, the
// nearest to it; another loop touching it is a second pass of the course, used only when the nearest
// places cannot pair (session 18: on the real mask the cheaper other pass mapped a right pair 225 mm off).
bool ColonRegistration::pair_at_places(const ScanCandidate& a, const std::vector<Place>& pa, const ScanCandidate& b,
                                       const std::vector<Place>& pb, CandidateMatch& best, double& cost) const {
  bool found = false;
  int best_rank = 0;  // places used other than a candidate's nearest
  for (size_t i = 0; i < pa.size(); ++i)
    for (size_t j = 0; j < pb.size(); ++j) {
      const Place &x = pa[i], &y = pb[j];
      const int rank = int(i > 0) + int(j > 0);
      if (x.gap > opts_.max_unsupported_mm || y.gap > opts_.max_unsupported_mm) continue;  // never paired
      double s2, t2;
      map_coordinates(Direction::kSupineToProne, x.s, x.theta, s2, t2);
      CandidateMatch m;
      m.supine_id = a.id, m.prone_id = b.id;
      m.along_mm = std::abs(y.s - s2);  // on the length map only: the common s does not see the wall slide
      m.around_deg = angle_difference(y.theta, t2) * 180 / kPi;
      m.size_ratio = a.size_mm > 0 && b.size_mm > 0 ? std::max(a.size_mm, b.size_mm) / std::min(a.size_mm, b.size_mm) : 1.0;
      m.distance_3d_mm = (a.lps - b.lps - b_to_a_).norm();
      if (m.along_mm > opts_.match_along_mm || m.around_deg > opts_.match_around_deg ||
          m.size_ratio > opts_.match_size_ratio || m.distance_3d_mm > opts_.match_3d_mm)
        continue;
      const double size_term = std::log(m.size_ratio) / std::log(std::max(1.0001, opts_.match_size_ratio));
      const double c = std::pow(m.along_mm / opts_.match_along_mm, 2) + std::pow(m.around_deg / opts_.match_around_deg, 2) +
                       size_term * size_term;
      if (found && (rank > best_rank || (rank == best_rank && c >= cost))) continue;
      m.supine_gap_mm = x.gap, m.prone_gap_mm = y.gap;
      m.supine_s_mm = x.s, m.supine_theta = x.theta, m.prone_s_mm = y.s, m.prone_theta = y.theta;
      m.anchor_mm = support_.supine_anchor_mm.empty() ? 0.0 : support_.supine_anchor_mm[size_t(sup_.profile.bin_of(x.s))];
      m.score = 1 - (1 - std::clamp(a.score, 0.0, 1.0)) * (1 - std::clamp(b.score, 0.0, 1.0));
      found = true, cost = c, best = m, best_rank = rank;
    }
  return found;
}

void ColonRegistration::list_unpaired(const std::vector<ScanCandidate>& c, const std::vector<std::vector<Place>>& pl,
                                      const std::vector<bool>& used, std::vector<int>& only, std::vector<int>& unaligned,
                                      std::vector<CandidatePlace>& shown) const {
  for (size_t i = 0; i < c.size(); ++i) {
    if (used[i]) continue;
    const Place& p = pl[i][shown_place(pl[i])];
    only.push_back(c[i].id), shown.push_back({c[i].id, p.s, p.theta});
    if (p.gap > opts_.max_unsupported_mm) unaligned.push_back(c[i].id);
  }
}

CandidateMatching ColonRegistration::match(const std::vector<ScanCandidate>& cs,
                                           const std::vector<ScanCandidate>& cp) const {
  CandidateMatching out;
  std::vector<std::vector<Place>> ps, pp;
  for (const auto& c : cs) ps.push_back(places(c, Direction::kSupineToProne));
  for (const auto& c : cp) pp.push_back(places(c, Direction::kProneToSupine));
  struct Option { double cost; size_t i, j; CandidateMatch m; };
  std::vector<Option> options;
  for (size_t i = 0; i < cs.size(); ++i)
    for (size_t j = 0; j < cp.size(); ++j) {
      Option o{0, i, j, {}};
      if (pair_at_places(cs[i], ps[i], cp[j], pp[j], o.m, o.cost)) options.push_back(o);
    }
  std::vector<int> per_s(cs.size(), 0), per_p(cp.size(), 0);
  for (const auto& o : options) ++per_s[o.i], ++per_p[o.j];
  std::sort(options.begin(), options.end(), [](const Option& x, const Option& y) { return x.cost < y.cost; });
  std::vector<bool> used_s(cs.size(), false), used_p(cp.size(), false);
  for (auto& o : options) {
    if (used_s[o.i] || used_p[o.j]) continue;
    used_s[o.i] = used_p[o.j] = true;
    o.m.unique = per_s[o.i] == 1 && per_p[o.j] == 1;
    out.pairs.push_back(o.m);
  }
  list_unpaired(cs, ps, used_s, out.supine_only, out.supine_unaligned, out.supine_shown);
  list_unpaired(cp, pp, used_p, out.prone_only, out.prone_unaligned, out.prone_shown);
  return out;
}

nlohmann::json ColonRegistration::pieces_json() const {
  auto list = [](const std::vector<ColonPiece>& pieces) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& p : pieces)
      a.push_back({{"segment", p.segment}, {"start_mm", p.start_mm}, {"length_mm", p.length_mm},
                   {"flipped", p.flipped}, {"registered", p.registered}, {"placed_fraction", p.placed_fraction},
                   {"x0_end", p.x0_end}, {"x1_end", p.x1_end}, {"branch", p.branch}});
    return a;
  };
  return {{"piecewise", piecewise_},
          {"reference", layout_.supine_is_reference ? "supine" : "prone"},
          {"prone_to_supine_shift_mm", {b_to_a_.x(), b_to_a_.y(), b_to_a_.z()}},
          {"shift_fit_residual_mm", layout_.fit_residual_mm},
          {"supine", list(layout_.supine)},
          {"prone", list(layout_.prone)}};
}

nlohmann::json ColonRegistration::landmarks_json() const {
  auto list = [](const std::vector<Landmark>& marks) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& l : marks) a.push_back({{"name", l.name}, {"s_mm", l.s_mm}, {"lps_mm", {l.lps.x(), l.lps.y(), l.lps.z()}}});
    return a;
  };
  nlohmann::json shared = nlohmann::json::array(), anchors = nlohmann::json::array();
  for (const auto& l : shared_)
    shared.push_back({{"name", l.name}, {"supine_mm", l.supine_mm}, {"prone_mm", l.prone_mm}, {"consistent", l.consistent}});
  for (const auto& a : anchors_)
    anchors.push_back({{"kind", a.kind}, {"supine_mm", a.a_mm}, {"prone_mm", a.b_mm}, {"tolerance_mm", a.tolerance_mm}});
  return {{"supine", list(sup_marks_)}, {"prone", list(pro_marks_)}, {"shared", shared}, {"anchors", anchors}};
}

nlohmann::json ColonRegistration::summary() const {
  auto scan_json = [](const ColonScan& scan, const ScanCoordinates& c) {
    size_t registered = 0;
    for (double s : c.s) registered += std::isnan(s) ? 0 : 1;
    return nlohmann::json{{"run", scan.name},
                          {"vertices", scan.lps.size()},
                          {"registered_vertices", registered},
                          {"axial_coordinate", c.axial_source},
                          {"starts_at_rectum", c.from_rectum},
                          {"reversed", c.reversed},
                          {"length_mm", c.profile.length_mm()},
                          {"mean_radius_mm", c.mean_radius_mm},
                          {"candidates_file", scan.candidates_file},
                          {"candidates", scan.candidates.size()}};
  };
  nlohmann::json knots = nlohmann::json::array();
  const double step = 10.0;
  for (double s = 0; s <= sup_.profile.length_mm(); s += step) {
    const int k = sup_.profile.bin_of(s);
    knots.push_back({{"supine_mm", s}, {"prone_mm", length_.a_to_b(s)},
                     {"twist_deg", twist_.empty() ? 0.0 : twist_[size_t(k)] * 180 / kPi}});
  }
  nlohmann::json pairs = nlohmann::json::array();
  for (const auto& m : matching_.pairs)
    pairs.push_back({{"supine_id", m.supine_id}, {"prone_id", m.prone_id}, {"along_mm", m.along_mm},
                     {"around_deg", m.around_deg}, {"size_ratio", m.size_ratio}, {"score", m.score},
                     {"distance_3d_mm", m.distance_3d_mm}, {"supine_gap_mm", m.supine_gap_mm},
                     {"prone_gap_mm", m.prone_gap_mm}, {"anchor_mm", finite_or_null(m.anchor_mm)},
                     {"supine_s_mm", finite_or_null(m.supine_s_mm)}, {"prone_s_mm", finite_or_null(m.prone_s_mm)},
                     {"unique", m.unique}});
  return {{"units", "mm"},
          {"coordinate_system", "LPS"},
          {"angles", "degrees around the colon; 0 = patient anterior projected on the cross-section"},
          {"supine", scan_json(supine_, sup_)},
          {"prone", scan_json(prone_, pro_)},
          {"length_alignment", {{"cost", length_.cost}, {"step_mm", step}, {"knots", knots}}},
          {"twist_windows", twist_windows_},
          {"candidates", {{"pairs", pairs}, {"supine_only", matching_.supine_only},
                          {"prone_only", matching_.prone_only}, {"supine_unaligned", matching_.supine_unaligned},
                          {"prone_unaligned", matching_.prone_unaligned}}},
          {"pieces", pieces_json()},
          {"landmarks", landmarks_json()},
          {"support", {{"radius_mm", opts_.support_radius_mm},
                       {"max_unsupported_mm", opts_.max_unsupported_mm},
                       {"supported_fraction", support_.supported_fraction},
                       {"unsupported_supine_mm", support_.unsupported}}},
          {"timing_s", timing_}};
}

}  // namespace cf
