#pragma once
// The report's "Segmentation" section (docs/report.md): coronal, axial and sagittal montages of the
// CT with the lumen outlined and every body the segment stage rejected (>= min_body_ml) outlined in
// another colour, plus the tables of kept and rejected bodies. Segment's internals are not used:
// a rejected body is the connected set of gas or tagged-fluid voxels outside the lumen found from
// the position of segment's decision (run_report.json, stage "segment", result.decisions:
// what, volume_ml, position_lps_mm, decision, reason), grown to at most 3x its volume.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/report/qc_tags.h"
#include "colonflat/volume/volume_io.h"

namespace cf {

struct SegmentationQcOptions {
  double min_body_ml = 5;     // rejected bodies outlined from this volume on
  int slices = 6;             // per plane (at least 4)
  int max_pixels = 360;       // longest side of a montage image
  double margin_mm = 15;      // around the lumen and the bodies
  double search_mm = 25;      // a body's voxels are looked for this far from its decision's position
  QcTagOptions tags;          // the numbered tags' size and placement (qc_tags.h)
};

// One montage drawn in memory: RGB pixels, 3 bytes a pixel, row 0 at the top.
struct QcMontage {
  std::string name;  // file name, seg_<plane>_<n>.png
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
};

// The Segmentation section drawn, nothing written yet: `section` as write_segmentation_qc()
// returns it but without the montages' "file" entries, and the montages in plane order
// (coronal, axial, sagittal), each plane's slices in order (`section.planes.<plane>[i]` is
// montages[k] for consecutive k).
struct SegmentationQcDrawing {
  nlohmann::json section = nlohmann::json::object();
  std::vector<QcMontage> montages;
};

// Draws the section (pure: reads the volumes, writes no file; the slices are drawn on the
// threads, the same pixels for any thread count). `ct` and `lumen` are only read during the call.
// Pre: the lumen is on the CT's grid, else section = {"missing": why} and no montage.
SegmentationQcDrawing draw_segmentation_qc(const CtImage* ct, const MaskImage* lumen, const nlohmann::json& segment_result,
                                           const SegmentationQcOptions& opts = {});
// The same from the CT in 16 bits (`colonflat run` holds it so from segment's crop on): the same drawing.
SegmentationQcDrawing draw_segmentation_qc(const CompactCtImage* ct, const MaskImage* lumen,
                                           const nlohmann::json& segment_result, const SegmentationQcOptions& opts = {});

// Writes a drawing's montages as `<dir>/<name>` and returns its section with each montage's
// "file" (`rel_prefix` + name) filled in; `images` += PNGs written.
nlohmann::json write_segmentation_qc(const SegmentationQcDrawing& drawing, const std::filesystem::path& dir,
                                     const std::string& rel_prefix, int* images);

// Both in one call: writes the montage PNGs `<dir>/seg_<plane>_<n>.png` and returns the section's data:
// {planes: {axial|coronal|sagittal: [{file, position_mm, axis, w, h, pixel_mm, tags: [{id, col, row
//  (anchor pixel), pixels, placed, x, y, w, h (tag box, image pixels), leader, lumen_covered}]}]},
//  bodies: [{id, what, kind, reason, reason_index, colour, volume_ml, position_lps_mm, outlined,
//  measured_ml, seen: [{plane, slice, axis, position_mm}]}], reasons: [{reason, colour, ink}],
//  kept: [...], lumen_ml, thresholds_hu}. Body `id` is its index in `bodies` + 1 and its tag's number. `segment_result` is the segment stage's result object (may be empty).
// The lumen must be on the CT's grid (else: {"missing": why}). `images` += PNGs written.
nlohmann::json write_segmentation_qc(const CtImage* ct, const MaskImage* lumen, const nlohmann::json& segment_result,
                                     const std::filesystem::path& dir, const std::string& rel_prefix, int* images,
                                     const SegmentationQcOptions& opts = {});

}  // namespace cf
