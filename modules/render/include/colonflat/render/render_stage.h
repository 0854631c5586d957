#pragma once
// `colonflat render FLAT -o colon.png [--candidates candidates.json] [--surface S.vtp] [--loops L.vtp]
//  [--denoised D.vtp] [--snapshot-before B.png] [--snapshot-after A.png]`: polyp candidates on the
// 3D wall, the 2D colon image with overlays, their JSON, and 3D snapshots.
#include <memory>
#include <string>

#include "colonflat/core/stage.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/render/colon_image.h"
#include "colonflat/render/polyps.h"

namespace cf {

struct RenderOptions {
  double pixel_size = 0.5;          // mm per pixel
  std::string color = "shading";    // shading | curvature
  double smooth_normal = 8.0;       // mm
  std::string known_polyps;         // JSON file of known polyp positions (LPS mm) to overlay
  bool detect = true;               // detect polyp candidates
  bool snapshots = true;            // 3D snapshots (need X or Xvfb)
  int snapshot_size = 900;          // pixels
  double fit_radius = 2.5;          // mm
  double min_size = 4.0;            // mm
  double min_score = 0.65;
  double seed_si = 0.9;
};

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
  const ParamTable<RenderOptions>& table() const override;
};

std::unique_ptr<Stage> make_render_stage();

}  // namespace cf
