#pragma once
// Orientation of surfaces made by any tool (docs/conventions.md, "Orientation"): every stage wants
// normals pointing out of the lumen, into the wall. A closed component enclosed by d other closed
// components (its nesting depth) then has a signed volume of sign (-1)^d: the colon's outer wall
// (d = 0) encloses a positive volume, the wall of a cavity inside the lumen (a blob, d = 1) a
// negative one - what reconstruct writes. Surfaces from other tools (Slicer, scikit-image,
// ITK-SNAP) often have every normal pointing into the lumen, or a patch of faces flipped.
//
//   make_consistent()  every component's faces agree with their neighbours (read time: OpenMesh
//                      cannot hold a face that disagrees); the minority of the faces is turned;
//                      a non-orientable component is refused with its size.
//   orient_outward()   every closed component whose signed volume has the wrong sign for its
//                      depth is reversed. Open components are kept as they are (no volume).
// Both return what they changed, one note per component, e.g.
//   "component 0 (1460112 faces, 3.80 L): normals pointed into the lumen; reversed".
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/topology.h"

namespace cf {

// Where a component lies and which way it faces.
struct ComponentSide {
  std::size_t faces = 0;
  double area_mm2 = 0;
  double volume_mm3 = 0;  // signed volume (closed components; 0 for open ones)
  bool closed = false;
  bool determined = false;  // closed with a volume clearly away from 0 (see kFlatVolumeRatio)
  int depth = 0;            // closed components that enclose it
  // Normals into the lumen: a determined component whose volume sign is not (-1)^depth.
  bool inward() const { return determined && ((volume_mm3 < 0) == (depth % 2 == 0)); }
  // A cavity's wall (a blob inside the lumen): odd depth.
  bool cavity() const { return depth % 2 == 1; }
};

// A closed component whose |volume| is below this fraction of area^1.5 (a sphere: 0.094) is
// flat (a folded sheet): which side is the lumen cannot be told, its orientation is kept.
constexpr double kFlatVolumeRatio = 1e-6;

// Per component of `topo` (same order): size, signed volume, nesting depth. Depth: the closed
// components whose generalised winding number at one of this component's vertices is +-1.
std::vector<ComponentSide> component_sides(const TriangleList& t, const TopologyReport& topo);

// What was changed in one component.
struct OrientationChange {
  int component = 0;
  std::size_t faces = 0;
  double area_mm2 = 0, volume_mm3 = 0;  // volume as found (before reversing)
  std::size_t flipped_faces = 0;        // faces turned to agree with their neighbours
  bool reversed = false;                // every face turned: normals pointed into the lumen
  std::string note() const;
};

struct OrientationReport {
  std::vector<OrientationChange> changes;  // only components that changed
  bool empty() const { return changes.empty(); }
  std::size_t reversed_components() const;
  std::size_t flipped_faces() const;
  std::vector<std::string> notes() const;
  // {"reversed_components": n, "flipped_faces": n, "notes": [...], "components": [...]}
  nlohmann::json to_json() const;
  void append(const OrientationReport& other);
  static OrientationReport from_json(const nlohmann::json& j);
};

// Makes every component consistently oriented (breadth-first across manifold edges; per
// component, the orientation of the majority of its faces is kept). Throws PreconditionError
// naming a non-orientable component with its size. Precondition: topo = analyze_topology(t),
// manifold.
OrientationReport make_consistent(TriangleList& t, const TopologyReport& topo);

// Reverses every closed component whose normals point into the lumen (ComponentSide::inward).
// Precondition: topo = analyze_topology(t), consistently oriented.
OrientationReport orient_outward(TriangleList& t, const TopologyReport& topo);
// The same on a mesh (no deleted elements); rebuilt, same vertex and face order, when a
// component is reversed. `topology` (optional) receives analyze_topology of the mesh, which
// reversing whole components does not change (components, counts, Euler characteristic, genus);
// `known` (optional): the mesh's topology when the caller has it, used instead of analysing when it
// fits (known_or_analysed); `list` (optional) receives to_triangle_list of the mesh as it is left
// (read back after a rebuild). The same report and mesh with or without `known`.
OrientationReport orient_outward(Mesh& mesh, TopologyReport* topology = nullptr, const TopologyReport* known = nullptr,
                                 std::optional<TriangleList>* list = nullptr);

// Builds an OpenMesh mesh from a manifold, consistently oriented triangle list (same order).
// Throws PreconditionError when a face cannot be added.
Mesh build_mesh(const TriangleList& t);

}  // namespace cf
