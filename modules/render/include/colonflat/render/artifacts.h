#pragma once
// Artifacts of the render stage: PNG images (vtkImageData, written with vtkPNGWriter) and JSON
// documents. (Its "loops" input is core's loops artifact, colonflat/core/loops.h.)
#include <nlohmann/json.hpp>
#include <vtkSmartPointer.h>

#include "colonflat/core/stage.h"

class vtkImageData;

namespace cf {

using ImagePtr = vtkSmartPointer<vtkImageData>;

const ArtifactType& png_image_artifact();  // value ImagePtr (RGB unsigned char)
const ArtifactType& json_artifact();       // value nlohmann::json

// zlib level of the PNGs write_png writes: 1, zlib's fastest. The colon image is 23 MB of RGB
// (4641 x 1652 px on the real CT); level 1 deflates it in about 0.4 of the time of vtkPNGWriter's
// default 5 for an 8 % larger file, and every PNG reader decodes the same pixels (docs/render.md).
constexpr int kPngCompressionLevel = 1;

void write_png(vtkImageData* image, const std::filesystem::path& path);  // atomic
ImagePtr read_png(const std::filesystem::path& path);                    // throws InputError

}  // namespace cf
