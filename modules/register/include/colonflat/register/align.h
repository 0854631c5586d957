#pragma once
// Alignment of two colons along their length (dynamic time warping of per-bin profiles) and
// around their circumference (circular cross-correlation of the wall's radial relief).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "colonflat/register/profile.h"

namespace cf {

struct AlignOptions {
  double band_mm = 250;        // mm; |s_b - s_a * Lb/La| allowed by the warping
  double prior_weight = 0.3;   // cost weight of leaving the proportional diagonal (per band^2)
  double fold_weight = 1.0;    // feature weights (each feature z-scored)
  double calibre_weight = 0.5;
  double curvature_weight = 0.0;  // off: mobile segments bend differently in the two scans (docs)
  double warp_smooth_mm = 15;  // mm; Gaussian smoothing of the warping path
  // With AlignContext::use_position (both colons laid out as pieces on one axis, pieces.h):
  double position_weight = 1.0;     // weight of the centre lines' distance term
  double position_sigma_mm = 60;    // mm; organ motion between supine and prone (docs)
  double position_cap = 9;          // the distance term saturates at (3 sigma)^2: any mismatch costs the same
  double empty_cost = 2;            // a bin without wall in either scan (a gap between pieces): below the
                                    // feature cost of two unrelated bins (3), above a matching pair's (docs)
};

// A position known in both colons (a shared landmark or a matched candidate pair): the warping
// path passes within `tolerance_mm` of it.
struct AlignAnchor {
  double a_mm = 0, b_mm = 0;
  double tolerance_mm = 10;
  std::string kind;  // "flexure", "candidate"
};

struct AlignContext {
  bool use_position = false;           // add the centre lines' distance; empty bins cost empty_cost
  Eigen::Vector3d b_to_a{0, 0, 0};     // LPS mm: a point of B + this ~ the same point of A
  std::vector<AlignAnchor> anchors;    // sorted by a_mm
};

// A monotone map between positions along colon A and colon B (mm), piecewise linear through
// knots; positions outside the knots are extrapolated with slope 1.
struct LengthAlignment {
  std::vector<double> a_mm, b_mm;  // strictly increasing knots
  double cost = 0;                 // mean feature cost along the path
  double a_to_b(double s) const;
  double b_to_a(double s) const;
};

// Aligns profile b to profile a (both from s = 0). Precondition: both have >= 2 bins.
LengthAlignment align_length(const LengthProfile& a, const LengthProfile& b, const AlignOptions& opts,
                             const AlignContext& ctx = {});

// The profile with its bins in reverse order (for trying the other orientation).
LengthProfile reversed_profile(const LengthProfile& p);

struct TwistOptions {
  double max_twist_deg = 45;  // degrees; search range of the residual rotation (0 = none)
  double window_mm = 60;      // mm; length of each correlation window
  int angle_bins = 72;        // angular bins of the relief profile
  double min_correlation = 0.5;  // windows with a weaker peak are ignored
};

// Residual rotation around the colon per bin of A (rad): theta_b = theta_a + twist[bin of s_a],
// from the wall's radial relief (folds, polyps) per window along A and its image in B.
// `windows_used` receives the number of windows with a confident correlation peak.
std::vector<double> estimate_twist(const ScanCoordinates& a, const ScanCoordinates& b, const LengthAlignment& length,
                                   const TwistOptions& opts, int* windows_used = nullptr);

}  // namespace cf
