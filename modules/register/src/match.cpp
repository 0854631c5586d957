// Candidate matching and the registration summary of cf::ColonRegistration.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "colonflat/register/register.h"

namespace cf {
namespace {

constexpr double kPi = 3.141592653589793;

double angle_difference(double a, double b) {
  double d = std::fmod(std::abs(a - b), 2 * kPi);
  return d > kPi ? 2 * kPi - d : d;
}

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
  struct Option { double cost; size_t i, j; CandidateMatch m; };
  std::vector<Option> options;
  for (size_t i = 0; i < cs.size(); ++i) {
    const auto [s, t] = locate(cs[i].lps, Direction::kSupineToProne);
    if (std::isnan(s)) continue;
    double s2, t2;
    map_coordinates(Direction::kSupineToProne, s, t, s2, t2);
    for (size_t j = 0; j < cp.size(); ++j) {
      if (std::isnan(where_p[j].s)) continue;
      CandidateMatch m;
      m.supine_id = cs[i].id;
      m.prone_id = cp[j].id;
      m.along_mm = std::abs(where_p[j].s - s2);
      m.around_deg = angle_difference(where_p[j].theta, t2) * 180 / kPi;
      const double a = cs[i].size_mm, b = cp[j].size_mm;
      m.size_ratio = a > 0 && b > 0 ? std::max(a, b) / std::min(a, b) : 1.0;
      if (m.along_mm > opts_.match_along_mm || m.around_deg > opts_.match_around_deg ||
          m.size_ratio > opts_.match_size_ratio)
        continue;
      m.score = 1 - (1 - std::clamp(cs[i].score, 0.0, 1.0)) * (1 - std::clamp(cp[j].score, 0.0, 1.0));
      const double size_term = std::log(m.size_ratio) / std::log(std::max(1.0001, opts_.match_size_ratio));
      const double cost = std::pow(m.along_mm / opts_.match_along_mm, 2) +
                          std::pow(m.around_deg / opts_.match_around_deg, 2) + size_term * size_term;
      options.push_back({cost, i, j, m});
    }
  }
  std::sort(options.begin(), options.end(), [](const Option& x, const Option& y) { return x.cost < y.cost; });
  std::vector<bool> used_s(cs.size(), false), used_p(cp.size(), false);
  for (const auto& o : options) {
    if (used_s[o.i] || used_p[o.j]) continue;
    used_s[o.i] = used_p[o.j] = true;
    out.pairs.push_back(o.m);
  }
  for (size_t i = 0; i < cs.size(); ++i)
    if (!used_s[i]) out.supine_only.push_back(cs[i].id);
  for (size_t j = 0; j < cp.size(); ++j)
    if (!used_p[j]) out.prone_only.push_back(cp[j].id);
  return out;
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
                     {"around_deg", m.around_deg}, {"size_ratio", m.size_ratio}, {"score", m.score}});
  return {{"units", "mm"},
          {"coordinate_system", "LPS"},
          {"angles", "degrees around the colon; 0 = patient anterior projected on the cross-section"},
          {"supine", scan_json(supine_, sup_)},
          {"prone", scan_json(prone_, pro_)},
          {"length_alignment", {{"cost", length_.cost}, {"step_mm", step}, {"knots", knots}}},
          {"twist_windows", twist_windows_},
          {"candidates", {{"pairs", pairs}, {"supine_only", matching_.supine_only},
                          {"prone_only", matching_.prone_only}}},
          {"timing_s", timing_}};
}

}  // namespace cf
