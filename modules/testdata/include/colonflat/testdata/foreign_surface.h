#pragma once
// Surfaces made the way other tools make them (test support, issue 29): VTK's
// vtkDiscreteMarchingCubes on a lumen mask - every component, no smoothing, no clean-up, nothing
// of reconstruct - in LPS mm, written by VTK's writers (PLY, legacy VTK, VTP) or a plain OFF
// writer, with every normal out of the lumen ("outward") or every face reversed ("inward", what
// Slicer exports, scikit-image on a (z, y, x) array and ITK-SNAP often give).
#include <filesystem>

#include "colonflat/core/soup.h"

namespace cf::testing {

// Marching cubes of the mask's voxels == 1, keeping every `step`-th voxel along each axis (1: the
// full mask), padded by one empty voxel so the surface is closed. Coordinates rounded to single
// precision (as VTK's float points and OpenMesh's readers keep them: every format then holds the
// same surface). Oriented outward: if the
// signed volume of the whole surface is negative (VTK's orientation depends on the axes'
// handedness), every face (a, b, c) becomes (a, c, b).
TriangleList foreign_marching_cubes(const std::filesystem::path& mask, int step = 1);

// Every face (a, b, c) -> (a, c, b): the normals reversed.
TriangleList reversed_faces(TriangleList t);

// Writes by the extension: .off (plain ASCII), .ply (vtkPLYWriter, binary), .vtk
// (vtkPolyDataWriter, binary), .vtp (vtkXMLPolyDataWriter). Throws std::runtime_error on failure.
void write_foreign(const TriangleList& t, const std::filesystem::path& file);

}  // namespace cf::testing
