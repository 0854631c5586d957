// The cut cases of the issue-27 test pairs (testdata phantom_pair.h): what the developed and the held-out
// kinds guarantee about the colons they leave, on colons of 0.8-2.3 m (the small phantom 1.2 m, the real
// mask at half resolution 836 mm, the full phantom ~1.5 m, flatten's real supine 2.3 m).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "colonflat/testdata/phantom_pair.h"

namespace cf {
namespace {

constexpr double kLengths[] = {800, 836, 1200, 1500, 2300};

// Millimetres of a colon of length L a cut list removes (cuts clipped to the colon).
double removed_mm(const CutList& cuts, double L) {
  double mm = 0;
  for (const auto& [a, b] : cuts) mm += std::max(0.0, std::min(b, L) - std::max(a, 0.0));
  return mm;
}

// Pieces a cut list adds to a colon of length L: one per cut with colon on both sides.
int pieces_added(const CutList& cuts, double L) {
  int n = 0;
  for (const auto& [a, b] : cuts) n += a > 0 && b < L ? 1 : 0;
  return n;
}

// Every cut lies on the colon (from >= 0, from < L), runs forward, and the cuts are in order without overlap.
void expect_well_formed(const CutList& cuts, double L, const std::string& name) {
  for (size_t k = 0; k < cuts.size(); ++k) {
    EXPECT_GE(cuts[k].first, 0.0) << name;
    EXPECT_LT(cuts[k].first, L) << name;
    EXPECT_GT(cuts[k].second, cuts[k].first) << name;
    if (k > 0) EXPECT_GE(cuts[k].first, cuts[k - 1].second) << name;
  }
}

// A case is within the targets exactly when only one scan is cut, lacking at most 25 % of the colon
// and split into at most 3 more pieces; every cut is well formed.
void expect_cases_keep_their_promise(const std::vector<CutCase>& cases, double L) {
  for (const CutCase& c : cases) {
    expect_well_formed(c.supine, L, c.name), expect_well_formed(c.prone, L, c.name);
    const bool one_scan = c.supine.empty() || c.prone.empty();
    const CutList& cut = c.supine.empty() ? c.prone : c.supine;
    const bool within = one_scan && removed_mm(cut, L) <= 0.25 * L && pieces_added(cut, L) <= 3;
    EXPECT_EQ(c.within_targets, within) << c.name << " at L = " << L << ": removes " << removed_mm(cut, L)
                                        << " mm, adds " << pieces_added(cut, L) << " pieces";
  }
}

// The developed kinds (segmentation_cut_cases): the uncut control first, every other case cuts something,
// and each keeps its within-targets flag (only "both" is beyond the targets).
TEST(RegisterPhantomPair, DevelopedCasesKeepTheirPromise) {
  for (const double L : kLengths) {
    const auto cases = segmentation_cut_cases(L);
    ASSERT_FALSE(cases.empty());
    EXPECT_TRUE(cases[0].supine.empty() && cases[0].prone.empty());
    for (size_t k = 1; k < cases.size(); ++k) EXPECT_FALSE(cases[k].supine.empty() && cases[k].prone.empty());
    expect_cases_keep_their_promise(cases, L);
  }
}

// The held-out kinds (held_out_cut_cases): each cuts something, keeps its within-targets flag (cases of the
// issue's size: at most 25 % removed, at most 3 more pieces, one scan), none repeats a developed case's
// cuts, and together they cut both scans, add 3 pieces, drop the rectal and the cecal end.
TEST(RegisterPhantomPair, HeldOutCasesKeepTheirPromiseAndDifferFromTheDeveloped) {
  for (const double L : kLengths) {
    const auto cases = held_out_cut_cases(L);
    expect_cases_keep_their_promise(cases, L);
    std::set<CutList> developed;
    for (const CutCase& d : segmentation_cut_cases(L)) developed.insert(d.supine), developed.insert(d.prone);
    bool supine = false, three = false, rectum = false, cecum = false;
    for (const CutCase& c : cases) {
      EXPECT_FALSE(c.supine.empty() && c.prone.empty()) << c.name;
      for (const CutList* cut : {&c.supine, &c.prone}) {
        if (cut->empty()) continue;
        EXPECT_EQ(developed.count(*cut), 0u) << c.name << " repeats a developed cut list";
        three |= pieces_added(*cut, L) == 3;
        rectum |= cut->front().first <= 0, cecum |= cut->back().second >= L;
      }
      supine |= !c.supine.empty() && c.prone.empty();
    }
    EXPECT_TRUE(supine && three && rectum && cecum) << "L = " << L;
  }
}

}  // namespace
}  // namespace cf
