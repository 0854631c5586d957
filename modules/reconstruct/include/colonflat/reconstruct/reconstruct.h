#pragma once
// Lumen mask -> closed, manifold colon surface in LPS millimetres (docs/reconstruct.md).
//
//   cf::ReconstructStats st;
//   cf::Mesh surface = cf::reconstruct_surface(mask.GetPointer(), cf::ReconstructOptions{}, &st);
//
// Guarantees on the returned mesh (checked after every step; a violation throws cf::Error):
//   * closed (no boundary edge), 2-manifold, consistently oriented, normals pointing out of the
//     lumen (signed volume of every outer surface > 0), whatever the sign of det(direction);
//   * points are LPS mm: p = origin + direction * diag(spacing) * index (ITK's convention);
//   * topology = the (6,18) digital topology of the mask: lumen voxels joined through faces,
//     background voxels through faces and edges. Exactly, before decimation:
//     chi(extracted surface) == 2 * mask_euler_characteristic_6_18(mask), before small components
//     are dropped. Smoothing moves points only; decimation keeps every component's genus.
//   * sub-voxel placement (subvoxel != "off"): the surface is the 0.5 isosurface of a field that is
//     > 0.5 exactly at lumen voxels: the CT's air/tissue boundary (air_tissue_hu) where a CT is
//     given and no tagged fluid is near, otherwise the constrained-smoothed mask. The triangles
//     are those of the binary mask's surface; every vertex stays on its lattice edge strictly
//     between the two voxel centres; the optional windowed-sinc smoothing after it is clamped so that
//     no vertex ends more than 1/2 voxel from its staircase position (index space).
//   * one surface component per 6-connected lumen component (plus one per enclosed background
//     cavity), components enclosing less than min_component_volume mm^3 dropped and reported.
#include <itkImage.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "colonflat/core/mesh.h"
#include "colonflat/core/params.h"
#include "colonflat/core/topology.h"

namespace cf {

// Same aliases as colonflat/volume/volume_io.h (0 outside, 1 lumen; any non-zero value is lumen).
using MaskImage = itk::Image<unsigned char, 3>;
using CtImage = itk::Image<float, 3>;  // HU, on the mask's voxel grid
using CompactCtImage = itk::Image<short, 3>;  // the same HU in 16 bits (`colonflat run` holds the CT so)

// The options of reconstruct: every field is a parameter declared once, with its default, unit, range and
// help, in reconstruct_params.def (also the source of `colonflat reconstruct`'s options and docs/reconstruct.md's table).
struct ReconstructOptions {
#define COLONFLAT_PARAMS "colonflat/reconstruct/reconstruct_params.def"
#include "colonflat/core/params_as_fields.h"
};

// The table of ReconstructOptions (generated from reconstruct_params.def): option names, units,
// help, ranges; used by the stage's command line, --help, JSON and validate().
const ParamTable<ReconstructOptions>& reconstruct_param_table();
// Throws UsageError naming the first invalid option.
void validate(const ReconstructOptions& o);

struct ReconstructComponent {
  std::size_t faces = 0;
  double volume_mm3 = 0;  // signed: > 0 an outer surface, < 0 the wall of an enclosed cavity
  double area_mm2 = 0;
  int genus = 0;
};

struct ReconstructStats {
  std::string method;
  std::size_t lumen_voxels = 0;
  std::array<std::size_t, 3> image_size{0, 0, 0};
  std::array<std::size_t, 3> crop_size{0, 0, 0};  // lumen bounding box (before 1-voxel padding)
  bool direction_flips_orientation = false;       // det(direction) < 0
  std::size_t extracted_vertices = 0, extracted_faces = 0;
  long long mask_euler_6_18 = 0;     // chi of the lumen, (6,18) topology
  long long surface_euler = 0;       // chi of the extracted surface (== 2 * mask_euler_6_18)
  std::size_t components_found = 0;
  std::vector<ReconstructComponent> kept;     // largest |volume| first
  std::vector<ReconstructComponent> dropped;  // below min_component_volume
  std::string field_source = "off";          // ct | mask | off
  std::size_t clamped_vertices = 0;           // vertices the smoothing moved > 1/2 voxel, pulled back
  std::size_t fluid_voxels = 0;               // lumen voxels >= fluid_hu (ct field only)
  std::size_t field_clamped_voxels = 0;       // lumen voxels the field would have put outside
  bool smoothed = false, decimated = false;
  int fairing_iterations = 0;                 // constrained fairing (mask surface without a CT)
  double fairing_energy_before = 0, fairing_energy_after = 0;  // umbrella energy, mm^2
  std::size_t fairing_vertices_at_limit = 0;  // vertices held at 1/2 voxel by the constraint
  std::size_t vertices = 0, faces = 0;
  int genus = 0;  // total over kept components
  double time_field_s = 0, time_extract_s = 0, time_check_s = 0, time_smooth_s = 0, time_fairing_s = 0, time_decimate_s = 0, time_total_s = 0;
  // analyze_topology of the surface returned (its final check's; not in to_json): the stage hands it
  // on to the stages that orient the surface (core topology_entry), which then need not analyse it.
  std::shared_ptr<TopologyReport> topology;
  nlohmann::json to_json() const;
};

// The surface of the lumen (see the guarantees above). Throws PreconditionError for an empty
// mask, a mask without a component above min_component_volume, or non-positive spacing;
// UsageError for invalid options; cf::Error if a guarantee fails to hold.
Mesh reconstruct_surface(const MaskImage* mask, const ReconstructOptions& options,
                         ReconstructStats* stats = nullptr);
// The same with the CT the mask was segmented from (null = none): with subvoxel auto or ct the
// surface follows the CT's air/tissue boundary inside the segmented lumen. The CT must have the
// mask's size, origin, spacing and direction (PreconditionError otherwise); subvoxel ct without a
// CT is a PreconditionError.
Mesh reconstruct_surface(const MaskImage* mask, const CtImage* ct, const ReconstructOptions& options,
                         ReconstructStats* stats = nullptr);
// The same, built in the caller's empty mesh `out` (e.g. one a std::any holds): an OpenMesh mesh
// has no move operations, so returning one copies it (on a 2 M-face surface, every array written
// again into fresh pages). PreconditionError when `out` is not empty.
void reconstruct_surface_into(Mesh& out, const MaskImage* mask, const CtImage* ct, const ReconstructOptions& options,
                              ReconstructStats* stats = nullptr);
// The same from the CT in 16 bits: the same surface, bit for bit, as from the float CT it holds.
void reconstruct_surface_into(Mesh& out, const MaskImage* mask, const CompactCtImage* ct,
                              const ReconstructOptions& options, ReconstructStats* stats = nullptr);
inline void reconstruct_surface_into(Mesh& out, const MaskImage* mask, std::nullptr_t, const ReconstructOptions& options,
                                     ReconstructStats* stats = nullptr) {  // no CT
  reconstruct_surface_into(out, mask, static_cast<const CtImage*>(nullptr), options, stats);
}

// Euler characteristic of the lumen (non-zero voxels) in the (6,18) digital topology, i.e. of
// the solid the marching-cubes surface bounds: #voxels - #face-adjacent pairs + #2x2 squares
// - #2x2x2 blocks + #2x2x2 blocks with exactly two background voxels at opposite corners.
long long mask_euler_characteristic_6_18(const MaskImage* mask);

// How far a surface lies from the mask's voxel boundary (the faces between lumen voxels and
// background voxels, outside the image counting as background), in LPS mm. For accuracy checks
// against a ground-truth mask (tests, benchmarks); assumes an orthonormal direction matrix.
// Vertices farther than 3 voxels from any boundary face count as `far`.
struct BoundaryDistance {
  double max_mm = 0, mean_mm = 0;
  std::size_t vertices = 0, far = 0;
  double max_spacing_mm = 0;  // largest voxel spacing of the mask
  double max_voxels = 0, mean_voxels = 0;  // the same distances in voxel (index) units
  nlohmann::json to_json() const;
};
BoundaryDistance distance_to_mask_boundary(const Mesh& surface, const MaskImage* mask);

}  // namespace cf
