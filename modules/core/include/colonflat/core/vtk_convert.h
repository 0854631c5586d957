#pragma once
// Conversions between cf::Mesh and vtkPolyData (same vertex and triangle order), and tagging of
// PolyData with its units and coordinate system (field data "Units", "CoordinateSystem").
#include <vtkSmartPointer.h>

#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"

class vtkPolyData;
class vtkXMLWriter;

namespace cf {

vtkSmartPointer<vtkPolyData> mesh_to_polydata(const Mesh& mesh);
// Polygons (and triangle strips, split into triangles) of a PolyData; lines and vertices ignored.
PolygonSoup polydata_to_soup(vtkPolyData* pd);
void tag_polydata_space(vtkPolyData* pd, const std::string& units, const std::string& space);
// How every .vtp this project writes is encoded: appended binary data, zlib level 1. Level 1, not
// VTK's default 5: on the real CT's surface (2.15 M faces) and flat map the files were 0.8 % and
// 0.6 % larger and took 41 % and 32 % less CPU to write (the coordinates are doubles and floats,
// which deflate barely shrinks whatever the level).
void use_fast_compression(vtkXMLWriter* writer);

}  // namespace cf
