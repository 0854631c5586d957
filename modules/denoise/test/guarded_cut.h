#pragma once
// A loop cut as the denoiser's loop search makes it: cut_and_cap guarded by a FaceGrid of the mesh
// (cells 3 mean edges wide), so that every cap kind is checked against the surface.
#include <utility>
#include <vector>

#include "colonflat/denoise/face_grid.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/surgery.h"
#include "swept_profile.h"

namespace cf::testing {

struct GuardedCut {
  Mesh mesh;
  SurgeryResult result;
};

// `mesh` cut along `loop` with `options` (its guard set here); `homology` (optional) is built on the
// mesh first and passed to the cut.
inline GuardedCut guarded_cut(Mesh mesh, const std::vector<Mesh::VertexHandle>& loop, SurgeryOptions options,
                              HomologyBasis* homology = nullptr) {
  GuardedCut c;
  c.mesh = std::move(mesh);
  if (homology) homology->build(c.mesh);
  FaceGrid grid(c.mesh, 3 * mean_edge(c.mesh));
  options.guard = &grid;
  c.result = cut_and_cap(c.mesh, loop, options, homology);
  return c;
}

}  // namespace cf::testing
