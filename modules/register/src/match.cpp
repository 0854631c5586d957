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

struct Located {
  double s, theta;
};

}  // namespace

void ColonRegistration::match_candidates() { matching_ = match(supine_.candidates, prone_.candidates); }

CandidateMatching ColonRegistration::match(const std::vector<ScanCandidate>& cs,
                                           const std::vector<ScanCandidate>& cp) const {
  CandidateMatching out;
  std::vector<Located> where_p;
  for (const auto& c : cp) {
    const auto [s, t] = locate(c.lps, Direction::kProneToSupine);
    where_p.push_back({s, t});
  }
  std::vector<double> gap_s(cs.size()), gap_p(cp.size());
  constexpr double kHeld = std::numeric_limits<double>::infinity();  // held at a neck: no support along
  for (size_t j = 0; j < cp.size(); ++j)
    gap_p[j] = held_at_neck(cp[j].lps, Direction::kProneToSupine) ? kHeld : support_gap_mm(false, where_p[j].s);
  struct Option { double cost; size_t i, j; CandidateMatch m; };
  std::vector<Option> options;
  for (size_t i = 0; i < cs.size(); ++i) {
    const auto [s, t] = locate(cs[i].lps, Direction::kSupineToProne);
    gap_s[i] = held_at_neck(cs[i].lps, Direction::kSupineToProne) ? kHeld : support_gap_mm(true, s);
    if (std::isnan(s) || gap_s[i] > opts_.max_unsupported_mm) continue;  // no support: never paired
    double s2, t2;
    map_coordinates(Direction::kSupineToProne, s, t, s2, t2);
    for (size_t j = 0; j < cp.size(); ++j) {
      if (std::isnan(where_p[j].s) || gap_p[j] > opts_.max_unsupported_mm) continue;
      CandidateMatch m;
      m.supine_id = cs[i].id;
      m.prone_id = cp[j].id;
      m.along_mm = std::abs(where_p[j].s - s2);
      m.around_deg = angle_difference(where_p[j].theta, t2) * 180 / kPi;
      const double a = cs[i].size_mm, b = cp[j].size_mm;
      m.size_ratio = a > 0 && b > 0 ? std::max(a, b) / std::min(a, b) : 1.0;
      m.distance_3d_mm = (cs[i].lps - cp[j].lps - b_to_a_).norm();
      if (m.along_mm > opts_.match_along_mm || m.around_deg > opts_.match_around_deg ||
          m.size_ratio > opts_.match_size_ratio || m.distance_3d_mm > opts_.match_3d_mm)
        continue;
      m.supine_gap_mm = gap_s[i], m.prone_gap_mm = gap_p[j];
      m.anchor_mm = support_.supine_anchor_mm.empty() ? 0.0 : support_.supine_anchor_mm[size_t(sup_.profile.bin_of(s))];
      m.score = 1 - (1 - std::clamp(cs[i].score, 0.0, 1.0)) * (1 - std::clamp(cp[j].score, 0.0, 1.0));
      const double size_term = std::log(m.size_ratio) / std::log(std::max(1.0001, opts_.match_size_ratio));
      const double cost = std::pow(m.along_mm / opts_.match_along_mm, 2) +
                          std::pow(m.around_deg / opts_.match_around_deg, 2) + size_term * size_term;
      options.push_back({cost, i, j, m});
    }
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
  for (size_t i = 0; i < cs.size(); ++i)
    if (!used_s[i]) {
      out.supine_only.push_back(cs[i].id);
      if (gap_s[i] > opts_.max_unsupported_mm) out.supine_unaligned.push_back(cs[i].id);
    }
  for (size_t j = 0; j < cp.size(); ++j)
    if (!used_p[j]) {
      out.prone_only.push_back(cp[j].id);
      if (gap_p[j] > opts_.max_unsupported_mm) out.prone_unaligned.push_back(cp[j].id);
    }
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
