// Writing the Segmentation section's montages (segmentation_qc.h): the PNGs of a drawing, named as
// its section says.
#include <filesystem>
#include <string>

#include "colonflat/core/threads.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/segmentation_qc.h"

namespace fs = std::filesystem;

namespace cf {

nlohmann::json write_segmentation_qc(const SegmentationQcDrawing& drawing, const fs::path& dir,
                                     const std::string& rel_prefix, int* images) {
  nlohmann::json section = drawing.section;
  std::size_t k = 0;
  for (Plane p : {Plane::coronal, Plane::axial, Plane::sagittal}) {
    if (!section.contains("planes") || !section["planes"].contains(plane_name(p))) continue;
    for (auto& entry : section["planes"][plane_name(p)]) entry["file"] = rel_prefix + drawing.montages.at(k++).name;
  }
  parallel_for(k, [&](std::size_t b, std::size_t e) {  // each thread's VtkMessageCapture is its own
    for (std::size_t i = b; i < e; ++i) {
      const QcMontage& m = drawing.montages[i];
      write_png_pixels(m.w, m.h, 3, m.rgb, dir / m.name);
    }
  });
  *images += int(k);
  return section;
}

nlohmann::json write_segmentation_qc(const CtImage* ct, const MaskImage* lumen, const nlohmann::json& segment_result,
                                     const fs::path& dir, const std::string& rel_prefix, int* images,
                                     const SegmentationQcOptions& opts) {
  return write_segmentation_qc(draw_segmentation_qc(ct, lumen, segment_result, opts), dir, rel_prefix, images);
}

}  // namespace cf
