#include "colonflat/reconstruct/reconstruct_stage.h"

#include <any>
#include <iomanip>
#include <sstream>

#include "colonflat/core/mesh_artifact.h"
#include "colonflat/volume/volume_io.h"

namespace cf {

const StageSpec& ReconstructStage::spec() const {
  static const StageSpec s{
      "reconstruct",
      "lumen mask -> closed manifold colon surface (LPS mm, normals out of the lumen)",
      {{"mask", &mask_artifact(), "lumen mask", "lumen_mask.nrrd"},
       {"ct", &volume_artifact(), "the CT the mask was segmented from (HU, same grid): surface at its air/tissue boundary",
        "ct.nrrd", false, true}},
      {{"surface", &mesh_artifact(), "colon surface (LPS mm)", "surface.vtp"}}};
  return s;
}

void ReconstructStage::run(ArtifactBag& bag, RunContext& ctx) {
  const auto& mask = bag.get<MaskImage::Pointer>("mask");
  ReconstructStats st;
  std::any surface;  // the mesh built where the bag keeps it (reconstruct_surface_into: no copy)
  const auto* ct16 = bag.has("ct") ? std::any_cast<CompactCtImage::Pointer>(&bag.raw("ct")) : nullptr;
  if (ct16)  // the run holds the CT in 16 bits from segment's crop on: the same surface
    reconstruct_surface_into(surface.emplace<Mesh>(), mask.GetPointer(), ct16->GetPointer(), opts_, &st);
  else
    reconstruct_surface_into(surface.emplace<Mesh>(), mask.GetPointer(),
                             bag.has("ct") ? bag.get<CtImage::Pointer>("ct").GetPointer() : nullptr, opts_, &st);
  ctx.report = st.to_json();
  std::ostringstream line;
  line << "  reconstruct: " << st.lumen_voxels << " lumen voxels -> " << st.extracted_faces << " triangles ("
       << st.components_found << " components, " << st.dropped.size() << " dropped below "
       << format_number(opts_.min_component_volume) << " mm^3) -> " << st.faces << " triangles, " << st.kept.size()
       << " components, genus " << st.genus << ", surface " << st.field_source << std::fixed << std::setprecision(2) << ", " << st.time_total_s << " s";
  ctx.progress(line.str());
  bag.put("surface", std::move(surface));
  // The final check's analysis of the surface, for the stages that orient it (denoise, render's
  // snapshot): core orient_mesh_input and orient_surface use it instead of analysing it again.
  if (st.topology) bag.put(topology_entry("surface"), std::move(*st.topology));
}

std::unique_ptr<Stage> make_reconstruct_stage() { return std::make_unique<ReconstructStage>(); }

}  // namespace cf
