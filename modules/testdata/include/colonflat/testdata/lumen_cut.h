#pragma once
// Registration test pairs from one phantom patient (issue 27): a scan whose segmentation differs
// the way real ones do is made by removing lumen from its mask along stretches of the phantom's
// centre line (a collapse, a fully tagged stretch left out, the rectum cut short by the catheter),
// then run through the pipeline from the mask (`colonflat run MASK --from reconstruct`).
#include <filesystem>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace cf {

struct PhantomCentreline {
  std::vector<Eigen::Vector3d> points;  // LPS mm, every 2 mm from the rectum
  std::vector<double> arc_mm;           // arc length of each point from the rectum
};

// The phantom's centerline.json (`colonflat phantom`). Throws InputError.
PhantomCentreline read_phantom_centreline(const std::filesystem::path& file);

// Reads `mask_in`, sets to 0 every lumen voxel whose nearest centre-line point lies in one of the
// arc-length ranges [from, to) (mm from the rectum), and writes `mask_out`. Returns the voxels removed.
long cut_lumen_mask(const std::filesystem::path& mask_in, const PhantomCentreline& centreline,
                    const std::vector<std::pair<double, double>>& cuts_mm, const std::filesystem::path& mask_out);

}  // namespace cf
