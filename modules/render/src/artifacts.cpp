#include "colonflat/render/artifacts.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPolyData.h>

#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {

void write_png(vtkImageData* image, const std::filesystem::path& path) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    VtkMessageCapture msgs;
    vtkNew<vtkPNGWriter> w;
    w->SetFileName(tmp.c_str());
    w->SetInputData(image);
    w->SetCompressionLevel(kPngCompressionLevel);
    w->Write();
    if (!msgs.first_problem().empty() || w->GetErrorCode() != 0 || !std::filesystem::exists(tmp))
      throw Error(path.string() + ": cannot write PNG: " + msgs.write_problem(w, tmp.string()));
  });
}

ImagePtr read_png(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError(path.string(), "no such file");
  VtkMessageCapture msgs;
  vtkNew<vtkPNGReader> r;
  if (!r->CanReadFile(path.c_str())) throw InputError(path.string(), "not a PNG file");
  r->SetFileName(path.c_str());
  r->Update();
  if (!msgs.first_problem().empty()) throw InputError(path.string(), "cannot read PNG: " + msgs.first_problem());
  ImagePtr img = ImagePtr::New();
  img->DeepCopy(r->GetOutput());
  return img;
}

const ArtifactType& png_image_artifact() {
  static const ArtifactType t{
      "image", "PNG image",
      [](const std::filesystem::path& p) { return std::any(read_png(p)); },
      [](const std::any& v, const std::filesystem::path& tmp, const std::filesystem::path&) {
        write_png(std::any_cast<const ImagePtr&>(v), tmp);
      }};
  return t;
}

const ArtifactType& json_artifact() {
  static const ArtifactType t{
      "json", "JSON document",
      [](const std::filesystem::path& p) { return std::any(read_json_file(p)); },
      [](const std::any& v, const std::filesystem::path& tmp, const std::filesystem::path&) {
        write_text_atomically(tmp, std::any_cast<const nlohmann::json&>(v).dump(2) + "\n");
      }};
  return t;
}

}  // namespace cf
