// `colonflat info` on ColonFlat's own outputs: loops.vtp (polylines, no faces) and flat.vtp (an
// open flat map with FlatSegments field data). Masks are recognised by the volume module.
#include <vtkAbstractArray.h>
#include <vtkCellArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "colonflat/core/library_output.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/vtk_messages.h"
#include "info_outputs.h"

namespace cf {
namespace {

std::string field_string(vtkPolyData* pd, const char* name) {
  auto* a = vtkStringArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray(name));
  return a && a->GetNumberOfValues() > 0 ? a->GetValue(0) : std::string();
}

nlohmann::json loops_info(vtkPolyData* pd) {
  nlohmann::json lengths = nlohmann::json::array();
  double total = 0;
  vtkNew<vtkIdList> ids;
  vtkCellArray* lines = pd->GetLines();
  lines->InitTraversal();
  while (lines->GetNextCell(ids)) {
    double len = 0, a[3], b[3];
    for (vtkIdType k = 1; k < ids->GetNumberOfIds(); ++k) {
      pd->GetPoint(ids->GetId(k - 1), a);
      pd->GetPoint(ids->GetId(k), b);
      len += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
    lengths.push_back(len);
    total += len;
  }
  return {{"kind", "loops"}, {"loops", lengths.size()}, {"points", pd->GetNumberOfPoints()},
          {"length_mm", lengths}, {"total_length_mm", total}, {"units", field_string(pd, "Units")},
          {"coordinate_system", field_string(pd, "CoordinateSystem")}};
}

// FlatSegments is {"segments": [...], "coverage": {...}, ...} (flatten's flat_io); files from before
// issue 11 hold the bare segment array.
nlohmann::json flat_info(const nlohmann::json& flat) {
  const nlohmann::json& segs = flat.is_object() && flat.contains("segments") ? flat["segments"] : flat;
  nlohmann::json rows = nlohmann::json::array();
  if (segs.is_array())
    for (const auto& s : segs)
      rows.push_back({{"id", s.value("id", -1)}, {"kind", s.value("kind", "colon")},
                      {"length_mm", s.contains("rectangle_mm") ? s["rectangle_mm"].value("length", 0.0) : 0.0},
                      {"around_mm", s.contains("rectangle_mm") ? s["rectangle_mm"].value("period", 0.0) : 0.0},
                      {"x0_end", s.value("x0_end", "")}, {"x1_end", s.value("x1_end", "")}});
  nlohmann::json info = {{"kind", "flat map"}, {"segments", rows.size()}, {"segment_list", rows}};
  if (flat.is_object() && flat.contains("coverage") && flat["coverage"].contains("fraction_shown"))
    info["fraction_shown"] = flat["coverage"]["fraction_shown"];
  return info;
}

}  // namespace

OwnOutput inspect_own_output(const std::string& file) {
  OwnOutput out;
  if (mesh_format_from_path(file) != MeshFormat::kVTP) return out;
  LibraryOutputCapture printed;  // VTK's logger prints to stderr besides the output window
  VtkMessageCapture quiet;
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  if (reader->GetErrorCode() != 0 || !quiet.errors().empty() || !pd) return out;
  if (pd->GetNumberOfPolys() == 0 && pd->GetNumberOfLines() > 0) {
    out.kind = OwnKind::kLoops;
    out.info = loops_info(pd);
  } else if (!field_string(pd, "FlatSegments").empty()) {
    out.kind = OwnKind::kFlat;
    out.info = flat_info(nlohmann::json::parse(field_string(pd, "FlatSegments"), nullptr, false));
    out.info["units"] = field_string(pd, "Units");
    out.info["coordinate_system"] = field_string(pd, "CoordinateSystem");
  }
  return out;
}

std::string own_output_text(const OwnOutput& o) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  if (o.kind == OwnKind::kLoops) {
    s << "ColonFlat loops (cut loops of denoise): " << o.info["loops"] << " closed polylines, "
      << o.info["points"] << " points, total length " << o.info["total_length_mm"].get<double>() << " mm\n";
    std::size_t i = 0;
    for (const auto& l : o.info["length_mm"]) {
      if (i == 20) {
        s << "  ... " << (o.info["loops"].get<std::size_t>() - 20) << " more (see --json)\n";
        break;
      }
      s << "  loop " << i++ << ": " << l.get<double>() << " mm\n";
    }
  } else if (o.kind == OwnKind::kFlat) {
    s << "ColonFlat flat map: " << o.info["segments"] << " segment(s); x, y in mm (an open surface: boundary "
      << "loops are expected)\n";
    if (o.info.contains("fraction_shown"))
      s << "  wall shown: " << 100.0 * o.info["fraction_shown"].get<double>() << " %\n";
    for (const auto& r : o.info["segment_list"]) {
      s << "  segment " << r["id"] << " (" << r["kind"].get<std::string>() << ")";
      if (r["length_mm"].get<double>() > 0)
        s << ": " << r["length_mm"].get<double>() << " x " << r["around_mm"].get<double>() << " mm";
      if (!r["x0_end"].get<std::string>().empty())
        s << ", " << r["x0_end"].get<std::string>() << " -> " << r["x1_end"].get<std::string>();
      s << "\n";
    }
  }
  return s.str();
}

}  // namespace cf
