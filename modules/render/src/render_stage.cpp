#include "colonflat/render/render_stage.h"

#include <future>
#include <optional>

#include <vtkImageData.h>
#include <vtkPolyData.h>

#include "colonflat/core/loops.h"
#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/topology.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/render/snapshot.h"

namespace cf {

const StageSpec& RenderStage::spec() const {
  static const StageSpec s{
      "render",
      "2D colon-wall image with polyp candidates, candidate JSON, 3D snapshots",
      {{"flat", &flat_artifact(), "flat colon map (from flatten)", "flat.vtp"},
       {"surface", &mesh_artifact(), "surface before denoising (snapshot)", "surface.vtp", false, true},
       {"loops", &loops_artifact(), "cut loops of denoise (snapshot)", "loops.vtp", false},
       {"denoised", &mesh_artifact(), "surface after denoising (snapshot)", "denoised.vtp", false, true}},
      {{"colon_image", &png_image_artifact(), "2D colon-wall image", "colon.png"},
       {"candidates", &json_artifact(), "polyp candidates (3D and 2D positions, size, score)", "candidates.json"},
       {"snapshot_before", &png_image_artifact(), "3D snapshot of the surface before denoising, loops highlighted",
        "snapshot_before.png", false},
       {"snapshot_after", &png_image_artifact(), "3D snapshot of the surface after denoising, loops highlighted",
        "snapshot_after.png", false}}};
  return s;
}

const ParamTable<RenderOptions>& render_param_table() {
  static const ParamTable<RenderOptions> table = [](ParamTable<RenderOptions> t) {
#define COLONFLAT_PARAMS "colonflat/render/render_params.def"
#include "colonflat/core/params_as_rows.h"
    return t;
  }({});
  return table;
}

namespace {

// The snapshot of a surface held as the mesh or as its stand-in (the same pixels either way).
ImagePtr snapshot_of(const BagSurface& s, vtkPolyData* loops, const SnapshotOptions& so) {
  return s.mesh ? render_snapshot(*s.mesh, loops, so) : render_snapshot(*s.triangles, loops, so);
}

// The snapshot of the surface before denoising, its caption giving the genus (of the surface's
// topology, found when it was oriented) and the loop count.
ImagePtr snapshot_before(const BagSurface& s, std::optional<int> genus, vtkPolyData* loops, SnapshotOptions so) {
  so.caption = "before denoising: genus " + (genus ? std::to_string(*genus) : std::string("?")) +
               (loops ? ", " + std::to_string(loops->GetNumberOfCells()) + " cut loops" : std::string());
  return snapshot_of(s, loops, so);
}

}  // namespace

// Orients the snapshot surfaces in place (snapshots light the outside of the wall): the report of
// each under "orientation", the seconds in orient_s; `surface_topology` gets the surface's.
RenderStage::SnapshotImages RenderStage::orient_snapshot_inputs(const BagSurface& surface, const BagSurface& denoised,
                                                                const RunContext& ctx,
                                                                TopologyReport* surface_topology,
                                                                const TopologyReport* known_surface,
                                                                const TopologyReport* known_denoised) {
  SnapshotImages im;
  Stopwatch sw;
  if (surface)
    im.orientation["surface"] = orient_surface(surface, ctx, "render", "surface", surface_topology, known_surface);
  if (denoised)
    im.orientation["denoised"] = orient_surface(denoised, ctx, "render", "denoised", nullptr, known_denoised);
  im.orient_s = sw.seconds();
  return im;
}

// Snapshots on: builds the loops' polylines, sets the display up (Xvfb is forked before any second
// thread runs) and orients and renders both snapshots on a second thread, one after the other:
// they need only the surfaces (or the flat map's) and the loops, and nothing else touches the
// surfaces meanwhile; the colon image drawn on this thread needs no OpenGL. The snapshot after
// denoising is rendered without its caption, which counts the candidates found meanwhile. Where no
// display can be had, `error` says why (the surfaces are still oriented, here).
RenderStage::Snapshots RenderStage::start_snapshots(ArtifactBag& bag, const FlatMap& flat, RunContext& ctx) const {
  Snapshots s;
  if (bag.has("loops")) s.loops = loops_to_polydata(bag.get<LoopSet>("loops"));
  s.options.width = s.options.height = opts_.snapshot_size;
  const BagSurface surface = bag.has("surface") ? bag_surface_for_orienting(bag, "surface") : BagSurface{};
  const BagSurface denoised = bag.has("denoised") ? bag_surface_for_orienting(bag, "denoised") : BagSurface{};
  // Their topologies as reconstruct and denoise handed them on, in `colonflat run`.
  const TopologyReport* known_surface = handed_topology_entry(bag, "surface");
  const TopologyReport* known_denoised = handed_topology_entry(bag, "denoised");
  try {
    s.display = ensure_display();
  } catch (const Error& e) {
    s.error = e.what();
    const SnapshotImages oriented = orient_snapshot_inputs(surface, denoised, ctx, nullptr, known_surface, known_denoised);
    ctx.report["orientation"] = oriented.orientation;
    ctx.report["snapshot_orient_s"] = oriented.orient_s;
    return s;
  }
  s.images = std::async(std::launch::async, [surface, denoised, known_surface, known_denoised, &flat, &ctx,
                                              loops = s.loops.Get(), so = s.options] {
    TopologyReport surface_topology;
    SnapshotImages im = orient_snapshot_inputs(surface, denoised, ctx, &surface_topology, known_surface, known_denoised);
    Stopwatch sw;
    if (surface) im.before = snapshot_before(surface, surface_topology.genus, loops, so);
    im.before_s = sw.lap();
    im.after = denoised ? snapshot_of(denoised, loops, so) : render_snapshot(flat_to_surface(flat), loops, so);
    im.after_s = sw.lap();
    return im;
  });
  return s;
}

// Waits for the snapshots, captions the one after denoising (with the candidate count) and puts
// both into the bag; a snapshot error is reported, never fatal.
void RenderStage::finish_snapshots(Snapshots& s, std::size_t candidates, ArtifactBag& bag, RunContext& ctx) const {
  try {
    if (!s.error.empty()) throw Error(s.error);
    Stopwatch wait;
    SnapshotImages im = s.images.get();
    ctx.report["snapshot_wait_s"] = wait.seconds();
    ctx.report["orientation"] = im.orientation;
    ctx.report["snapshot_orient_s"] = im.orient_s;
    ctx.report["snapshot_time_s"] = {{"before", im.before_s}, {"after", im.after_s}};
    phase_done("3D snapshots before and after denoising (beside the colon image)");
    if (im.before) bag.put("snapshot_before", im.before);
    const bool denoised = bag.has("denoised");
    caption_snapshot(im.after, std::string(denoised ? "after denoising" : "flattened surface") + ", " +
                                   std::to_string(candidates) + " polyp candidates" +
                                   (s.loops ? ", cut loops highlighted" : std::string()));
    bag.put("snapshot_after", im.after);
    ctx.report["display"] = s.display;
  } catch (const Error& e) {
    ctx.report["snapshot_error"] = e.what();
    ctx.progress(std::string("render: no 3D snapshots: ") + e.what());
  }
}

void RenderStage::run(ArtifactBag& bag, RunContext& ctx) {
  const FlatMap& flat = bag.get<FlatMap>("flat");
  Snapshots snapshots;
  if (opts_.snapshots) snapshots = start_snapshots(bag, flat, ctx);
  Stopwatch sw;
  RenderResult r = render_flat(flat, opts_);
  phase_done("colon image and candidates");
  ctx.report["colon_image"] = {{"width", r.colon.width},
                               {"height", r.colon.height},
                               {"pixel_size_mm", r.colon.pixel_size},
                               {"labels_moved", r.colon.labels_moved},
                               {"labels_crowded", r.colon.labels_crowded},
                               {"crowded_labels", r.colon.crowded_labels}};
  ctx.report["candidates"] = r.candidates.size();
  if (r.candidates_json.contains("score_vs_known")) ctx.report["score_vs_known"] = r.candidates_json["score_vs_known"];
  ctx.report["image_time_s"] = sw.seconds();
  ctx.progress("render: colon image " + std::to_string(r.colon.width) + " x " + std::to_string(r.colon.height) +
               " px, " + std::to_string(r.candidates.size()) + " polyp candidates; labels: " +
               std::to_string(r.colon.labels_moved) + " moved off other text, " + std::to_string(r.colon.labels_crowded) +
               " with no free spot");
  bag.put("colon_image", r.colon.image);
  bag.put("candidates", r.candidates_json);
  if (opts_.snapshots) finish_snapshots(snapshots, r.candidates.size(), bag, ctx);
}

std::unique_ptr<Stage> make_render_stage() { return std::make_unique<RenderStage>(); }

}  // namespace cf
