#include "colonflat/flatten/flatten_stage.h"

#include <iomanip>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/run_stats.h"

namespace cf {

const StageSpec& FlattenStage::spec() const {
  static const StageSpec s{
      "flatten",
      "flattening of the colon wall onto bands: x from the rectum along the centreline, y around; area-balanced "
      "or conformal",
      {{"denoised", &mesh_artifact(), "genus-0 colon surface (after denoise)", "denoised.vtp"}},
      {{"flat", &flat_artifact(), "flat colon map", "flat.vtp"}}};
  return s;
}

const ParamTable<FlattenOptions>& FlattenStage::table() const {
  static const ParamTable<FlattenOptions> t = [] {
    ParamTable<FlattenOptions> t;
    t.real("end-cut-radius", &FlattenOptions::end_cut_radius, "mm",
           "geodesic radius of the cap opened at each closed end (at most 10% of the segment length)", 0.0, 1000.0);
    t.real("min-segment-fraction", &FlattenOptions::min_segment_fraction, "",
           "skip components with fewer faces than this fraction of the largest", 0.0, 1.0);
    t.real("segment-gap", &FlattenOptions::segment_gap, "mm", "gap between segment rectangles in the layout", 0.0,
           1000.0);
    t.choice("weights", &FlattenOptions::weights, {"auto", "cotan", "clamped"},
             "Laplacian weights: cotan; clamped (negative cotangents clamped, never flips in practice); auto = "
             "cotan, clamped if cotan flips a triangle");
    t.choice("map", &FlattenOptions::map, {"area-balanced", "conformal"},
             "area-balanced: x from the rectal end (0) to the cecal end (= centreline length), each slice as wide "
             "as its wall area, out-of-bounds regions corrected locally (bijective); conformal: the pure conformal "
             "(holomorphic 1-form) map");
    t.real("area-ratio-low", &FlattenOptions::area_ratio_low, "",
           "area-balanced: faces whose 2D/3D area ratio is below this are corrected", 0.0, 1.0);
    t.real("area-ratio-high", &FlattenOptions::area_ratio_high, "",
           "area-balanced: faces whose 2D/3D area ratio is above this are corrected", 1.0, 1000.0);
    t.integer("balance-iterations", &FlattenOptions::balance_iterations, "",
              "area-balanced: symmetric-Dirichlet descent steps per correction pass (0: no correction)", 0, 10000);
    t.real("coverage-min-ratio", &FlattenOptions::coverage_min_ratio, "",
           "a face counts as shown on the image when its 2D/3D area ratio is at least this", 0.0, 1.0);
    t.real("branch-min-area", &FlattenOptions::branch_min_area, "mm^2",
           "area-balanced: a pouch behind a neck that the conformal map collapses over at least this wall area "
           "(diverticulum, blind colon loop) is cut at its neck and shown as a band of its own (0: never)",
           0.0, 1e7);
    return t;
  }();
  return t;
}

void FlattenStage::run(ArtifactBag& bag, RunContext& ctx) {
  const Mesh& mesh = bag.get<Mesh>("denoised");
  Stopwatch sw;
  FlatMap flat = flatten_colon(mesh, opts_);
  ctx.report = flat_report(flat);
  ctx.report["flatten_time_s"] = sw.seconds();
  for (const auto& s : flat.segments) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(1) << "flatten: segment " << s.id << " (" << s.input_kind << ", "
         << s.faces << " faces): " << s.length << " x " << s.period << " mm, flipped " << s.stats.flipped
         << ", quasi-conformal mean " << std::setprecision(3) << s.stats.qc_mean << " p95 " << s.stats.qc_p95
         << " max " << s.stats.qc_max << ", area p05 " << s.stats.area_p05 << " p95 " << s.stats.area_p95
         << ", shown " << std::setprecision(2) << 100 * s.coverage.fraction << " % of the wall, ends "
         << s.x0_end << " (left) / " << s.x1_end << " (right), centreline " << std::setprecision(0)
         << s.centreline_length << " mm";
    ctx.progress(line.str());
  }
  if (flat.stats.flipped > 0)
    ctx.progress("flatten: warning: " + std::to_string(flat.stats.flipped) + " flipped triangles");
  bag.put("flat", std::move(flat));
}

std::unique_ptr<Stage> make_flatten_stage() { return std::make_unique<FlattenStage>(); }

}  // namespace cf
