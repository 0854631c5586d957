#pragma once
// Polyp candidates on the 3D colon surface (Yoshida & Naeppi 2001 style): per-vertex principal
// curvatures from a local quadric fit (radius `fit_radius` mm), shape index SI (+1 cap, +0.5
// ridge, 0 saddle, -0.5 rut, -1 cup; signs taken with the normal pointing into the lumen, so a
// polyp is a cap and a haustral fold a ridge) and curvedness CV (1/mm). Seeds SI >= seed_si with
// CV in range, grown through SI >= grow_si into a cap region; the size estimate is the diameter of
// the sphere with the cap's mean curvedness (2 / CV); the score combines mean SI, cap coverage of
// that sphere and roundness (fold tips are elongated caps). Folds are ridges (SI ~0.5) and are not
// flagged. The footprint (SI >= footprint_si within max_radius) is kept for outlines. A cap with
// lumen right behind it (median tissue thickness along the normal < min_thickness_ratio x size:
// the partial-volume sheet of a gas/tagged-fluid level left out of the lumen) is not a polyp.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/soup.h"

namespace cf {

struct PolypOptions {
  double fit_radius = 2.5;      // mm, neighbourhood of the curvature fit
  double seed_si = 0.9;         // shape index of seed vertices
  double grow_si = 0.8;         // shape index for growing the cap region
  double footprint_si = -0.1;   // shape index of the polyp footprint (size estimate)
  double min_curvedness = 0.08; // 1/mm (radius of curvature <= 12.5 mm)
  double max_curvedness = 1.0;  // 1/mm (radius of curvature >= 1 mm; smaller is noise)
  double min_size = 4.0;        // mm, smallest reported candidate diameter
  double max_size = 40.0;       // mm, larger regions are not polyps
  double max_radius = 15.0;     // mm, footprint growth limit from the candidate centre
  double min_cap_area = 3.0;    // mm^2, smallest cap region (smaller caps are surface noise)
  double min_score = 0.65;      // candidates below this score are dropped
  double min_thickness_ratio = 0.5;  // tissue behind the cap along its normal (median), x size: a polyp
                                     // head is solid; a fluid level's partial-volume sheet is ~1 voxel
};

struct Curvature {
  std::vector<double> k1, k2;  // principal curvatures (1/mm), k1 >= k2, positive = bulging into the lumen
  std::vector<double> si, cv;  // shape index, curvedness
};

// `normals`: unit vertex normals pointing out of the lumen (FlatMap convention).
Curvature surface_curvature(const TriangleList& surface, const std::vector<std::array<double, 3>>& normals,
                            double fit_radius);

struct PolypCandidate {
  int id = 0;                                   // 1-based, by decreasing score
  std::array<double, 3> center_lps_mm{0, 0, 0}; // apex vertex
  int vertex = -1;                              // apex vertex id in the surface
  double size_mm = 0;                           // estimated diameter
  double score = 0;                             // 0..1
  double mean_si = 0, mean_cv = 0, cap_area_mm2 = 0, footprint_area_mm2 = 0;
  double elongation = 1;                        // sqrt of the cap's two in-plane spread eigenvalues
  std::vector<int> footprint;                   // surface vertices of the footprint
};

std::vector<PolypCandidate> detect_polyps(const TriangleList& surface,
                                          const std::vector<std::array<double, 3>>& normals,
                                          const PolypOptions& opts, Curvature* curvature_out = nullptr);

// Known polyps: a JSON list of objects with "center_lps_mm" (or "center"/"position") [x,y,z] and
// optional "id", "diameter_mm"; or a list of [x,y,z]. Throws InputError.
struct KnownPolyp {
  int id = 0;
  std::array<double, 3> center_lps_mm{0, 0, 0};
  double diameter_mm = 0;
  std::string type;
};
std::vector<KnownPolyp> read_known_polyps(const std::filesystem::path& path);
std::vector<KnownPolyp> known_polyps_from_json(const nlohmann::json& j, const std::string& name_for_errors);

// Scoring against ground truth: a candidate hits a polyp when its apex is within
// diameter/2 + tolerance_mm of the polyp centre.
struct DetectionScore {
  int polyps = 0, polyps_detected = 0;  // polyps >= min_diameter
  int false_positives = 0;              // candidates matching no polyp (of any size)
  double sensitivity = 0;
  std::vector<int> missed_ids;
};
DetectionScore score_detections(const std::vector<PolypCandidate>& candidates, const std::vector<KnownPolyp>& truth,
                                double min_diameter_mm = 6.0, double tolerance_mm = 5.0);

}  // namespace cf
