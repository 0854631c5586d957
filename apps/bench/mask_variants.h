#pragma once
// Variations of a real lumen mask for the stress sets: the same anatomy with its walls a voxel
// thinner or thicker, as another segmentation of the same scan could give it. Growing the lumen
// closes the thin walls between touching colon loops (more and longer handles, pockets behind
// long contacts); shrinking it opens thin necks and strands (fewer handles).
#include <cstdio>
#include <string>

#include "colonflat/volume/volume_io.h"

namespace cf::bench {

// The slice spacing (mm) of the benches' thick-slice variant of a thinner-slice mask: each slice the
// nearest of the mask's (phantom's resample_mask_slices). A wall between two touching colon loops
// that lay in a dropped slice is gone, so the loops merge (the real CT's lumen reconstructed from the
// mask: genus 93 at its 1 mm slices, 170 at 1.25 mm; painted at 1.25 mm and run end to end: 224);
// a common slice spacing of CT colonography.
constexpr double kThickSliceMm = 1.25;

// kThickSliceMm as text ("1.25"), for command lines and row names.
inline std::string thick_slice_text() {
  char text[32];
  std::snprintf(text, sizeof text, "%g", kThickSliceMm);
  return text;
}

// `mask` (lumen 1, else 0) dilated (voxels > 0) or eroded (voxels < 0) by ITK's binary
// morphology with a ball of |voxels| voxels along every axis (BinaryBallStructuringElement).
// Post: the same size, origin, spacing and direction as `mask`; values 0/1; voxels == 0: a copy.
MaskImage::Pointer grown_mask(const MaskImage* mask, int voxels);

// `mask` with `slices` empty slices (value 0) added after its last slice (the third index axis), as
// a longer scan of the same colon would hold them (ITK's ConstantPadImageFilter). Post: size[2] grown
// by `slices`; origin, spacing, direction and every original voxel unchanged. slices >= 0.
MaskImage::Pointer padded_mask(const MaskImage* mask, int slices);

}  // namespace cf::bench
