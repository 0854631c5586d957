#pragma once
// Mesh files: OFF, OBJ, PLY (ASCII/binary), STL (ASCII/binary) through OpenMesh's readers and
// writers; VTK PolyData (.vtp XML, .vtk legacy) through VTK's. No parser is written here.
// Writes are atomic (temp file + rename). Coordinates are written as they are: from
// reconstruction on they are LPS millimetres, and .vtp/.vtk outputs record that in field data.
#include <filesystem>
#include <optional>
#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/validation.h"

namespace cf {

enum class MeshFormat { kOFF, kOBJ, kPLY, kSTL, kVTP, kVTK };

// Format from the file extension (case-insensitive); nullopt when unknown.
std::optional<MeshFormat> mesh_format_from_path(const std::filesystem::path& path);
std::string mesh_format_list();  // ".off .obj .ply .stl .vtp .vtk"

// Reads raw data. Throws InputError (file missing, unreadable, unknown format, parse failure,
// truncated, empty).
PolygonSoup read_polygon_soup(const std::filesystem::path& path);

struct LoadedMesh {
  Mesh mesh;
  MeshDiagnosis diagnosis;
  TopologyReport topology;  // of `mesh` as loaded
  OrientationReport orientation;  // faces turned to agree with their neighbours (not reversed)
};

// Reads, diagnoses and converts a file to a valid, consistently oriented triangle mesh (each
// component's minority of faces turned; whether its normals point out of the lumen is the
// stages' business: orient_outward(), orientation.h).
// Throws InputError with the diagnosis when the file cannot be made a 2-manifold per `policy`.
LoadedMesh load_mesh(const std::filesystem::path& path, const LoadPolicy& policy = {});

struct WriteOptions {
  bool binary = true;       // binary where the format has it (PLY, STL, VTK legacy); .vtp is
                            // always appended binary, OFF/OBJ always ASCII
  int ascii_precision = 17; // significant digits for ASCII coordinates (17 = lossless double)
  std::string units = "mm";
  std::string space = "LPS";
};

// Writes atomically. Throws cf::Error on failure (the target is then untouched).
void write_mesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& = {});
// The same file from a triangle list (what `colonflat run` holds a mesh as while no stage needs its
// halfedges: mesh_artifact's stand-in): write_mesh(to_triangle_list(m), ...) writes the bytes
// write_mesh(m, ...) writes for a mesh without deleted elements. OFF, OBJ, PLY and STL go through
// build_mesh (throws PreconditionError when a face cannot be added to a halfedge mesh).
void write_mesh(const TriangleList& mesh, const std::filesystem::path& path, const WriteOptions& = {});

}  // namespace cf
