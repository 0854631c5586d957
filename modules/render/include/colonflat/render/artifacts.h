#pragma once
// Artifacts of the render stage: PNG images (vtkImageData, written with vtkPNGWriter), JSON
// documents, and generic polylines (.vtp read with vtkXMLPolyDataReader; e.g. the denoise stage's
// cut loops, whose cell data "loop_id", "type" ... are kept as they are).
#include <nlohmann/json.hpp>
#include <vtkSmartPointer.h>

#include "colonflat/core/stage.h"

class vtkImageData;
class vtkPolyData;

namespace cf {

using ImagePtr = vtkSmartPointer<vtkImageData>;
using PolylinesPtr = vtkSmartPointer<vtkPolyData>;

const ArtifactType& png_image_artifact();  // value ImagePtr (RGB unsigned char)
const ArtifactType& json_artifact();       // value nlohmann::json
const ArtifactType& polylines_artifact();  // value PolylinesPtr (name "loops")

void write_png(vtkImageData* image, const std::filesystem::path& path);  // atomic
ImagePtr read_png(const std::filesystem::path& path);                    // throws InputError

}  // namespace cf
