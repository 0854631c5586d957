#pragma once
// Alignment of two colons along their length (dynamic time warping of per-bin profiles) and
// around their circumference (circular cross-correlation of the wall's radial relief).
#include <vector>

#include "colonflat/register/profile.h"

namespace cf {

struct AlignOptions {
  double band_mm = 250;        // mm; |s_b - s_a * Lb/La| allowed by the warping
  double prior_weight = 0.3;   // cost weight of leaving the proportional diagonal (per band^2)
  double fold_weight = 1.0;    // feature weights (each feature z-scored)
  double calibre_weight = 0.5;
  double curvature_weight = 0.0;  // off: mobile segments bend differently in the two scans (docs)
  double warp_smooth_mm = 15;  // mm; Gaussian smoothing of the warping path
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
LengthAlignment align_length(const LengthProfile& a, const LengthProfile& b, const AlignOptions& opts);

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
