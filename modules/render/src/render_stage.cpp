#include "colonflat/render/render_stage.h"

#include <vtkImageData.h>
#include <vtkPolyData.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/topology.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/render/snapshot.h"

#ifdef COLONFLAT_RENDER_HAVE_DENOISE
#include "colonflat/core/atomic_file.h"
#include "colonflat/denoise/loops_io.h"
#endif

namespace cf {

namespace {

std::string fmt(double v, int prec = 1) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

// Local length scale 2D/3D around flat vertex v (sqrt of the area ratio of its triangles).
double local_scale(const FlatMap& f, const std::vector<std::vector<int>>& vf, int v) {
  double a2 = 0, a3 = 0;
  for (int t : vf[v]) {
    const auto& T = f.triangles[t];
    auto p = [&](int i, int k) { return f.position[T[i]][k]; };
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) e1[k] = p(1, k) - p(0, k), e2[k] = p(2, k) - p(0, k);
    const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    a3 += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    const auto &q0 = f.uv[T[0]], &q1 = f.uv[T[1]], &q2 = f.uv[T[2]];
    a2 += 0.5 * std::abs((q1[0] - q0[0]) * (q2[1] - q0[1]) - (q1[1] - q0[1]) * (q2[0] - q0[0]));
  }
  return a3 > 0 ? std::sqrt(a2 / a3) : 1.0;
}

}  // namespace

RenderResult render_flat(const FlatMap& flat, const RenderOptions& o) {
  RenderResult r;
  std::vector<int> f2s;
  const TriangleList surf = flat_to_surface(flat, &f2s);
  std::vector<std::array<double, 3>> normals(surf.points.size());
  std::vector<int> s2f(surf.points.size(), -1);
  for (std::size_t i = 0; i < f2s.size(); ++i) {
    normals[f2s[i]] = flat.normal[i];
    if (s2f[f2s[i]] < 0) s2f[f2s[i]] = int(i);
  }
  std::vector<std::vector<int>> vf(flat.uv.size());
  for (std::size_t t = 0; t < flat.triangles.size(); ++t)
    for (int v : flat.triangles[t]) vf[v].push_back(int(t));
  PolypOptions po;
  po.fit_radius = o.fit_radius;
  po.min_size = o.min_size;
  po.min_score = o.min_score;
  po.seed_si = o.seed_si;
  po.grow_si = std::min(po.grow_si, o.seed_si);
  Curvature curv;
  if (o.detect) r.candidates = detect_polyps(surf, normals, po, &curv);
  else if (o.color == "curvature") curv = surface_curvature(surf, normals, o.fit_radius);
  std::vector<double> si_flat;
  if (!curv.si.empty()) {
    si_flat.resize(flat.uv.size());
    for (std::size_t i = 0; i < f2s.size(); ++i) si_flat[i] = curv.si[f2s[i]];
  }
  for (const auto& c : r.candidates) {
    const int fv = s2f[c.vertex];
    ImageMarker m;
    m.id = c.id;
    m.segment = flat.segment[fv];
    m.x = flat.uv[fv][0];
    m.y = flat.uv[fv][1];
    m.radius_mm = 0.5 * c.size_mm * local_scale(flat, vf, fv);
    m.label = "P" + std::to_string(c.id) + " " + fmt(c.size_mm, 0) + " mm";
    r.markers.push_back(m);
  }
  std::vector<KnownPolyp> known;
  std::vector<double> known_dist;
  if (!o.known_polyps.empty()) {
    known = read_known_polyps(o.known_polyps);
    for (const auto& k : known) {
      int best = 0;
      double bd = kInf;
      for (std::size_t i = 0; i < flat.position.size(); ++i) {
        const auto& p = flat.position[i];
        const double d = (p[0] - k.center_lps_mm[0]) * (p[0] - k.center_lps_mm[0]) +
                         (p[1] - k.center_lps_mm[1]) * (p[1] - k.center_lps_mm[1]) +
                         (p[2] - k.center_lps_mm[2]) * (p[2] - k.center_lps_mm[2]);
        if (d < bd) bd = d, best = int(i);
      }
      known_dist.push_back(std::sqrt(bd));
      ImageMarker m;
      m.id = k.id;
      m.known = true;
      m.segment = flat.segment[best];
      m.x = flat.uv[best][0];
      m.y = flat.uv[best][1];
      m.radius_mm = 0.5 * std::max(k.diameter_mm, 4.0) * local_scale(flat, vf, best) + 1.5;
      m.label = "K" + std::to_string(k.id) + (k.diameter_mm > 0 ? " " + fmt(k.diameter_mm, 0) + " mm" : "");
      r.markers.push_back(m);
    }
  }
  ColonImageOptions io;
  io.pixel_size = o.pixel_size;
  io.color = o.color;
  io.smooth_normal = o.smooth_normal;
  r.colon = render_colon_image(flat, si_flat, r.markers, io);
  nlohmann::json cj = nlohmann::json::array();
  std::size_t mi = 0;
  for (const auto& c : r.candidates) {
    const ImageMarker& m = r.markers[mi++];
    cj.push_back({{"id", c.id},
                  {"center_lps_mm", c.center_lps_mm},
                  {"flat_mm", {m.x, m.y}},
                  {"segment", m.segment},
                  {"pixel", {m.px, m.py}},
                  {"size_mm", c.size_mm},
                  {"score", c.score},
                  {"shape_index", c.mean_si},
                  {"curvedness_per_mm", c.mean_cv},
                  {"cap_area_mm2", c.cap_area_mm2},
                  {"elongation", c.elongation},
                  {"footprint_area_mm2", c.footprint_area_mm2}});
  }
  nlohmann::json kj = nlohmann::json::array();
  for (std::size_t i = 0; i < known.size(); ++i) {
    const ImageMarker& m = r.markers[mi++];
    kj.push_back({{"id", known[i].id},
                  {"center_lps_mm", known[i].center_lps_mm},
                  {"diameter_mm", known[i].diameter_mm},
                  {"distance_to_surface_mm", known_dist[i]},
                  {"flat_mm", {m.x, m.y}},
                  {"segment", m.segment},
                  {"pixel", {m.px, m.py}}});
  }
  r.candidates_json = {{"units", "mm"},
                       {"coordinate_system", "LPS"},
                       {"image", {{"width", r.colon.width}, {"height", r.colon.height},
                                  {"pixel_size_mm", r.colon.pixel_size},
                                  {"pixel_origin", "column, row from the top-left corner"}}},
                       {"candidates", cj},
                       {"known_polyps", kj}};
  if (!o.known_polyps.empty()) {
    const DetectionScore sc = score_detections(r.candidates, known);
    r.candidates_json["score_vs_known"] = {{"polyps_ge_6mm", sc.polyps},
                                           {"detected", sc.polyps_detected},
                                           {"sensitivity", sc.sensitivity},
                                           {"false_positives", sc.false_positives},
                                           {"missed_ids", sc.missed_ids}};
  }
  return r;
}

const StageSpec& RenderStage::spec() const {
  static const StageSpec s{
      "render",
      "2D colon-wall image with polyp candidates, candidate JSON, 3D snapshots",
      {{"flat", &flat_artifact(), "flat colon map (from flatten)", "flat.vtp"},
       {"surface", &mesh_artifact(), "surface before denoising (snapshot)", "surface.vtp", false},
       {"loops", &polylines_artifact(), "cut loops of denoise (snapshot)", "loops.vtp", false},
       {"denoised", &mesh_artifact(), "surface after denoising (snapshot)", "denoised.vtp", false}},
      {{"colon_image", &png_image_artifact(), "2D colon-wall image", "colon.png"},
       {"candidates", &json_artifact(), "polyp candidates (3D and 2D positions, size, score)", "candidates.json"},
       {"snapshot_before", &png_image_artifact(), "3D snapshot of the surface before denoising, loops highlighted",
        "snapshot_before.png", false},
       {"snapshot_after", &png_image_artifact(), "3D snapshot of the surface after denoising, loops highlighted",
        "snapshot_after.png", false}}};
  return s;
}

const ParamTable<RenderOptions>& RenderStage::table() const {
  static const ParamTable<RenderOptions> t = [] {
    ParamTable<RenderOptions> t;
    t.real("pixel-size", &RenderOptions::pixel_size, "mm", "pixel size of the colon image", 0.15, 10);
    t.choice("color", &RenderOptions::color, {"shading", "curvature"},
             "colon image colouring: shading (virtual dissection) or curvature (shape index) on top");
    t.real("smooth-normal", &RenderOptions::smooth_normal, "mm", "scale of the reference normal for shading", 0.5, 100);
    t.text("known-polyps", &RenderOptions::known_polyps,
           "JSON list of known polyp positions (LPS mm; {center_lps_mm, diameter_mm, id} or [x,y,z]) to overlay");
    t.flag("detect", &RenderOptions::detect, "detect polyp candidates (shape index, curvedness, region growing)");
    t.flag("snapshots", &RenderOptions::snapshots, "render 3D snapshots off-screen (X display or Xvfb)");
    t.integer("snapshot-size", &RenderOptions::snapshot_size, "px", "snapshot width and height", 64, 4096);
    t.real("fit-radius", &RenderOptions::fit_radius, "mm", "neighbourhood of the curvature fit", 0.3, 20);
    t.real("min-size", &RenderOptions::min_size, "mm", "smallest candidate diameter reported", 0, 100);
    t.real("min-score", &RenderOptions::min_score, "", "smallest candidate score reported", 0, 1);
    t.real("seed-si", &RenderOptions::seed_si, "", "shape index of candidate seeds", 0, 1);
    return t;
  }();
  return t;
}

void RenderStage::run(ArtifactBag& bag, RunContext& ctx) {
  const FlatMap& flat = bag.get<FlatMap>("flat");
  Stopwatch sw;
  RenderResult r = render_flat(flat, opts_);
  phase_done("colon image and candidates");
  ctx.report["colon_image"] = {{"width", r.colon.width}, {"height", r.colon.height}, {"pixel_size_mm", r.colon.pixel_size}};
  ctx.report["candidates"] = r.candidates.size();
  if (r.candidates_json.contains("score_vs_known")) ctx.report["score_vs_known"] = r.candidates_json["score_vs_known"];
  ctx.report["image_time_s"] = sw.seconds();
  ctx.progress("render: colon image " + std::to_string(r.colon.width) + " x " + std::to_string(r.colon.height) +
               " px, " + std::to_string(r.candidates.size()) + " polyp candidates");
  bag.put("colon_image", r.colon.image);
  bag.put("candidates", r.candidates_json);
  if (!opts_.snapshots) return;
  try {
    PolylinesPtr loops;
    if (bag.has("loops")) {
      if (const auto* lp = std::any_cast<PolylinesPtr>(&bag.raw("loops"))) loops = *lp;
#ifdef COLONFLAT_RENDER_HAVE_DENOISE
      else if (const auto* ls = std::any_cast<LoopSet>(&bag.raw("loops"))) {
        // through denoise's writer and our reader: exactly what `colonflat render --loops` sees
        const auto tmp = temp_sibling(std::filesystem::temp_directory_path() / "colonflat_render_loops.vtp");
        write_loops(*ls, tmp);
        try {
          loops = std::any_cast<PolylinesPtr>(polylines_artifact().read(tmp));
        } catch (...) {
          std::filesystem::remove(tmp);
          throw;
        }
        std::filesystem::remove(tmp);
      }
#endif
      else ctx.report["snapshot_note"] = "loops artifact of another type: not drawn";
    }
    SnapshotOptions so;
    so.width = so.height = opts_.snapshot_size;
    if (bag.has("surface")) {
      const Mesh& m = bag.get<Mesh>("surface");
      const auto topo = analyze_topology(m);
      so.caption = "before denoising: genus " + (topo.genus ? std::to_string(*topo.genus) : std::string("?")) +
                   (loops ? ", " + std::to_string(loops->GetNumberOfCells()) + " cut loops" : std::string());
      bag.put("snapshot_before", render_snapshot(to_triangle_list(m), loops, so));
      phase_done("3D snapshot before denoising");
    }
    TriangleList after = bag.has("denoised") ? to_triangle_list(bag.get<Mesh>("denoised")) : flat_to_surface(flat);
    so.caption = std::string(bag.has("denoised") ? "after denoising" : "flattened surface") + ", " +
                 std::to_string(r.candidates.size()) + " polyp candidates" +
                 (loops ? ", cut loops highlighted" : std::string());
    bag.put("snapshot_after", render_snapshot(after, loops, so));
    phase_done("3D snapshot after denoising");
    ctx.report["display"] = ensure_display();
  } catch (const Error& e) {
    ctx.report["snapshot_error"] = e.what();
    ctx.progress(std::string("render: no 3D snapshots: ") + e.what());
  }
}

std::unique_ptr<Stage> make_render_stage() { return std::make_unique<RenderStage>(); }

}  // namespace cf
