#pragma once
// `colonflat render FLAT -o colon.png [--candidates candidates.json] [--surface S.vtp] [--loops L.vtp]
//  [--denoised D.vtp] [--snapshot-before B.png] [--snapshot-after A.png] [parameters:
// render_params.def]`: polyp candidates on the 3D wall, the 2D colon image with overlays, their
// JSON, and 3D snapshots.
#include <future>
#include <memory>
#include <string>

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/topology.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/render/colon_image.h"
#include "colonflat/render/polyps.h"
#include "colonflat/render/snapshot.h"

#include "colonflat/core/params.h"
namespace cf {

// The options of render: every field is a parameter declared once, with its default, unit, range and
// help, in render_params.def (also the source of `colonflat render`'s options and docs/render.md's table).
struct RenderOptions {
#define COLONFLAT_PARAMS "colonflat/render/render_params.def"
#include "colonflat/core/params_as_fields.h"
};

// The table of RenderOptions (generated from render_params.def): option names, units, help, ranges.
const ParamTable<RenderOptions>& render_param_table();

struct RenderResult {
  ColonImage colon;
  std::vector<PolypCandidate> candidates;
  std::vector<ImageMarker> markers;
  nlohmann::json candidates_json;
};

// The colon image and candidate JSON of a flat map (no snapshots).
RenderResult render_flat(const FlatMap& flat, const RenderOptions& opts);

class RenderStage : public StageWithOptions<RenderOptions> {
 public:
  const StageSpec& spec() const override;
  void run(ArtifactBag& bag, RunContext& ctx) override;

 protected:
  const ParamTable<RenderOptions>& table() const override { return render_param_table(); }

 private:
  // The 3D snapshots of one run: both surfaces are oriented and rendered on a second thread while
  // the colon image is drawn.
  struct SnapshotImages {
    ImagePtr before;  // null without a surface before denoising
    ImagePtr after;   // without its caption (it counts the candidates)
    double before_s = 0, after_s = 0;  // wall seconds of each on the snapshot thread (report "snapshot_time_s")
    nlohmann::json orientation = nlohmann::json::object();  // per port: orient_mesh's report (report "orientation")
    double orient_s = 0;  // wall seconds of orienting both surfaces on the snapshot thread
  };
  struct Snapshots {
    vtkSmartPointer<vtkPolyData> loops;
    SnapshotOptions options;
    std::string display, error;
    std::future<SnapshotImages> images;
  };
  // Each surface may be the mesh or, in `colonflat run`, its stand-in (the inputs read_stand_in).
  // `known_surface`, `known_denoised` (optional): their topologies handed on by reconstruct and
  // denoise (handed_topology_entry; orient_surface uses each only when it fits).
  static SnapshotImages orient_snapshot_inputs(const BagSurface& surface, const BagSurface& denoised,
                                               const RunContext& ctx, TopologyReport* surface_topology,
                                               const TopologyReport* known_surface = nullptr,
                                               const TopologyReport* known_denoised = nullptr);
  Snapshots start_snapshots(ArtifactBag& bag, const FlatMap& flat, RunContext& ctx) const;
  void finish_snapshots(Snapshots& s, std::size_t candidates, ArtifactBag& bag, RunContext& ctx) const;
};

std::unique_ptr<Stage> make_render_stage();

}  // namespace cf
