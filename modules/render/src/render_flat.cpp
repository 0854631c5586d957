// render_flat(): polyp candidates on the 3D wall, the markers they and the known polyps get on the
// colon image, the image itself, and the candidate JSON, as named steps of one FlatRenderer.
#include <vtkImageData.h>

#include <cmath>
#include <iomanip>
#include <sstream>

#include "colonflat/core/params.h"
#include "colonflat/render/render_stage.h"

namespace cf {
namespace {

std::string fmt(double v, int prec = 1) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

class FlatRenderer {
 public:
  FlatRenderer(const FlatMap& flat, const RenderOptions& opts) : flat_(flat), opts_(opts) {}
  RenderResult run();

 private:
  void map_surface();
  void detect_candidates();
  void mark_candidates();
  void mark_known_polyps();
  int nearest_flat_vertex(const std::array<double, 3>& lps, double* distance_squared) const;
  double local_scale(int flat_vertex) const;
  void render_image();
  nlohmann::json candidates_json(std::size_t* marker) const;
  nlohmann::json known_json(std::size_t* marker) const;
  void write_json();

  const FlatMap& flat_;
  const RenderOptions& opts_;
  RenderResult result_;
  TriangleList surface_;                            // the 3D wall, shared vertices merged
  std::vector<int> flat_to_surface_;                // flat vertex -> surface vertex
  std::vector<int> surface_to_flat_;                // surface vertex -> its first flat vertex
  std::vector<std::array<double, 3>> normals_;      // per surface vertex, outward
  std::vector<double> shape_index_flat_;            // per flat vertex (empty without curvature)
  std::vector<KnownPolyp> known_;
  std::vector<double> known_distance_;              // known polyp centre -> nearest wall vertex (mm)
};

RenderResult FlatRenderer::run() {
  map_surface();
  detect_candidates();
  mark_candidates();
  if (!opts_.known_polyps.empty()) mark_known_polyps();
  render_image();
  write_json();
  return std::move(result_);
}

// The flat map's 3D wall as one surface (cut vertices merged), with the links both ways.
void FlatRenderer::map_surface() {
  surface_ = flat_to_surface(flat_, &flat_to_surface_);
  normals_.resize(surface_.points.size());
  surface_to_flat_.assign(surface_.points.size(), -1);
  for (std::size_t i = 0; i < flat_to_surface_.size(); ++i) {
    normals_[flat_to_surface_[i]] = flat_.normal[i];
    if (surface_to_flat_[flat_to_surface_[i]] < 0) surface_to_flat_[flat_to_surface_[i]] = int(i);
  }
}

// Candidates (when detect is on) and the shape index per flat vertex (for curvature colouring).
void FlatRenderer::detect_candidates() {
  PolypOptions po;
  po.fit_radius = opts_.fit_radius;
  po.min_size = opts_.min_size;
  po.min_score = opts_.min_score;
  po.seed_si = opts_.seed_si;
  po.grow_si = std::min(po.grow_si, opts_.seed_si);
  Curvature curv;
  if (opts_.detect) result_.candidates = detect_polyps(surface_, normals_, po, &curv);
  else if (opts_.color == "curvature") curv = surface_curvature(surface_, normals_, opts_.fit_radius);
  if (curv.si.empty()) return;
  shape_index_flat_.resize(flat_.uv.size());
  for (std::size_t i = 0; i < flat_to_surface_.size(); ++i) shape_index_flat_[i] = curv.si[flat_to_surface_[i]];
}

void FlatRenderer::mark_candidates() {
  for (const auto& c : result_.candidates) {
    const int fv = surface_to_flat_[c.vertex];
    ImageMarker m;
    m.id = c.id;
    m.segment = flat_.segment[fv];
    m.x = flat_.uv[fv][0];
    m.y = flat_.uv[fv][1];
    m.radius_mm = 0.5 * c.size_mm * local_scale(fv);
    m.label = "P" + std::to_string(c.id) + " " + fmt(c.size_mm, 0) + " mm";
    result_.markers.push_back(m);
  }
}

// Each known polyp at the wall vertex nearest to its centre, dashed, a little wider than the polyp.
void FlatRenderer::mark_known_polyps() {
  known_ = read_known_polyps(opts_.known_polyps);
  for (const auto& k : known_) {
    double distance_squared = kInf;
    const int best = nearest_flat_vertex(k.center_lps_mm, &distance_squared);
    known_distance_.push_back(std::sqrt(distance_squared));
    ImageMarker m;
    m.id = k.id;
    m.known = true;
    m.segment = flat_.segment[best];
    m.x = flat_.uv[best][0];
    m.y = flat_.uv[best][1];
    m.radius_mm = 0.5 * std::max(k.diameter_mm, 4.0) * local_scale(best) + 1.5;
    m.label = "K" + std::to_string(k.id) + (k.diameter_mm > 0 ? " " + fmt(k.diameter_mm, 0) + " mm" : "");
    result_.markers.push_back(m);
  }
}

int FlatRenderer::nearest_flat_vertex(const std::array<double, 3>& c, double* bd) const {
  int best = 0;
  for (std::size_t i = 0; i < flat_.position.size(); ++i) {
    const auto& p = flat_.position[i];
    const double d = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
    if (d < *bd) *bd = d, best = int(i);
  }
  return best;
}

// Local length scale 2D/3D around a flat vertex (sqrt of the area ratio of its triangles). Called
// once per marker, so its triangles are found by a scan rather than an index kept for every vertex.
double FlatRenderer::local_scale(int v) const {
  const FlatMap& f = flat_;
  double a2 = 0, a3 = 0;
  for (const auto& T : f.triangles) {
    if (T[0] != v && T[1] != v && T[2] != v) continue;
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

void FlatRenderer::render_image() {
  ColonImageOptions io;
  io.pixel_size = opts_.pixel_size;
  io.color = opts_.color;
  io.smooth_normal = opts_.smooth_normal;
  result_.colon = render_colon_image(flat_, shape_index_flat_, result_.markers, io);
}

// Markers are in order: candidates first, then known polyps; `marker` walks them.
nlohmann::json FlatRenderer::candidates_json(std::size_t* marker) const {
  nlohmann::json cj = nlohmann::json::array();
  for (const auto& c : result_.candidates) {
    const ImageMarker& m = result_.markers[(*marker)++];
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
  return cj;
}

nlohmann::json FlatRenderer::known_json(std::size_t* marker) const {
  nlohmann::json kj = nlohmann::json::array();
  for (std::size_t i = 0; i < known_.size(); ++i) {
    const ImageMarker& m = result_.markers[(*marker)++];
    kj.push_back({{"id", known_[i].id},
                  {"center_lps_mm", known_[i].center_lps_mm},
                  {"diameter_mm", known_[i].diameter_mm},
                  {"distance_to_surface_mm", known_distance_[i]},
                  {"flat_mm", {m.x, m.y}},
                  {"segment", m.segment},
                  {"pixel", {m.px, m.py}}});
  }
  return kj;
}

void FlatRenderer::write_json() {
  std::size_t marker = 0;
  nlohmann::json cj = candidates_json(&marker);
  nlohmann::json kj = known_json(&marker);
  const ColonImage& img = result_.colon;
  result_.candidates_json = {{"units", "mm"},
                             {"coordinate_system", "LPS"},
                             {"image", {{"width", img.width}, {"height", img.height},
                                        {"pixel_size_mm", img.pixel_size},
                                        {"pixel_origin", "column, row from the top-left corner"}}},
                             {"candidates", cj},
                             {"known_polyps", kj}};
  if (opts_.known_polyps.empty()) return;
  const DetectionScore sc = score_detections(result_.candidates, known_);
  result_.candidates_json["score_vs_known"] = {{"polyps_ge_6mm", sc.polyps},
                                               {"detected", sc.polyps_detected},
                                               {"sensitivity", sc.sensitivity},
                                               {"false_positives", sc.false_positives},
                                               {"missed_ids", sc.missed_ids}};
}

}  // namespace

RenderResult render_flat(const FlatMap& flat, const RenderOptions& opts) { return FlatRenderer(flat, opts).run(); }

}  // namespace cf
