#pragma once
// register_bench --real-mask: the options of the real-mask pairs, and (--show-pieces) where each
// piece of the two scans was laid out against the truth of the pair (mask_pair.h) and where each
// polyp went.
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "colonflat/register/register.h"
#include "colonflat/testdata/mask_pair.h"

namespace {

struct RealMaskOptions {
  std::vector<double> table = {15, -30, 40};  // prone table shift, LPS mm
  double turn_deg = 0;                         // prone turned about the superior axis
  bool painted = false, no_cli = false, show = false;
  int downsample = 1;                          // the mask at this many times its voxel size
  std::vector<int> only;                       // cases to run (all when empty)
};

// Per piece of each scan: own centreline mm -> path distance of the truth (the centre point
// unmoved onto the mask) -> common s of the layout, every 20 mm (--show-pieces).
inline void show_pieces(const cf::ColonRegistration& reg, const cf::MaskCourse& course, const Eigen::Vector3d& shift, double turn) {
  for (const bool prone : {false, true}) {
    const auto& pieces = prone ? reg.pieces().prone : reg.pieces().supine;
    for (const auto& p : pieces) {
      std::printf("  %s piece seg %d len %.0f start %.0f flip %d reg %d placed %.2f:", prone ? "prone" : "supine", p.segment,
                  p.length_mm, p.start_mm, int(p.flipped), int(p.registered), p.placed_fraction);
      for (size_t k = 0; k < p.centre.size(); k += 10) {
        const Eigen::Vector3d at = prone ? cf::MaskCourse::unmoved(p.centre[k], course.centroid(), shift, turn) : p.centre[k];
        const double own = (double(k) + 0.5) * 2;
        double best = 1e18, sup_own = NAN;  // nearest supine centre point (the scans' geometry is the same mask)
        for (const auto& q : reg.pieces().supine)
          for (size_t j = 0; j < q.centre.size(); ++j)
            if (const double d = (q.centre[j] - at).squaredNorm(); d < best) best = d, sup_own = q.s_of((double(j) + 0.5) * 2);
        std::printf(" %.0f>%.0f>%.0f>%.0f(%.0f)", own, course.path_at(at), p.s_of(own), sup_own, std::sqrt(best));
      }
      std::printf("\n");
    }
  }
}

// The polyps a scan cut by `cuts` shows as truth candidates, moved with that scan on the table.
inline std::vector<cf::ScanCandidate> seen_polyps(const std::vector<cf::MaskPolyp>& polyps,
                                                  const std::vector<std::pair<double, double>>& cuts,
                                                  const cf::MaskCourse& course, const Eigen::Vector3d& shift, double turn) {
  std::vector<cf::ScanCandidate> out;
  for (const auto& q : cf::polyps_seen(polyps, cuts))
    out.push_back({q.id, cf::MaskCourse::moved(q.lps, course.centroid(), shift, turn), q.diameter_mm, 1});
  return out;
}

// One polyp seen in both scans: its common s in each, the supine s mapped, support gaps, error.
inline void show_polyp(const cf::ColonRegistration& reg, const cf::ScanCandidate& q, const cf::ScanCandidate& p, double path_mm,
                       double along_mm, double distance_mm) {
  const auto [ss, st] = reg.locate(q.lps, cf::Direction::kSupineToProne);
  const auto [ps, pt] = reg.locate(p.lps, cf::Direction::kProneToSupine);
  double ms, mt;
  reg.map_coordinates(cf::Direction::kSupineToProne, ss, st, ms, mt);
  const double deg = 180 / 3.141592653589793;
  std::printf("  polyp %d path %.0f: supine s %.0f (%.0f deg) -> %.0f (%.0f deg), prone s %.0f (%.0f deg) (gap %.0f / %.0f), "
              "along %.1f, 3-D %.1f mm\n", q.id, path_mm, ss, st * deg, ms, mt * deg, ps, pt * deg, reg.support_gap_mm(true, ss),
              reg.support_gap_mm(false, ps), along_mm, distance_mm);
}

}  // namespace
