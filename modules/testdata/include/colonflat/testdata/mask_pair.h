#pragma once
// Supine/prone registration test pairs from one real lumen mask (issue 27): synthetic polyps placed
// on the real wall, stretches cut out by path distance through the lumen from the rectal end (a
// collapse, a fully tagged stretch left out, the rectum cut short), the second scan's mask moved
// rigidly on the table (origin shifted, optionally turned about the colon's centre). The scans are
// then run from their masks (`colonflat run MASK --from reconstruct`). The anatomy is the real one;
// the movement between the scans is rigid (no organ deformation).
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "colonflat/volume/volume_io.h"

namespace cf {

struct MaskPolyp {
  int id = 0;
  Eigen::Vector3d lps{0, 0, 0};  // centre of the polyp's base on the wall, LPS mm
  double diameter_mm = 0;
  double path_mm = 0;            // path distance through the lumen from the rectal end
};

// The lumen's course: per lumen voxel of the mask's lumen box, the shortest path (26-neighbour
// Dijkstra, mm) through the lumen from the rectal end (the most inferior lumen voxel). Where two
// segments touch, the path may cross between them (a real mask's touching walls).
class MaskCourse {
 public:
  explicit MaskCourse(MaskImage::Pointer mask);
  const MaskImage* mask() const { return mask_.GetPointer(); }
  double length_mm() const { return length_; }
  // Path distance of the lumen voxel nearest to an LPS point (searched within 15 mm; NaN if none).
  double path_at(const Eigen::Vector3d& lps) const;
  // Removes `count` polyps (balls of 6-10 mm diameter centred on wall voxels, i.e. soft tissue
  // bulging into the lumen) spread evenly along 8-92 % of the course; returns them (ids 1, 2, ...).
  std::vector<MaskPolyp> place_polyps(int count, std::uint64_t seed);
  // A copy with every lumen voxel whose path distance lies in one of the ranges removed, then moved
  // by `shift_mm` (LPS) and turned by `rotate_deg` about the superior axis through the lumen's
  // centroid (the table: the direction's rotation and the origin change together).
  MaskImage::Pointer cut_and_move(const std::vector<std::pair<double, double>>& cuts_mm,
                                  const Eigen::Vector3d& shift_mm, double rotate_deg = 0) const;
  // The same rigid move applied to a point of the unmoved mask.
  static Eigen::Vector3d moved(const Eigen::Vector3d& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& shift_mm,
                               double rotate_deg);
  static Eigen::Vector3d unmoved(const Eigen::Vector3d& p, const Eigen::Vector3d& centre, const Eigen::Vector3d& shift_mm,
                                 double rotate_deg);
  Eigen::Vector3d centroid() const { return centroid_; }

 private:
  size_t box_index(const MaskImage::IndexType& i) const;
  MaskImage::Pointer mask_;
  MaskImage::IndexType lo_{};
  MaskImage::SizeType size_{};
  std::vector<float> path_;  // per voxel of the lumen box; +inf outside the lumen or unreached
  double length_ = 0;
  Eigen::Vector3d centroid_{0, 0, 0};
};

// The mask at `factor` times the voxel size (same origin, direction and extent): a voxel is lumen
// when at least half of the fine voxels it covers are (keeps the lumen's volume and shape, not its
// finest contacts). For tests that must run a real mask through the pipeline quickly.
MaskImage::Pointer downsample_mask(const MaskImage* mask, int factor);

// The polyps a scan cut by `cuts_mm` still shows: none within a diameter of a cut.
std::vector<MaskPolyp> polyps_seen(const std::vector<MaskPolyp>& polyps, const std::vector<std::pair<double, double>>& cuts_mm);

}  // namespace cf
