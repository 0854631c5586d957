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
// The same PolyData (double points, one triangle cell per face, in order) from a triangle list:
// triangles_to_polydata(to_triangle_list(m)) equals mesh_to_polydata(m) for a mesh without
// deleted elements.
vtkSmartPointer<vtkPolyData> triangles_to_polydata(const TriangleList& t);
// Polygons (and triangle strips, split into triangles) of a PolyData; lines and vertices ignored.
PolygonSoup polydata_to_soup(vtkPolyData* pd);
void tag_polydata_space(vtkPolyData* pd, const std::string& units, const std::string& space);
// How every .vtp this project writes is encoded: appended raw binary data (no base64), LZ4
// blocks (vtkLZ4DataCompressor, read by VTK >= 8.1: Slicer, ParaView, VMTK). Measured on the real
// CT's files (CPU s to write, size): flat.vtp zlib level 1 + base64 2.5 s, 124.3 MB -> 0.25 s,
// 121.3 MB; surface.vtp 1.0 s, 47.5 MB -> 0.13 s, 54.3 MB. Coordinates are doubles and floats,
// which deflate barely shrinks, so the faster codec costs little size.
void use_fast_compression(vtkXMLWriter* writer);

}  // namespace cf
