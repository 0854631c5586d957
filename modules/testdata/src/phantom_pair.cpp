#include "colonflat/testdata/phantom_pair.h"

#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"

namespace cf {
namespace {

constexpr double kPi = 3.141592653589793;

Eigen::Vector3d vec3(const nlohmann::json& a) { return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()}; }

size_t nearest_sample(const PhantomCentreline& c, const Eigen::Vector3d& p) {
  size_t best = 0;
  for (size_t i = 1; i < c.points.size(); ++i)
    if ((c.points[i] - p).squaredNorm() < (c.points[best] - p).squaredNorm()) best = i;
  return best;
}

}  // namespace

double upper_median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double PairFigures::along_median_mm() const { return upper_median(along_mm); }
double PairFigures::along_max_mm() const { return along_mm.empty() ? NAN : *std::max_element(along_mm.begin(), along_mm.end()); }

PhantomTruth read_phantom_truth(const std::filesystem::path& dir) {
  PhantomTruth t;
  t.centreline = read_phantom_centreline(dir / "centerline.json");
  const nlohmann::json j = read_json_file(dir / "polyps.json");
  if (!j.is_array()) throw InputError((dir / "polyps.json").string(), "not a list of polyps");
  for (const auto& e : j)
    t.polyps.push_back({e.value("id", 0), vec3(e.contains("position_lps_mm") ? e["position_lps_mm"] : e["center_lps_mm"]),
                        e.value("diameter_mm", 0.0), e.value("centreline_mm", e.value("arclength_mm", 0.0))});
  return t;
}

std::vector<ScanCandidate> truth_candidates(const PhantomTruth& t, const CutList& cuts) {
  std::vector<ScanCandidate> out;
  for (const auto& q : t.polyps) {
    bool cut = false;
    for (const auto& [a, b] : cuts) cut |= q.arc_mm >= a - q.diameter_mm && q.arc_mm < b + q.diameter_mm;
    if (q.diameter_mm >= 6 && !cut) out.push_back({q.id, q.lps, q.diameter_mm, 1});
  }
  return out;
}

std::vector<ScanCandidate> all_truth_candidates(const PhantomTruth& t) {
  std::vector<ScanCandidate> out;
  for (const auto& q : t.polyps) out.push_back({q.id, q.lps, q.diameter_mm, 1});
  return out;
}

std::pair<double, double> truth_error(const PhantomTruth& t, const Eigen::Vector3d& mapped, const Eigen::Vector3d& truth) {
  const PhantomCentreline& c = t.centreline;
  const size_t a = nearest_sample(c, mapped), b = nearest_sample(c, truth), n = c.points.size();
  const Eigen::Vector3d tangent = (c.points[std::min(n - 1, b + 1)] - c.points[b > 0 ? b - 1 : 0]).normalized();
  Eigen::Vector3d ra = mapped - c.points[b], rb = truth - c.points[b];
  ra -= ra.dot(tangent) * tangent, rb -= rb.dot(tangent) * tangent;
  const double angle = std::acos(std::clamp(ra.normalized().dot(rb.normalized()), -1.0, 1.0)) * 180 / kPi;
  return {std::abs(c.arc_mm[a] - c.arc_mm[b]), angle};
}

std::vector<CutCase> segmentation_cut_cases(double L) {
  return {{"uncut", {}, {}},
          {"collapse 20 mm at 45 %", {}, {{0.45 * L, 0.45 * L + 20}}},
          {"tagged 25 % dropped", {}, {{0.40 * L, 0.65 * L}}},
          {"split +3 (15 mm each)", {}, {{0.25 * L, 0.25 * L + 15}, {0.5 * L, 0.5 * L + 15}, {0.75 * L, 0.75 * L + 15}}},
          {"rectum cut 60 mm", {}, {{0, 60}}},
          {"tagged 100 mm at 70 %", {}, {{0.70 * L, 0.70 * L + 100}}},
          {"both: sup 20+100, pro 25 %", {{0.2 * L, 0.2 * L + 20}, {0.8 * L, 0.8 * L + 100}}, {{0, 50}, {0.35 * L, 0.6 * L}}, false}};
}

std::vector<CutCase> held_out_cut_cases(double L) {
  return {{"held: sup collapse 15 mm at 30 %", {{0.30 * L, 0.30 * L + 15}}, {}},
          {"held: sup split +3 (10/25/12 mm)", {{0.18 * L, 0.18 * L + 10}, {0.42 * L, 0.42 * L + 25}, {0.66 * L, 0.66 * L + 12}}, {}},
          {"held: pro 20 % dropped at 15 %", {}, {{0.15 * L, 0.35 * L}}},
          {"held: pro cecal 25 % dropped", {}, {{0.75 * L, L + 1}}},
          {"held: pro rectum 90 + collapse 60 %", {}, {{0, 90}, {0.60 * L, 0.60 * L + 20}}},
          {"held: sup 20 % at 50 %, pro split +2", {{0.50 * L, 0.70 * L}}, {{0.22 * L, 0.22 * L + 15}, {0.85 * L, 0.85 * L + 15}}, false}};
}

PairFigures score_truth_pair(const ColonRegistration& reg, const std::vector<ScanCandidate>& supine,
                             const std::vector<ScanCandidate>& prone, const PhantomTruth& prone_truth) {
  PairFigures f;
  const CandidateMatching matching = reg.match(supine, prone);
  for (const auto& q : supine)
    for (const auto& p : prone) {
      if (p.id != q.id) continue;
      ++f.seen_in_both;  // the supine polyp mapped from the place it is matched (or shown) at, as the review shows it
      const Eigen::Vector3d mapped = reg.map_place(matching, q.id, Direction::kSupineToProne);
      if (!std::isfinite(mapped.sum())) continue;
      const auto [along, around] = truth_error(prone_truth, mapped, p.lps);
      f.along_mm.push_back(along), f.around_deg.push_back(around);
    }
  for (const auto& m : matching.pairs) (m.supine_id == m.prone_id ? f.right : f.wrong) += 1;
  return f;
}

}  // namespace cf
