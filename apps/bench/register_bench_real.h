#pragma once
// register_bench --real-mask: the options of the real-mask pairs, and (--show-pieces) where each
// piece of the two scans was laid out against the truth of the pair (mask_pair.h) and where each
// polyp went.
#include <algorithm>
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
  int polyp_seed = 1;                          // seed of the polyps' places on the mask
  int polyp_count = 10;                        // polyps along 8-92 % of the course
  bool held_out = false;                       // held_out_cut_cases instead of segmentation_cut_cases
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

// Where the course passes a point: its places (locations(), reach 20 mm beyond the nearest wall vertex).
inline void show_places(const cf::ColonRegistration& reg, const Eigen::Vector3d& p, cf::Direction from) {
  for (const auto& [s, theta] : reg.locations(p, from, 20)) std::printf(" s %.0f;", s);
}

// The polyps whose centre lies within their diameter of the scan's flat-map wall: a cut by path distance
// can take the wall around a polyp away although the polyp's own path distance is beyond the cut (the
// path distance crosses where the colon's walls touch; painted split +3: the prone's nearest wall to
// polyp 3 was 11.5 mm away on another loop, its own loop's 25 mm), and a polyp without wall is not
// on that scan's colon surface. Each polyp left out is printed.
inline std::vector<cf::ScanCandidate> on_wall(const std::vector<cf::ScanCandidate>& polyps, const cf::ColonScan& scan) {
  std::vector<cf::ScanCandidate> out;
  for (const auto& q : polyps) {
    double nearest = INFINITY;
    for (const auto& v : scan.lps) nearest = std::min(nearest, (v - q.lps).squaredNorm());
    if (std::sqrt(nearest) <= q.size_mm) out.push_back(q);
    else std::printf("  polyp %d not on the %s wall: nearest wall vertex %.1f mm\n", q.id, scan.name.c_str(), std::sqrt(nearest));
  }
  return out;
}

// One polyp seen in both scans: the place of each in its scan the matching `m` shows it at (the pair's,
// else the first with support), the supine place mapped, support gaps, error; the length map from 100 mm
// before to 60 mm after the supine place; each polyp's places on the course.
inline void show_polyp(const cf::ColonRegistration& reg, const cf::CandidateMatching& m, const cf::ScanCandidate& q,
                       const cf::ScanCandidate& p, double path_mm, double along_mm, double distance_mm) {
  const auto [ss, st] = m.place(q.id, true);
  const auto [ps, pt] = m.place(p.id, false);
  double ms, mt;
  reg.map_coordinates(cf::Direction::kSupineToProne, ss, st, ms, mt);
  const double deg = 180 / 3.141592653589793;
  std::printf("  polyp %d path %.0f: supine s %.0f (%.0f deg) -> %.0f (%.0f deg), prone s %.0f (%.0f deg) (gap %.0f / %.0f), "
              "along %.1f, 3-D %.1f mm\n", q.id, path_mm, ss, st * deg, ms, mt * deg, ps, pt * deg, reg.support_gap_mm(true, ss),
              reg.support_gap_mm(false, ps), along_mm, distance_mm);
  std::printf("   length map (supine s > prone s):");  // the alignment around the polyp's place
  for (double x = ss - 100; x <= ss + 60; x += 10) std::printf(" %.0f>%.0f", x, reg.length().a_to_b(x));
  std::printf("\n");
  std::printf("   places: supine");
  show_places(reg, q.lps, cf::Direction::kSupineToProne);
  std::printf(" prone");
  show_places(reg, p.lps, cf::Direction::kProneToSupine);
  std::printf("\n");
}

}  // namespace
