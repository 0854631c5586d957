#pragma once
// The "flat" artifact: a FlatMap in a .vtp file. Points are the 2D positions (x, y, 0) in mm;
// triangles as polys; point data "position_lps_mm" (3D position), "Normals" (3D normal, out of
// the lumen), "segment_id", "source_vertex"; field data "Units" = mm, "CoordinateSystem" = LPS
// (of position_lps_mm), "FlatSegments" (JSON text: one object per segment with its rectangle).
#include <filesystem>

#include <vtkSmartPointer.h>

#include "colonflat/core/stage.h"
#include "colonflat/flatten/flatten.h"

class vtkPolyData;

namespace cf {

const ArtifactType& flat_artifact();

vtkSmartPointer<vtkPolyData> flat_to_polydata(const FlatMap& flat);
FlatMap polydata_to_flat(vtkPolyData* pd, const std::string& name_for_errors);
void write_flat(const FlatMap& flat, const std::filesystem::path& path);  // atomic
FlatMap read_flat(const std::filesystem::path& path);                     // throws InputError

}  // namespace cf
