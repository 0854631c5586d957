#pragma once
// How sure the registration is along the colon (docs/register.md, "Confidence"): a bin of one
// colon is *supported* when it holds wall, the bin it maps to in the other colon holds wall, and
// the two centre points lie within `support_radius_mm` of each other after the rigid shift (LPS is
// patient-fixed: only organ motion separates them). Every point carries its distance along the
// colon to the nearest supported bin (0 inside supported stretches; large across a piece missing
// in the other scan) and to the nearest shared landmark or anchor (rectum, cecum and flexures
// found in both scans, matched candidate pairs).
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "colonflat/register/align.h"
#include "colonflat/register/profile.h"

namespace cf {

// A landmark of one scan's colon found from its centre line's course in LPS.
struct Landmark {
  std::string name;  // "rectum", "cecum", "splenic flexure", "hepatic flexure"
  double s_mm = 0;   // along the colon (the scan's own s)
  Eigen::Vector3d lps{0, 0, 0};
};

struct LandmarkOptions {
  double side_mm = 30;        // mm; a flexure lies this far left / right of the colon's midline
  double drop_mm = 40;        // mm; the course falls this much below it on both sides (a turning point)
  double drop_window_mm = 250;  // mm; along the colon, on each side, where that fall is looked for
};

// Rectum / cecum (ends labelled by flatten, passed in as s or NaN) and the two flexures: the
// highest (most superior) point of the course on the patient's left / right, accepted only where
// the colon is present around it and turns down on both sides.
std::vector<Landmark> find_landmarks(const LengthProfile& p, double rectum_s, double cecum_s, const LandmarkOptions& o);

struct SharedLandmark {
  std::string name;
  double supine_mm = 0, prone_mm = 0;
  bool consistent = false;  // the registration maps one within `tolerance` of the other
};

// Landmarks found in both scans, each marked consistent when the length map agrees with it.
std::vector<SharedLandmark> share_landmarks(const std::vector<Landmark>& supine, const std::vector<Landmark>& prone,
                                            const LengthAlignment& length, double tolerance_mm);

struct AlignmentSupport {
  std::vector<char> supine_supported, prone_supported;  // per profile bin
  std::vector<double> supine_gap_mm, prone_gap_mm;      // per bin: mm along to the nearest supported bin
  std::vector<double> supine_anchor_mm;                 // per supine bin: mm to the nearest landmark / anchor
  std::vector<std::pair<double, double>> unsupported;   // supine s stretches [from, to) without support
  double supported_fraction = 0;                        // of the supine bins with wall
};

// Support of the length map `length` (A = supine, B = prone; b + b_to_a ~ a). `anchors_mm` are the
// supine positions of the shared landmarks and anchors.
AlignmentSupport alignment_support(const LengthProfile& a, const LengthProfile& b, const LengthAlignment& length,
                                   const Eigen::Vector3d& b_to_a, double support_radius_mm,
                                   const std::vector<double>& anchors_mm);

}  // namespace cf
