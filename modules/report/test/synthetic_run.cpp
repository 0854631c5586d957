#include "synthetic_run.h"

#include <cmath>
#include <fstream>

#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/render/render_stage.h"

#include <vtkImageData.h>

namespace fs = std::filesystem;

namespace cf::testing {

CtImage::Pointer ball_ct(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                         const std::array<double, 3>& centre) {
  auto ct = CtImage::New();
  CtImage::SizeType size;
  CtImage::PointType origin;
  CtImage::SpacingType spacing;
  for (int k = 0; k < 3; ++k) {
    origin[k] = std::floor(lo[k]) - 15;
    spacing[k] = 1.0;
    size[k] = std::size_t(std::ceil(hi[k] - lo[k])) + 31;
  }
  ct->SetRegions(CtImage::RegionType(size));
  ct->SetOrigin(origin);
  ct->SetSpacing(spacing);
  ct->Allocate();
  ct->FillBuffer(-1000.0f);
  const std::array<std::array<double, 3>, 3> balls = {
      centre, std::array<double, 3>{centre[0] + 12, centre[1], centre[2]},
      std::array<double, 3>{centre[0], centre[1], centre[2] + 12}};
  for (const auto& b : balls) {
    CtImage::IndexType c;
    for (int k = 0; k < 3; ++k) c[k] = std::lround(b[k] - origin[k]);
    for (int dz = -3; dz <= 3; ++dz)
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          if (dx * dx + dy * dy + dz * dz > 2.25) continue;  // radius 1.5 mm
          CtImage::IndexType i = {{c[0] + dx, c[1] + dy, c[2] + dz}};
          if (ct->GetLargestPossibleRegion().IsInside(i)) ct->SetPixel(i, 1000.0f);
        }
  }
  return ct;
}

namespace {

// Two colon segments side by side (the second 90 mm to patient left), each with two polyps.
synthetic::Colon two_segment_colon(std::vector<synthetic::ColonPolyp>& polyps) {
  synthetic::ColonOptions o;
  o.length = 200;
  o.radius = 16;
  o.spacing = 1.0;
  o.polyps = {{50, 0.3, 9}, {140, 3.0, 10}};
  synthetic::Colon a = synthetic::colon(o);
  o.polyps = {{70, 5.0, 8}, {150, 1.5, 11}};
  synthetic::Colon b = synthetic::colon(o);
  const int offset = int(a.mesh.points.size());
  for (auto p : b.mesh.points) a.mesh.points.push_back({p[0] + 90, p[1], p[2]});
  for (auto t : b.mesh.triangles) a.mesh.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  polyps = a.polyps;
  for (auto p : b.polyps) {
    p.center[0] += 90;
    p.id += int(a.polyps.size());
    polyps.push_back(p);
  }
  return a;
}

void write_json(const fs::path& p, const nlohmann::json& j) { std::ofstream(p) << j.dump(2) << "\n"; }

}  // namespace

SyntheticRun make_synthetic_run(const fs::path& dir) {
  SyntheticRun run;
  run.dir = dir;
  fs::create_directories(dir / "phantom");
  std::vector<synthetic::ColonPolyp> polyps;
  const synthetic::Colon colon = two_segment_colon(polyps);
  const FlatMap flat = flatten_colon(colon.mesh);
  write_flat(flat, dir / "flat.vtp");
  RenderOptions ro;
  ro.snapshots = false;
  const RenderResult rr = render_flat(flat, ro);
  write_png(rr.colon.image, dir / "colon.png");
  run.candidates = rr.candidates_json;
  write_json(dir / "candidates.json", run.candidates);
  const auto top = candidates_from_json(run.candidates, "candidates.json").at(0);
  run.top_candidate = top.lps_mm;
  std::array<double, 3> lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
  for (const auto& p : flat.position)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  write_ct_volume(ball_ct(lo, hi, run.top_candidate), dir / "phantom" / "ct.nrrd");
  nlohmann::json truth = nlohmann::json::array();
  for (const auto& p : polyps)
    truth.push_back({{"id", p.id}, {"center_lps_mm", p.center}, {"diameter_mm", p.diameter}, {"type", "sessile"}});
  write_json(dir / "phantom" / "polyps.json", truth);
  write_json(dir / "phantom" / "phantom.json", {{"generator", "report test"}});
  run.known_polyps = int(polyps.size());
  const nlohmann::json render_result = {{"colon_image", {{"pixel_size_mm", rr.colon.pixel_size}}},
                                        {"candidates", rr.candidates.size()}};
  write_json(dir / "run_report.json",
             {{"version", "test"},
              {"input", fs::absolute(dir / "phantom" / "ct.nrrd").string()},
              {"units", "mm"},
              {"coordinate_system", "LPS"},
              {"stages", {{{"stage", "render"}, {"time_s", 1.5}, {"peak_memory_mib", 100}, {"result", render_result}}}},
              {"total_time_s", 10.0},
              {"peak_memory_mib", 120}});
  return run;
}

}  // namespace cf::testing
