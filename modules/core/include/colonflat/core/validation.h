#pragma once
// Diagnosis of raw mesh data: every defect with its count and a few example element ids, and a
// policy for turning a soup into a valid triangle mesh (triangulate, drop, re-orient, or refuse).
#include <string>
#include <vector>

#include "colonflat/core/orientation.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/topology.h"

namespace cf {

enum class Severity {
  kNote,      // worth saying, not a defect (several components, coincident points)
  kRepaired,  // a defect that loading repaired (polygons triangulated, unreferenced dropped)
  kDefect,    // makes the mesh unfit as a closed 2-manifold (boundary, non-manifold, ...)
  kFatal      // cannot be processed at all (NaN coordinates, ids out of range, empty)
};

struct Finding {
  std::string code;      // stable identifier, e.g. "nonmanifold_edges"
  Severity severity;
  std::size_t count;     // how many elements
  std::string message;   // "2 non-manifold edges (e.g. 17-40, 90-91)"
};

struct MeshDiagnosis {
  std::vector<Finding> findings;
  bool has(const std::string& code) const;
  const Finding* find(const std::string& code) const;
  bool has_at_least(Severity s) const;
  // One line: all findings of severity >= s joined by "; ".
  std::string summary(Severity s) const;
};

struct LoadPolicy {
  bool triangulate = true;            // fan-triangulate polygons with more than 3 vertices
  bool drop_degenerate = true;        // drop faces with a repeated vertex id or < 3 vertices
  bool drop_unreferenced = true;      // drop vertices no face uses
  bool fix_orientation = true;        // re-orient an orientable but inconsistently oriented mesh
  bool allow_boundary = true;         // accept open meshes (boundary loops)
  bool allow_several_components = true;
};

// Checks on the raw soup: empty, non-finite coordinates, out-of-range ids, polygon sizes,
// repeated ids in a face, duplicate faces, unreferenced vertices, coincident points.
MeshDiagnosis diagnose_soup(const PolygonSoup& soup);

// Adds the findings a topology report implies (boundary, non-manifold, orientation, components).
void add_topology_findings(const TopologyReport& topo, bool allow_boundary, MeshDiagnosis& diag);

// Adds a note when closed components have their normals into the lumen (orientation.h: the
// signed volume's sign against the nesting depth; faces made consistent first on the copy `t`).
void add_orientation_findings(TriangleList t, const TopologyReport& topo, MeshDiagnosis& diag);

// Triangulates and cleans a soup per `policy`. Throws PreconditionError on fatal findings.
TriangleList soup_to_triangles(const PolygonSoup& soup, const LoadPolicy& policy,
                               const MeshDiagnosis& diag);

// Checks that `t` is a manifold and makes every component consistently oriented (see
// orientation.h make_consistent); returns the faces turned. Throws PreconditionError naming the
// defect (not a manifold, a non-orientable component with its size, or an inconsistent
// orientation when !fix_orientation).
OrientationReport make_orientation_consistent(TriangleList& t, const TopologyReport& topo, bool fix_orientation);

// Makes a consistently oriented OpenMesh mesh. Preconditions: manifold, orientable triangles
// (checked; throws PreconditionError naming the defect otherwise).
Mesh triangles_to_mesh(TriangleList tris, const TopologyReport& topo, bool fix_orientation);

}  // namespace cf
