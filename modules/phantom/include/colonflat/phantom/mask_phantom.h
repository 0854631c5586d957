#pragma once
// A CT painted around a real colon lumen mask (docs/phantom.md, "Phantom from a mask"): the mask's
// lumen (gas + fluid) stays the ground truth; around it the painter puts the phantom's body (outline,
// fat, muscle, liver, kidneys, psoas, spine, lung bases; scaled and placed around the colon), a pelvis,
// a 3 mm colon wall, dependent tagged-fluid pools with level surfaces in each pocket of the lumen,
// fully tagged stretches along the colon's course, small-bowel loops with oral contrast, a bladder
// with excreted contrast, blur and noise, in the mask's geometry (spacing, origin, direction).
//
//   cf::MaskImage::Pointer m = cf::read_binary_mask("lumen.nii.gz");
//   cf::MaskPhantomOptions o; o.position = "prone";
//   cf::MaskPhantom p = cf::paint_phantom_from_mask(m, o);   // p.phantom.ct, .lumen, .labels
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "colonflat/phantom/phantom.h"

namespace cf {

struct MaskPhantomOptions {
  std::uint64_t seed = 1;
  std::string position = "supine";  // supine | prone | left-down | right-down (the dependent side)
  bool position_header = true;      // write DICOM PatientPosition (HFS, HFP, HFDL, HFDR) into the CT
  double noise_hu = 20;             // HU, Gaussian noise standard deviation
  double blur_mm = 0;               // mm, partial-volume blur sigma (0 = automatic, as the phantom)
  int fully_tagged = 1;             // 0..3 stretches of the colon completely filled with tagged fluid
  int bowel_loops = 4;              // 0..8 small-bowel loops with oral contrast
  bool bladder = true;              // bladder with excreted contrast in its dependent part
  bool pools = true;                // dependent tagged-fluid pools in the gas-filled lumen
  double long_stretch_mm = 0;       // 0, or 100..400 mm: one stretch completely filled with tagged fluid,
                                    // where the colon lies beside other parts of itself (issue 25)
  bool deep_pools = false;          // pools at 30-50 % of their pocket's height, over the folds into the
                                    // neighbouring pockets: one level along tens of cm of a segment
  bool pressed_bowel = false;       // the touching small-bowel loops pressed against the colon wall
                                    // (no fat between the walls; the contrast 3 mm from the colon's lumen)
};

// One fluid body of the colon (a pool or a fully tagged stretch), in the result's `fluid_id` order.
struct MaskFluidBody {
  std::string kind;          // "pool" or "stretch"
  std::size_t voxels = 0;
  double hu = 0;
  double level_depth_mm = 0; // pools: depth (mm along gravity) of the level; fluid lies deeper
  double bottom_depth_mm = 0;// pools: depth of the pocket's lowest point
  double pocket_height_mm = 0;  // pools: lumen height along gravity through the lowest point
  double fraction = 0;       // pools: (bottom - level) / pocket height
  double from_mm = 0, to_mm = 0;  // stretches: range of path distance from the rectal end
};

struct MaskPhantom {
  Phantom phantom;  // ct, lumen (= the mask), labels (1 colon gas, 2 colon fluid, 3 small bowel, 5 bladder)
  std::vector<std::uint16_t> fluid_id;  // per voxel: 0 = not colon fluid, k = fluid body k (1-based)
  std::vector<MaskFluidBody> bodies;
  std::array<double, 3> gravity_lps{};  // unit vector pointing down (dependent direction)
};

// Reads a lumen mask through the volume reader and checks it: values exactly 0 and 1, at least one
// lumen voxel. Throws InputError(file, problem).
MaskImage::Pointer read_binary_mask(const std::filesystem::path& file);

// Paints the CT around `mask` (1 = lumen). Throws UsageError for invalid options.
MaskPhantom paint_phantom_from_mask(const MaskImage* mask, const MaskPhantomOptions& opts);

// A segmentation scored against a painted case's truth: Dice of the lumen, the share of the colon's
// fluid voxels segmented, and the volume segmented more than `outside_mm` from the true lumen
// (a boundary a voxel off is not "outside the colon"; a kept small-bowel loop is).
struct MaskSegmentationScore {
  double dice = 0, fluid_kept = 0, fluid_ml = 0, outside_ml = 0;
  double small_bowel_ml = 0, bladder_ml = 0;  // segmented voxels labelled small bowel / bladder
};
MaskSegmentationScore score_segmentation(const MaskImage* segmentation, const Phantom& truth, double outside_mm = 2.0);

// The mask resampled to `slice_mm` between slices (nearest slice centre; in-plane unchanged, the
// same origin and direction): painted cases at 0.6-1.5 mm slice spacing.
MaskImage::Pointer resample_mask_slices(const MaskImage* mask, double slice_mm);

// Per colon fluid body (MaskPhantom::bodies order): its volume, the share segmented and its centroid.
struct MaskBodyScore {
  std::size_t body = 0;  // 1-based, as fluid_id
  double ml = 0, kept = 0;
  std::array<double, 3> centroid_lps{};
};
std::vector<MaskBodyScore> score_fluid_bodies(const MaskImage* segmentation, const MaskPhantom& truth);

// Block-majority downsampling of a mask by integer factors (geometry: spacing x factor, origin at
// the first block's centre, same direction); for fast tests on a real mask.
MaskImage::Pointer downsample_mask(const MaskImage* mask, const std::array<int, 3>& factors);

// The dependent direction of a position in LPS (supine +y, prone -y, left-down +x, right-down -x);
// throws UsageError for an unknown position.
std::array<double, 3> gravity_of_position(const std::string& position);

}  // namespace cf
