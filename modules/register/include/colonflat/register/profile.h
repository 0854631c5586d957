#pragma once
// Colon coordinates of one scan: per wall vertex the distance along the colon s (mm) and the
// angle around it theta (rad), and per length bin a profile (centre, tangent, calibre, curvature,
// fold signal) used to align two scans along their length.
//
// s: the flat map's `centreline_mm` (contract 1) when present; otherwise the x of the largest
// segment, turned into arc length of the centroid line of x-slices (conformal x is not arc length).
// theta: around the local tangent, 0 = the patient's anterior direction (LPS -P) projected on the
// cross-section (parallel transport where the colon runs anterior-posterior). LPS is attached to
// the patient, so supine and prone angles agree when the colon does not twist.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "colonflat/register/scan.h"

namespace cf {

struct ProfileOptions {
  double bin_mm = 2.0;       // mm; length bin of the profile
  double smooth_mm = 8.0;    // mm; Gaussian sigma smoothing the centre line
  double fold_band_mm = 25;  // mm; calibre minus its Gaussian smoothing at this sigma = fold signal
};

// Per-bin profile along the colon; bin k covers s in [k, k + 1) * bin_mm.
struct LengthProfile {
  double bin_mm = 2.0;
  std::vector<Eigen::Vector3d> centre;     // LPS mm, smoothed centroid of the bin's wall vertices
  std::vector<Eigen::Vector3d> tangent;    // unit, towards increasing s
  std::vector<Eigen::Vector3d> reference;  // unit, normal to tangent: theta = 0
  std::vector<double> radius;              // mm, mean distance of the wall to the centre line
  std::vector<double> curvature;           // 1/mm, of the smoothed centre line
  std::vector<double> fold;                // mm, radius minus its large-scale trend (folds < 0)
  std::vector<int> count;                  // wall vertices in the bin
  int bins() const { return int(centre.size()); }
  double length_mm() const { return bin_mm * bins(); }
  int bin_of(double s) const;              // clamped to [0, bins)
};

struct ScanCoordinates {
  std::vector<double> s;       // mm along the colon per vertex; NaN = vertex not registered
  std::vector<double> theta;   // rad in [0, 2 pi) per vertex; NaN with s
  std::vector<double> radial;  // mm, distance of the vertex from the centre line; NaN with s
  LengthProfile profile;
  std::string axial_source;    // "centreline_mm" or "flat x of segment K"
  bool from_rectum = false;    // s starts at the rectal end (known from the map's labels)
  bool reversed = false;       // s was reversed relative to the source
  double mean_radius_mm = 0;
};

// Computes the coordinates of `scan`. `reverse` flips the direction of s (s -> length - s).
// Throws PreconditionError(scan.name + ...) when the colon is shorter than 20 bins.
ScanCoordinates colon_coordinates(const ColonScan& scan, const ProfileOptions& opts, bool reverse = false);

// Coordinates from a given s per vertex (NaN = not registered; e.g. the common s of the pieces,
// pieces.h), the profile at least `min_length_mm` long (bins beyond the colon are empty).
// Throws PreconditionError when the colon is shorter than 20 bins.
ScanCoordinates colon_coordinates_from_s(const ColonScan& scan, std::vector<double> s, const ProfileOptions& opts,
                                         double min_length_mm, const std::string& source, bool from_rectum);

// The profile, theta and radial of `c` from its s (`bins` bins of opts.bin_mm).
void fill_profile(const ColonScan& scan, const ProfileOptions& opts, int bins, ScanCoordinates& c);

// Angle (rad in [0, 2 pi)) of the LPS point `x` about the centre line at s (0 = the bin's reference
// direction, the patient's anterior); its distance from the centre line in `radial` when given.
double angle_about_centre(const LengthProfile& p, double s, const Eigen::Vector3d& x, double* radial = nullptr);

// Angle (rad in [0, 2 pi)) of `x` about the axis through `centre` along the unit `tangent`, 0 = `reference`
// projected on the cross-section (the profile's convention with another axis); NaN when `reference` is
// parallel to `tangent`. Its distance from the axis in `radial` when given.
double angle_about_axis(const Eigen::Vector3d& centre, const Eigen::Vector3d& tangent, const Eigen::Vector3d& reference,
                        const Eigen::Vector3d& x, double* radial = nullptr);

// Gaussian smoothing of a sampled signal (sigma in samples), edges by renormalisation.
std::vector<double> gaussian_smooth(const std::vector<double>& v, double sigma_samples);

}  // namespace cf
