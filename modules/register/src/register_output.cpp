#include "colonflat/register/register_output.h"

#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <fstream>
#include <limits>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/vtk_messages.h"
#include "colonflat/render/artifacts.h"

namespace cf {
namespace fs = std::filesystem;

namespace {

vtkSmartPointer<vtkDoubleArray> double_array(const std::string& name, int components, vtkIdType n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name.c_str());
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(n);
  return a;
}

void write_vtp(vtkPolyData* pd, const fs::path& tmp, const fs::path& target) {
  VtkMessageCapture msgs;
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(tmp.c_str());
  w->SetInputData(pd);
  w->SetDataModeToAppended();
  w->SetCompressorTypeToNone();  // raw binary: compressing doubles costs seconds per file for a few % of size
  w->EncodeAppendedDataOff();
  if (!w->Write() || !msgs.first_problem().empty())
    throw Error(target.string() + ": cannot write: " + msgs.write_problem(w, tmp.string()));
}

}  // namespace

vtkSmartPointer<vtkPolyData> correspondence_polydata(const ColonRegistration& reg, Direction d) {
  const bool forward = d == Direction::kSupineToProne;
  const ColonScan& from = forward ? reg.supine() : reg.prone();
  const ColonScan& to = forward ? reg.prone() : reg.supine();
  const ScanCoordinates& c = forward ? reg.supine_coordinates() : reg.prone_coordinates();
  const std::vector<int>& map = forward ? reg.supine_to_prone() : reg.prone_to_supine();
  const std::string other = forward ? "prone" : "supine";
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->ShallowCopy(from.flat);
  const vtkIdType n = vtkIdType(from.lps.size());
  vtkNew<vtkIntArray> vertex;
  vertex->SetName((other + "_vertex").c_str());
  vertex->SetNumberOfTuples(n);
  auto flat = double_array(other + "_flat_mm", 3, n), lps = double_array(other + "_position_lps_mm", 3, n);
  auto s = double_array("register_s_mm", 1, n), theta = double_array("register_angle_rad", 1, n);
  auto gap = double_array("register_gap_mm", 1, n);  // mm along to supported alignment (0 = supported)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (vtkIdType v = 0; v < n; ++v) {
    const int w = map[size_t(v)];
    vertex->SetValue(v, w);
    if (w >= 0) {
      flat->SetTuple3(v, to.uv[size_t(w)].x(), to.uv[size_t(w)].y(), 0.0);
      lps->SetTuple(v, to.lps[size_t(w)].data());
    } else {
      flat->SetTuple3(v, nan, nan, nan);
      lps->SetTuple3(v, nan, nan, nan);
    }
    s->SetValue(v, c.s[size_t(v)]);
    theta->SetValue(v, c.theta[size_t(v)]);
    gap->SetValue(v, reg.support_gap_mm(forward, c.s[size_t(v)]));
  }
  for (vtkAbstractArray* a : std::initializer_list<vtkAbstractArray*>{vertex, flat, lps, s, theta, gap})
    pd->GetPointData()->AddArray(a);
  vtkNew<vtkStringArray> note;
  note->SetName("Registration");
  note->InsertNextValue(nlohmann::json{{"direction", forward ? "supine_to_prone" : "prone_to_supine"},
                                       {"units", "mm"}, {"coordinate_system", "LPS"},
                                       {"other_scan", to.name}}.dump());
  pd->GetFieldData()->AddArray(note);
  return pd;
}

void stage_registration(const ColonRegistration& reg, const fs::path& dir, const SideBySideOptions& image,
                        const nlohmann::json& params, OutputTransaction& tx) {
  nlohmann::json j = reg.summary();
  j["parameters"] = params;
  j["files"] = {{"supine_to_prone", "supine_to_prone.vtp"}, {"prone_to_supine", "prone_to_supine.vtp"},
                {"image", "supine_prone.png"}};
  Stopwatch clock;
  auto png = render_side_by_side(reg, image);
  j["timing_s"]["image_s"] = clock.seconds();
  auto forward = correspondence_polydata(reg, Direction::kSupineToProne);
  auto backward = correspondence_polydata(reg, Direction::kProneToSupine);
  write_vtp(forward, tx.stage(dir / "supine_to_prone.vtp"), dir / "supine_to_prone.vtp");
  write_vtp(backward, tx.stage(dir / "prone_to_supine.vtp"), dir / "prone_to_supine.vtp");
  png_image_artifact().write(std::any(ImagePtr(png)), tx.stage(dir / "supine_prone.png"), dir / "supine_prone.png");
  j["timing_s"]["image_and_files_s"] = clock.seconds();
  std::ofstream(tx.stage(dir / "registration.json")) << j.dump(1) << "\n";
}

void write_registration(const ColonRegistration& reg, const fs::path& dir, const SideBySideOptions& image,
                        const nlohmann::json& params) {
  std::error_code ec;
  const bool created = !fs::exists(dir);
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create folder: " + ec.message());
  try {
    OutputTransaction tx;
    stage_registration(reg, dir, image, params, tx);
    tx.commit();
  } catch (...) {
    if (created) fs::remove_all(dir, ec);
    throw;
  }
}

}  // namespace cf
