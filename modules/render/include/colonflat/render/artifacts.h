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

void write_png(vtkImageData* image, const std::filesystem::path& path);  // atomic
ImagePtr read_png(const std::filesystem::path& path);                    // throws InputError

}  // namespace cf
