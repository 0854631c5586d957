#pragma once
// The mesh type every stage shares: an OpenMesh triangle mesh with double-precision points.
// From reconstruction on, coordinates are LPS millimetres (see docs/conventions.md).
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace cf {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};

using Mesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;
using Vec3 = OpenMesh::Vec3d;

}  // namespace cf
