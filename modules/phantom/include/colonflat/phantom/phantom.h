#pragma once
// A synthetic CT-colonography phantom with ground truth (docs/phantom.md): an abdomen in HU (body
// outline, fat, muscle, spine, outside air, lung bases at the top, a stomach gas bubble) and an
// insufflated colon (rectum, sigmoid, descending, transverse, ascending colon and cecum) with
// haustral folds, pools of tagged fluid, sessile and pedunculated polyps, optional collapsed segment,
// partial-volume blur and noise, and deliberate topological noise (tissue strands across the lumen,
// two segments almost touching, small holes through folds). Deterministic for a given seed.
//
//   cf::PhantomOptions o; o.size = "small"; o.seed = 3;
//   cf::Phantom p = cf::generate_phantom(o);   // p.ct (HU), p.lumen (0/1), p.polyps, ...
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/volume/volume_io.h"

namespace cf {

struct PhantomOptions {
  std::uint64_t seed = 1;
  std::string size = "small";     // "small" (128 x 128 x 128, 2.8 x 2.8 x 3.125 mm) or "full" (512 x 512 x 400, 0.7 x 0.7 x 1 mm)
  bool collapsed_segment = false; // a collapsed stretch of descending colon (the lumen splits in two)
  bool tagged_fluid = true;       // pools of tagged fluid in the dependent (posterior) parts
  bool polyps = true;
  bool topological_noise = true;  // strands, near-touching segments, holes through folds
  double noise_hu = 20;           // HU, standard deviation of the added Gaussian noise
  double blur_mm = 0.0;           // mm, sigma of the partial-volume blur; 0 = automatic (0.6 x in-plane spacing, >= 0.45 mm)
};

struct PhantomPolyp {
  int id = 0;
  std::array<double, 3> center_lps_mm{};  // centre of the polyp head
  double diameter_mm = 0;
  std::string type;                       // "sessile" or "pedunculated"
  std::string segment;                    // anatomical segment name
  double arclength_mm = 0;                // position along the centreline from the rectum
};

struct CenterlinePoint {
  std::array<double, 3> p_lps_mm{};
  double radius_mm = 0;     // nominal lumen radius (without folds)
  double arclength_mm = 0;  // from the rectal end
  std::string segment;
};

struct NoiseSite {
  int id = 0;
  std::string type;  // "strand", "near_touch", "fold_hole"
  std::array<double, 3> center_lps_mm{};
  double size_mm = 0;  // strand/hole diameter, or wall gap for near_touch
  std::string effect;  // expected effect on the lumen surface: "handle" (genus +1) or "possible_handle"
};

struct Phantom {
  CtImage::Pointer ct;       // HU, integer valued (as written to disk)
  MaskImage::Pointer lumen;  // ground-truth lumen (air and tagged fluid), 1 = lumen
  std::vector<PhantomPolyp> polyps;
  std::vector<CenterlinePoint> centerline;
  std::vector<NoiseSite> noise_sites;
  nlohmann::json description;  // the case: options, geometry, segments, lengths, volumes, HU values
};

// Builds the phantom in memory. Throws UsageError for invalid options.
Phantom generate_phantom(const PhantomOptions& opts);

// Writes DIR/ct.nrrd (or DIR/dicom/ with format "dicom"), lumen_mask.nrrd, polyps.json,
// centerline.json, noise_sites.json and phantom.json; all files appear together or not at all.
void write_phantom(const Phantom& p, const std::filesystem::path& dir, const std::string& format = "nrrd");

// JSON forms of the ground truth (as written to the files).
nlohmann::json polyps_json(const Phantom& p);
nlohmann::json centerline_json(const Phantom& p);
nlohmann::json noise_sites_json(const Phantom& p);

}  // namespace cf
