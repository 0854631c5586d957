#pragma once
// segment_bench --painted's cases (issue 25; docs/segment.md): the painted cases, their selection
// by --cases, and the per-body report of the colon fluid lost.
#include <cstdio>
#include <sstream>
#include <string>

#include "colonflat/phantom/mask_phantom.h"

namespace {

// Issue 25: segmentation of CTs painted around a real lumen mask (ground truth = the mask). "easy":
// pools in each pocket and one 60-120 mm stretch; "stretch": + a 200 mm stretch filled where the colon
// lies beside other parts of itself; "pools": pools over the folds (30-50 % of the pocket); "bowel":
// loops pressed against the colon wall; "hard": all three; slice spacing resampled where given.
struct PaintedCase {
  const char* name;
  const char* position;
  bool header;
  double long_mm;
  bool deep, pressed;
  double slice_mm;  // 0: the mask's own
};
const PaintedCase kPaintedCases[] = {
    {"easy", "supine", true, 0, false, false, 0},       {"easy", "prone", false, 0, false, false, 0},
    {"stretch", "supine", true, 200, false, false, 0},  {"stretch", "prone", false, 250, false, false, 0},
    {"pools", "supine", true, 0, true, false, 0},       {"pools", "prone", false, 0, true, false, 0},
    {"bowel", "supine", true, 0, false, true, 0},       {"hard", "supine", true, 200, true, true, 0.6},
    {"hard", "prone", false, 200, true, true, 1.5},     {"hard", "left-down", false, 200, true, true, 1.0}};

// --cases: comma-separated names ("hard") or name/position ("hard/left-down"); empty: all.
bool case_selected(const std::string& only, const PaintedCase& c) {
  if (only.empty()) return true;
  std::stringstream s(only);
  for (std::string x; std::getline(s, x, ',');)
    if (x == c.name || x == std::string(c.name) + "/" + c.position) return true;
  return false;
}

double long_stretch_kept(const cf::MaskPhantom& p, const cf::MaskImage* seg) {
  if (p.bodies.empty() || p.bodies[0].kind != "stretch" || p.bodies[0].to_mm - p.bodies[0].from_mm < 150) return -1;
  return 100 * cf::score_fluid_bodies(seg, p).at(0).kept;
}

// Every colon fluid body of >= 5 mL kept less than 95 % (and the long stretch): kind, mL, share kept, centroid (LPS).
void print_lost_bodies(const cf::MaskPhantom& p, const cf::MaskImage* seg) {
  for (const cf::MaskBodyScore& b : cf::score_fluid_bodies(seg, p))
    if ((b.ml >= 5 && b.kept < 0.95) || (b.body == 1 && long_stretch_kept(p, seg) >= 0))
      std::printf("   %s: %s %zu, %.1f mL, %.1f %% kept, LPS (%.0f %.0f %.0f)\n", b.kept < 0.95 ? "lost" : "long", p.bodies[b.body - 1].kind.c_str(),
                  b.body, b.ml, 100 * b.kept, b.centroid_lps[0], b.centroid_lps[1], b.centroid_lps[2]);
}

}  // namespace
