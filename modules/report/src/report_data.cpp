#include "colonflat/report/report_data.h"

#include <vtkImageData.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "colonflat/core/error.h"

#include "colonflat/report/ct_views.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

int tenths(double v) { return int(std::lround(v * 10)); }

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// The finding of the other kind that matches `f` (candidate within known diameter/2 + 5 mm of a
// known polyp, the rule of render's score_detections), or null.
nlohmann::json match_of(const RunData& run, const ReportFinding& f) {
  const auto& others = f.known ? run.candidates : run.known;
  const ReportFinding* best = nullptr;
  double best_d = 0;
  for (const auto& o : others) {
    const double d = distance(f.lps_mm, o.lps_mm);
    const double reach = 0.5 * (f.known ? f.size_mm : o.size_mm) + 5.0;
    if (d <= reach && (!best || d < best_d)) best = &o, best_d = d;
  }
  if (!best) return nullptr;
  return {{"key", best->key}, {"distance_mm", std::round(best_d * 10) / 10}};
}

void write_crop(vtkImageData* rgb, double cx, double cy_top, int side, const fs::path& path) {
  int ext[6];
  rgb->GetExtent(ext);
  const int W = ext[1] - ext[0] + 1, H = ext[3] - ext[2] + 1;
  vtkNew<vtkImageData> out;
  out->SetDimensions(side, side, 1);
  out->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* dst = static_cast<unsigned char*>(out->GetScalarPointer());
  const auto* src = static_cast<const unsigned char*>(rgb->GetScalarPointer());
  const int c0 = int(std::lround(cx)) - side / 2, r0 = int(std::lround(cy_top)) - side / 2;
  for (int r = 0; r < side; ++r)
    for (int c = 0; c < side; ++c) {
      const int sc = c0 + c, sr_top = r0 + r;
      unsigned char* d = dst + (std::size_t(side - 1 - r) * side + c) * 3;
      if (sc < 0 || sc >= W || sr_top < 0 || sr_top >= H) {
        d[0] = d[1] = d[2] = 28;
        continue;
      }
      const unsigned char* s = src + (std::size_t(H - 1 - sr_top) * W + sc) * 3;
      d[0] = s[0], d[1] = s[1], d[2] = s[2];
    }
  write_png(out, path);
}

}  // namespace

double colon_image_pixel_size(const RunData& run) {
  if (run.run_report.contains("stages"))
    for (const auto& s : run.run_report["stages"])
      if (s.value("stage", "") == "render" && s.contains("result") && s["result"].contains("colon_image"))
        return s["result"]["colon_image"].value("pixel_size_mm", 0.5);
  if (run.candidates_doc.contains("image")) return run.candidates_doc["image"].value("pixel_size_mm", 0.5);
  return 0.5;
}

nlohmann::json lookup_json(const RunData& run, const LookupGrid& grid) {
  std::vector<int> cells;
  cells.reserve(grid.vertex.size() * 5);
  for (int v : grid.vertex) {
    if (v < 0) {
      cells.insert(cells.end(), {-1, 0, 0, 0, 0});
      continue;
    }
    const ColonPosition p = colon_position(run, v);
    const auto& lps = run.flat->position[v];
    cells.insert(cells.end(), {p.segment, tenths(p.mm), tenths(lps[0]), tenths(lps[1]), tenths(lps[2])});
  }
  return {{"step_px", grid.step_px}, {"cols", grid.cols}, {"rows", grid.rows}, {"cells", cells}};
}

nlohmann::json finding_json(const RunData& run, const ReportFinding& f, const ColonImageLayout* layout) {
  nlohmann::json j = {{"key", f.key},
                      {"id", f.id},
                      {"known", f.known},
                      {"lps_mm", {std::round(f.lps_mm[0] * 10) / 10, std::round(f.lps_mm[1] * 10) / 10,
                                  std::round(f.lps_mm[2] * 10) / 10}},
                      {"size_mm", std::round(f.size_mm * 10) / 10},
                      {"match", match_of(run, f)}};
  if (!f.known) j["score"] = std::round(f.score * 1000) / 1000;
  if (!f.type.empty()) j["type"] = f.type;
  if (f.flat_vertex >= 0 && run.flat) {
    const ColonPosition p = colon_position(run, f.flat_vertex);
    j["segment"] = p.segment;
    j["along_mm"] = std::round(p.mm * 10) / 10;
    j["from"] = p.from;
    j["surface_distance_mm"] = std::round(f.surface_distance_mm * 10) / 10;
    if (layout) {
      const auto& uv = run.flat->uv[f.flat_vertex];
      const auto px = layout->to_pixel(p.segment, uv[0], uv[1]);
      j["pixel"] = {std::round(px[0] * 10) / 10, std::round(px[1] * 10) / 10};
    }
  }
  return j;
}

int write_finding_images(const RunData& run, const ReportFinding& f, const ReportOptions& o, const fs::path& dir,
                         vtkImageData* colon_image, EndoluminalRenderer* endo, nlohmann::json& fj) {
  int written = 0;
  const std::string rel = "report_files/";
  if (has_ct(run) || run.mask) {
    const double fov = std::clamp(o.fov_per_size * f.size_mm, o.min_fov_mm, o.max_fov_mm);
    fj["fov_mm"] = std::round(fov * 10) / 10;
    // A CT in the lung and soft-tissue windows; a mask (no CT) once, in the mask window.
    std::vector<std::pair<const CtWindow*, std::string>> windows = {{&lung_window(), "lung"},
                                                                    {&soft_tissue_window(), "soft"}};
    if (run.volume_is_mask) windows = {{&mask_window(), "mask"}};
    for (Plane plane : {Plane::axial, Plane::coronal, Plane::sagittal}) {
      const PlaneImage im = with_view_volume(
          run, [&](const auto* volume) { return sample_plane_around(volume, plane, f.lps_mm, fov, o.tile_pixels); });
      for (const auto& [window, key] : windows) {
        const std::string name = f.key + "_" + plane_name(plane) + "_" + key + ".png";
        write_windowed_png(im, *window, dir / name);
        fj["ct"][plane_name(plane)][key] = rel + name;
        ++written;
      }
    }
  }
  if (colon_image && fj.contains("pixel")) {
    const std::string name = f.key + "_flat.png";
    write_crop(colon_image, fj["pixel"][0].get<double>(), fj["pixel"][1].get<double>(), o.thumbnail_pixels,
               dir / name);
    fj["flat_thumbnail"] = rel + name;
    ++written;
  }
  if (endo && f.flat_vertex >= 0) {
    double d = 0;
    const std::string name = f.key + "_endoluminal.png";
    write_png(endo->render(f.lps_mm, run.flat->normal[f.flat_vertex], &d), dir / name);
    fj["endoluminal"] = rel + name;
    fj["endoluminal_distance_mm"] = std::round(d * 10) / 10;
    ++written;
  }
  return written;
}

ImagePtr colon_image_of(const RunData& run) {
  if (run.colon_image) return run.colon_image;
  if (!run_has_file(run, "colon.png")) return nullptr;
  return read_png(run.dir / "colon.png");
}

std::optional<ColonImageLayout> colon_image_layout(const RunData& run, vtkImageData* colon, std::string* problem) {
  if (!run.flat || !colon) return std::nullopt;
  int dims[3];
  colon->GetDimensions(dims);
  std::optional<ColonImageLayout> layout;
  layout.emplace(*run.flat, colon_image_pixel_size(run), std::numeric_limits<int>::max());
  const nlohmann::json cands = run.candidates_doc.value("candidates", nlohmann::json::array());
  layout->set_rolls_from_candidates(cands);
  const std::string differs = layout->check(dims[0], dims[1], cands);
  if (differs.empty()) return layout;
  if (problem) *problem = differs;
  return std::nullopt;
}

std::unique_ptr<EndoluminalRenderer> make_endoluminal_renderer(const RunData& run, int pixels,
                                                               std::vector<std::string>& warnings) {
  if (!run.flat) return nullptr;
  try {
    std::vector<int> flat_to_3d;
    const TriangleList surface = flat_to_surface(*run.flat, &flat_to_3d);
    std::vector<std::array<double, 3>> normals(surface.points.size());
    for (std::size_t i = 0; i < flat_to_3d.size(); ++i) normals[flat_to_3d[i]] = run.flat->normal[i];
    EndoluminalOptions eo;
    eo.size = pixels;
    return std::make_unique<EndoluminalRenderer>(surface, normals, eo);
  } catch (const Error& e) {
    warnings.push_back(std::string("no endoluminal views: ") + e.what());
    return nullptr;
  }
}

nlohmann::json summary_json(const RunData& run) {
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& s : run.run_report.value("stages", nlohmann::json::array()))
    stages.push_back({{"stage", s.value("stage", "?")},
                      {"time_s", s.value("time_s", 0.0)},
                      {"peak_memory_mib", s.value("peak_memory_mib", 0.0)},
                      {"result", s.value("result", nlohmann::json::object())}});
  nlohmann::json snapshots = nlohmann::json::array();
  for (const char* name : {"snapshot_before.png", "snapshot_after.png"})
    if (run_has_file(run, name)) snapshots.push_back(name);
  nlohmann::json j = {{"stages", stages},
                      {"total_time_s", run.run_report.value("total_time_s", 0.0)},
                      {"peak_memory_mib", run.run_report.value("peak_memory_mib", 0.0)},
                      {"input", run.run_report.value("input", "")},
                      {"version", run.run_report.value("version", "")},
                      {"snapshots", snapshots},
                      {"warnings", run.warnings},
                      {"segments", run.flat_segments}};
  if (run.run_report.contains("not_run")) j["not_run"] = run.run_report["not_run"];
  if (run.candidates_doc.contains("score_vs_known")) j["score_vs_known"] = run.candidates_doc["score_vs_known"];
  return j;
}

}  // namespace cf
