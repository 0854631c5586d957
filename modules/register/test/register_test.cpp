// Registration of synthetic supine/prone pairs with known correspondence (synthetic_pair.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/register/register.h"
#include "colonflat/testdata/synthetic_pair.h"

namespace cf {
namespace {

constexpr double kPi = 3.141592653589793;

struct Errors {
  double along_median = 0, along_p95 = 0, around_median_deg = 0, mapped_fraction = 0;
};

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[size_t(q * double(v.size() - 1))];
}

// Material-coordinate error of the supine -> prone vertex map (every 7th supine vertex).
Errors vertex_errors(const SyntheticPair& pair, const ColonRegistration& reg) {
  std::vector<double> along, around;
  size_t mapped = 0, total = 0;
  for (size_t v = 0; v < pair.supine_sigma.size(); v += 7) {
    ++total;
    const int w = reg.supine_to_prone()[v];
    if (w < 0) continue;
    ++mapped;
    along.push_back(std::abs(pair.supine_sigma[v] - pair.prone_sigma[size_t(w)]));
    double d = std::fmod(std::abs(pair.supine_phi[v] - pair.prone_phi[size_t(w)]), 2 * kPi);
    around.push_back((d > kPi ? 2 * kPi - d : d) * 180 / kPi);
  }
  return {percentile(along, 0.5), percentile(along, 0.95), percentile(around, 0.5), double(mapped) / double(total)};
}

// A synthetic pair and its registration (default options), run.
struct RegisteredPair {
  explicit RegisteredPair(SyntheticPair p) : pair(std::move(p)), reg(pair.supine, pair.prone) { reg.run(); }
  SyntheticPair pair;
  ColonRegistration reg;
};

// Every true polyp pair is matched to its own id, and no pair joins different ids.
void expect_polyps_paired(const SyntheticPair& pair, const ColonRegistration& reg) {
  int correct = 0;
  for (const auto& m : reg.matching().pairs) {
    EXPECT_EQ(m.supine_id, m.prone_id) << "false match";
    correct += m.supine_id == m.prone_id ? 1 : 0;
  }
  EXPECT_EQ(correct, int(pair.polyps.size()));
}

// Registering a scan to itself maps every vertex onto itself and pairs every candidate with itself.
TEST(RegisterSynthetic, IdentityPairMapsVerticesOntoThemselves) {
  SyntheticPair input = make_synthetic_pair({});
  input.prone = input.supine;
  input.prone_sigma = input.supine_sigma, input.prone_phi = input.supine_phi;
  auto&& [pair, reg] = RegisteredPair(std::move(input));
  const Errors e = vertex_errors(pair, reg);
  EXPECT_LT(e.along_median, 1.0);
  EXPECT_LT(e.around_median_deg, 2.0);
  EXPECT_GT(e.mapped_fraction, 0.999);
  EXPECT_EQ(reg.matching().pairs.size(), pair.supine.candidates.size());
}

// A deformed prone scan (middle shifted 40 mm, wall slid +-15 mm along the colon): small
// along/around errors, every polyp paired with itself, the one-scan-only candidates left single.
TEST(RegisterSynthetic, DeformedPairWithCentrelineIsAligned) {
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair({}));
  const Errors e = vertex_errors(pair, reg);
  EXPECT_LT(e.along_median, 5.0);
  EXPECT_LT(e.along_p95, 15.0);
  EXPECT_LT(e.around_median_deg, 10.0);
  expect_polyps_paired(pair, reg);
  EXPECT_EQ(reg.matching().supine_only.size(), 1u);
  EXPECT_EQ(reg.matching().prone_only.size(), 1u);
  EXPECT_FALSE(reg.prone_reversed());
}

// Without centreline_mm or end labels (older flat maps) and with the prone map running from the
// other end, the orientation is found from the profiles and the errors stay small.
TEST(RegisterSynthetic, FallbackFindsReversedProneOrientation) {
  SyntheticPairOptions o;
  o.centreline = false;
  o.reverse_prone = true;
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair(o));
  EXPECT_TRUE(reg.prone_reversed());
  const Errors e = vertex_errors(pair, reg);
  EXPECT_LT(e.along_median, 6.0);
  EXPECT_LT(e.around_median_deg, 12.0);
  expect_polyps_paired(pair, reg);
}

// A prone wall rotated 25 degrees around its centre line is turned back by the relief
// correlation; with the search switched off the around error is the full rotation.
TEST(RegisterSynthetic, RotationAroundTheColonIsRecovered) {
  SyntheticPairOptions o;
  o.twist_deg = 25;
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair(o));
  EXPECT_LT(vertex_errors(pair, reg).around_median_deg, 10.0);
  RegisterOptions off;
  off.twist.max_twist_deg = 0;
  ColonRegistration plain(pair.supine, pair.prone, off);
  plain.run();
  EXPECT_GT(vertex_errors(pair, plain).around_median_deg, 18.0);
}

// LPS points map between the scans: each polyp's supine centre lands within 6 mm of its prone
// centre, and back.
TEST(RegisterSynthetic, LpsPointMapLandsOnTheSamePolyp) {
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair({}));
  for (const auto& q : pair.polyps) {
    EXPECT_LT((reg.map_lps(q.supine_lps, Direction::kSupineToProne) - q.prone_lps).norm(), 6.0) << "polyp " << q.id;
    EXPECT_LT((reg.map_lps(q.prone_lps, Direction::kProneToSupine) - q.supine_lps).norm(), 6.0) << "polyp " << q.id;
  }
}

// The length map is strictly increasing and its inverse undoes it.
TEST(RegisterSynthetic, LengthMapIsMonotoneAndInvertible) {
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair({}));
  const auto& l = reg.length();
  for (size_t k = 1; k < l.b_mm.size(); ++k) EXPECT_GT(l.b_mm[k], l.b_mm[k - 1]);
  for (double s = 0; s < 500; s += 37) EXPECT_NEAR(l.b_to_a(l.a_to_b(s)), s, 1e-6);
}

// A prone candidate four times the size of its supine partner is not paired; both stay single.
TEST(RegisterCandidates, SizeMismatchIsNotPaired) {
  SyntheticPair input = make_synthetic_pair({});
  input.prone.candidates[0].size_mm *= 4;
  auto&& [pair, reg] = RegisteredPair(std::move(input));
  for (const auto& m : reg.matching().pairs) EXPECT_NE(m.supine_id, 1);
  EXPECT_EQ(reg.matching().supine_only.size(), 2u);
  EXPECT_EQ(reg.matching().prone_only.size(), 2u);
}

// A pair's score is raised above both candidates' own scores.
TEST(RegisterCandidates, PairScoreIsRaised) {
  auto&& [pair, reg] = RegisteredPair(make_synthetic_pair({}));
  ASSERT_FALSE(reg.matching().pairs.empty());
  for (const auto& m : reg.matching().pairs) EXPECT_NEAR(m.score, 1 - 0.3 * 0.3, 1e-9);
}

// A colon map shorter than 20 profile bins cannot be registered: PreconditionError.
TEST(RegisterProfile, TooShortColonIsRejected) {
  SyntheticPairOptions o;
  o.length_mm = 30;
  o.polyps = 0;
  o.extra_candidates = 0;
  const SyntheticPair pair = make_synthetic_pair(o);
  ColonRegistration reg(pair.supine, pair.prone);
  EXPECT_THROW(reg.run(), PreconditionError);
}

// An unknown orientation choice is a usage error.
TEST(RegisterProfile, UnknownOrientationIsRejected) {
  const SyntheticPair pair = make_synthetic_pair({});
  RegisterOptions o;
  o.orientation = "sideways";
  EXPECT_THROW(ColonRegistration(pair.supine, pair.prone, o), UsageError);
}

// Candidate files: the render stage's object form and the phantom's plain list are read; an
// entry without a position is an InputError.
TEST(RegisterScan, CandidateJsonForms) {
  const auto a = scan_candidates_from_json(
      nlohmann::json::parse(R"({"candidates":[{"id":3,"position_lps_mm":[1,2,3],"size_mm":7,"score":0.8}]})"), "c.json");
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].id, 3);
  EXPECT_DOUBLE_EQ(a[0].lps.z(), 3);
  EXPECT_DOUBLE_EQ(a[0].size_mm, 7);
  const auto b = scan_candidates_from_json(nlohmann::json::parse(R"([{"id":1,"center_lps_mm":[4,5,6],"diameter_mm":9}])"), "p");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_DOUBLE_EQ(b[0].size_mm, 9);
  EXPECT_DOUBLE_EQ(b[0].score, 1.0);
  EXPECT_THROW(scan_candidates_from_json(nlohmann::json::parse(R"([{"id":1,"size_mm":3}])"), "p"), InputError);
  EXPECT_THROW(scan_candidates_from_json(nlohmann::json::parse(R"({"items":[]})"), "p"), InputError);
}

}  // namespace
}  // namespace cf

namespace cf {
namespace {

// A tube of 300 mm (segment 0, centreline_mm = x) with a side-branch band (segment 1, a pouch at
// x = 150 whose own centreline_mm runs 0..20 mm): the pouch's vertices are placed at its neck
// (attach_mm = 150) along the colon, not at the rectal end.
TEST(RegisterProfile, SideBranchVerticesSitAtTheirNeck) {
  ColonScan scan;
  scan.name = "synthetic";
  for (int i = 0; i <= 300; ++i)
    for (int k = 0; k < 16; ++k) {
      const double a = 2 * M_PI * k / 16;
      scan.lps.emplace_back(double(i), 10 * std::cos(a), 10 * std::sin(a));
      scan.uv.emplace_back(double(i), 10 * a);
      scan.segment.push_back(0);
      scan.centreline_mm.push_back(double(i));
    }
  for (int j = 0; j <= 20; ++j) {
    scan.lps.emplace_back(150.0, 10.0 + j, 0.0);
    scan.uv.emplace_back(double(j), 400.0);
    scan.segment.push_back(1);
    scan.centreline_mm.push_back(double(j));
  }
  scan.normal.assign(scan.lps.size(), Eigen::Vector3d::Zero());
  scan.segments = nlohmann::json::array({{{"id", 0}, {"kind", "colon"}, {"x0_end", "rectum"}, {"x1_end", "cecum"}},
                                         {{"id", 1}, {"kind", "branch"}, {"parent", 0}, {"attach_mm", 150.0}}});
  const ScanCoordinates c = colon_coordinates(scan, ProfileOptions{});
  for (std::size_t v = scan.lps.size() - 21; v < scan.lps.size(); ++v) EXPECT_NEAR(c.s[v], 150.0, 1e-9) << v;
  EXPECT_NEAR(c.s[16 * 100], 100.0, 1e-9);  // a colon vertex keeps its centreline mm
}

// angle_about_axis keeps the profile's convention about any axis: 0 = the reference projected on the
// cross-section, a quarter turn at tangent x reference, the distance from the axis in radial; NaN when
// the reference runs along the axis.
TEST(RegisterProfile, AngleAboutAnAxisUsesTheProjectedReference) {
  const Eigen::Vector3d c(10, 20, 30), t(0, 0, 1), ref(0, -1, 0.5);  // reference not across the axis
  double radial = 0;
  EXPECT_NEAR(angle_about_axis(c, t, ref, c + Eigen::Vector3d(0, -5, 3), &radial), 0.0, 1e-12);
  EXPECT_NEAR(radial, 5.0, 1e-12);
  EXPECT_NEAR(angle_about_axis(c, t, ref, c + Eigen::Vector3d(2, 0, -7), &radial), M_PI / 2, 1e-12);  // t x (0,-1,0) = +x
  EXPECT_NEAR(radial, 2.0, 1e-12);
  EXPECT_NEAR(angle_about_axis(c, t, ref, c + Eigen::Vector3d(0, 4, 0)), M_PI, 1e-12);
  EXPECT_TRUE(std::isnan(angle_about_axis(c, t, Eigen::Vector3d(0, 0, 2), c + Eigen::Vector3d(1, 0, 0))));
}

}  // namespace
}  // namespace cf
