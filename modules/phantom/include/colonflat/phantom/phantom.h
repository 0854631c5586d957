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
  std::string size = "full";      // "small" (128 x 128 x 128, 2.8 x 2.8 x 3.125 mm), "medium" (256 x 256 x 200,
                                  // 1.4 x 1.4 x 2 mm) or "full" (512 x 512 x 400, 0.7 x 0.7 x 1 mm)
  bool collapsed_segment = false; // a collapsed stretch of descending colon (the lumen splits in two)
  bool tagged_fluid = true;       // pools of tagged fluid in the dependent (posterior) parts
  bool polyps = true;
  bool topological_noise = true;  // strands, near-touching segments, holes through folds
  double noise_hu = 20;           // HU, standard deviation of the added Gaussian noise
  double blur_mm = 0.0;           // mm, sigma of the partial-volume blur; 0 = automatic (0.6 x in-plane spacing, >= 0.45 mm)
  // Patient position: "supine" (posterior down, DICOM HFS) or "prone" (anterior down, HFP). The same
  // seed gives the same colon, polyps and folds; prone moves the mobile transverse and sigmoid colon
  // (smooth displacement) and puts the fluid pools on the anterior side.
  std::string position = "supine";
  int fully_tagged_segments = 0;  // 0..3 colon stretches completely filled with tagged fluid (no gas)
  bool oral_contrast = false;     // small-bowel loops with positive oral contrast and a few gas bubbles
  bool excreted_contrast = false; // bladder with excreted contrast (dependent layer) and urine
  bool enhanced_vessels = false;  // contrast-enhanced aorta (+260 HU) in front of the spine
  bool rectal_tube = false;       // rectal catheter (plastic wall, air lumen) through the anus into the rectum
};

struct PhantomPolyp {
  int id = 0;
  std::array<double, 3> center_lps_mm{};  // centre of the polyp head
  double diameter_mm = 0;
  std::string type;                       // "sessile" or "pedunculated"
  std::string segment;                    // anatomical segment name
  double arclength_mm = 0;                // material position along the centreline (supine arc length, mm)
  double centreline_mm = 0;               // arc length from the rectal end along this case's true centreline
};

struct CenterlinePoint {
  std::array<double, 3> p_lps_mm{};
  double radius_mm = 0;     // nominal lumen radius (without folds)
  double arclength_mm = 0;  // from the rectal end, along this case's centreline
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
  // Ground-truth labels: 0 other, 1 colon gas, 2 colon fluid, 3 small-bowel contrast, 4 small-bowel
  // gas, 5 bladder (urine, excreted contrast), 6 rectal tube, 7 other gas, 8 enhanced vessel.
  MaskImage::Pointer labels;
  std::string patient_position = "HFS";  // DICOM PatientPosition (0018,5100): HFS supine, HFP prone
  std::vector<PhantomPolyp> polyps;
  std::vector<CenterlinePoint> centerline;
  std::vector<NoiseSite> noise_sites;
  nlohmann::json description;  // the case: options, geometry, segments, lengths, volumes, HU values
};

// Builds the phantom in memory. Throws UsageError for invalid options.
Phantom generate_phantom(const PhantomOptions& opts);

// Writes DIR/ct.nrrd (or DIR/dicom/ with format "dicom"; both carry PatientPosition),
// lumen_mask.nrrd, labels.nrrd, polyps.json, centerline.json, noise_sites.json and phantom.json;
// all files appear together or not at all.
void write_phantom(const Phantom& p, const std::filesystem::path& dir, const std::string& format = "nrrd");

// JSON forms of the ground truth (as written to the files).
nlohmann::json polyps_json(const Phantom& p);
nlohmann::json centerline_json(const Phantom& p);
nlohmann::json noise_sites_json(const Phantom& p);

}  // namespace cf
