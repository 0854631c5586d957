#pragma once
// A registered supine/prone pair of one phantom patient scored against the phantom's truth (issue
// 27): the truth polyps of each position (`colonflat phantom`: polyps.json, centerline.json), the
// kinds of difference between two segmentations as stretches cut along the colon (lumen_cut.h), and
// the figures: polyps seen in both scans paired right / wrong, error along the colon.
// Shared by register_bench --cuts and the ctest pairs cut from a phantom's lumen mask.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "colonflat/register/register.h"
#include "colonflat/testdata/lumen_cut.h"

namespace cf {

using CutList = std::vector<std::pair<double, double>>;  // [from, to) mm along the colon from the rectum

struct PhantomTruthPolyp {
  int id = 0;
  Eigen::Vector3d lps{0, 0, 0};
  double diameter_mm = 0;
  double arc_mm = 0;  // mm along the phantom's centre line from the rectum
};

struct PhantomTruth {
  std::vector<PhantomTruthPolyp> polyps;
  PhantomCentreline centreline;
};

// DIR/polyps.json and DIR/centerline.json of `colonflat phantom -o DIR`. Throws InputError.
PhantomTruth read_phantom_truth(const std::filesystem::path& phantom_dir);

// The truth polyps >= 6 mm (the size) a scan cut by `cuts` still shows: none within a
// diameter of a cut. As candidates (score 1).
std::vector<ScanCandidate> truth_candidates(const PhantomTruth& t, const CutList& cuts = {});

// Every truth polyp, any size, as candidates.
std::vector<ScanCandidate> all_truth_candidates(const PhantomTruth& t);

// Along (mm between the nearest true centre-line samples) and around (degrees about the true centre
// line at `truth`) distance of a mapped point from the true position.
std::pair<double, double> truth_error(const PhantomTruth& t, const Eigen::Vector3d& mapped, const Eigen::Vector3d& truth);

// The kinds of difference on a colon of length L (mm along its course): none, a collapse,
// a fully tagged stretch of 25 % left out, the colon split into 3 more pieces, the rectum cut short
// by the catheter, a 100 mm tagged stretch left out, both scans differing at once (beyond the
// issue's targets: the prone lacks 25 % + 50 mm and the supine 120 mm as well).
struct CutCase {
  std::string name;
  CutList supine, prone;
  bool within_targets = true;  // one scan lacks up to 25 % or is split into up to 3 more pieces
};
std::vector<CutCase> segmentation_cut_cases(double length_mm);
// Held-out kinds (session 17; the rules were not developed on them): other positions and lengths, a
// collapse and a split in the supine scan, the cecal end dropped, the rectum cut with a collapse, both
// scans differing (beyond the targets: the supine lacks 20 %, the prone is split into 2 more pieces).
std::vector<CutCase> held_out_cut_cases(double length_mm);

// The figures of one registered pair.
struct PairFigures {
  int seen_in_both = 0, right = 0, wrong = 0;
  std::vector<double> along_mm, around_deg;  // per polyp seen in both, registered supine position vs the prone one
  double along_median_mm() const;            // NaN when empty
  double along_max_mm() const;
};

// Pairs `supine` with `prone` truth candidates through the registration (right = same id) and
// measures each supine polyp's mapped position (map_place: from the place it was matched at, else
// the place it is shown at) against its prone position on the prone truth.
PairFigures score_truth_pair(const ColonRegistration& reg, const std::vector<ScanCandidate>& supine,
                             const std::vector<ScanCandidate>& prone, const PhantomTruth& prone_truth);

// Upper median (v[n / 2] of the sorted values), NaN when empty.
double upper_median(std::vector<double> v);

}  // namespace cf
