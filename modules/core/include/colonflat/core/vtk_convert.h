#pragma once
// Conversions between cf::Mesh and vtkPolyData (same vertex and triangle order), and tagging of
// PolyData with its units and coordinate system (field data "Units", "CoordinateSystem").
#include <vtkSmartPointer.h>

#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"

class vtkPolyData;

namespace cf {

vtkSmartPointer<vtkPolyData> mesh_to_polydata(const Mesh& mesh);
// Polygons (and triangle strips, split into triangles) of a PolyData; lines and vertices ignored.
PolygonSoup polydata_to_soup(vtkPolyData* pd);
void tag_polydata_space(vtkPolyData* pd, const std::string& units, const std::string& space);

}  // namespace cf
