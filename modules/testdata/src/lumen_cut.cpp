#include "colonflat/testdata/lumen_cut.h"

#include <itkImageRegionIteratorWithIndex.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStaticPointLocator.h>

#include "colonflat/core/error.h"
#include "colonflat/core/stage.h"
#include "colonflat/volume/volume_io.h"

namespace cf {

PhantomCentreline read_phantom_centreline(const std::filesystem::path& file) {
  const nlohmann::json j = read_json_file(file);
  if (!j.contains("points") || !j["points"].is_array()) throw InputError(file.string(), "no centre-line points");
  PhantomCentreline c;
  for (const auto& p : j["points"]) {
    const auto& x = p.at("p_lps_mm");
    c.points.emplace_back(x[0].get<double>(), x[1].get<double>(), x[2].get<double>());
    c.arc_mm.push_back(p.at("arclength_mm").get<double>());
  }
  return c;
}

long cut_lumen_mask(const std::filesystem::path& mask_in, const PhantomCentreline& c,
                    const std::vector<std::pair<double, double>>& cuts, const std::filesystem::path& mask_out) {
  MaskImage::Pointer mask = read_mask(mask_in);
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const auto& p : c.points) pts->InsertNextPoint(p.data());
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  vtkNew<vtkStaticPointLocator> loc;
  loc->SetDataSet(pd);
  loc->BuildLocator();
  long removed = 0;
  itk::ImageRegionIteratorWithIndex<MaskImage> it(mask, mask->GetLargestPossibleRegion());
  for (; !it.IsAtEnd(); ++it) {
    if (it.Get() == 0) continue;
    MaskImage::PointType p;
    mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);  // ITK physical space = LPS
    const double q[3] = {p[0], p[1], p[2]};
    const vtkIdType k = loc->FindClosestPoint(q);
    if (k < 0) continue;
    const double s = c.arc_mm[size_t(k)];
    for (const auto& [a, b] : cuts)
      if (s >= a && s < b) {
        it.Set(0);
        ++removed;
        break;
      }
  }
  write_mask(mask, mask_out);
  return removed;
}

}  // namespace cf
