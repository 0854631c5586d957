#pragma once
// The "mesh" artifact (triangle surface in LPS mm) and topology reports as JSON and text.
#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/validation.h"

namespace cf {

// Reads any supported mesh file through load_mesh() (boundaries and several components
// accepted, polygons triangulated, orientation made consistent and outward: what was turned or
// reversed is kept in the mesh property kReadOrientationProperty); writes via write_mesh().
// Its stand-in in `colonflat run` (ArtifactType::compact) is the TriangleList (to_triangle_list,
// about a quarter of the halfedge mesh's memory), expanded by build_mesh; a mesh with deleted
// elements or with the reader's orientation note still on it is not compacted. A stage that
// declares a mesh input reads_stand_in takes it through bag_surface_for_orienting or
// oriented_mesh_input, which accept both.
const ArtifactType& mesh_artifact();

// Name of the mesh property in which mesh_artifact()'s reader leaves the faces it turned (an
// OrientationReport as JSON) for the stage to report.
inline constexpr const char* kReadOrientationProperty = "colonflat:read_orientation";

// A stage's first step on an input mesh `port` of `bag` (the one place stages orient meshes):
// reports what the reader turned or reversed, reverses every closed component whose normals still
// point into the lumen (orient_outward, orientation.h: a mesh not read from a file) in the bag, prints one progress line per changed
// component ("<stage>: <port>: component 0 (...): normals pointed into the lumen; reversed")
// and returns the report entry (OrientationReport::to_json()). `topology` (optional) receives
// the mesh's analyze_topology, computed on the way (orient_outward), or the bag's
// topology_entry(port) when one is there and fits the mesh (topology_fits: the producing stage's
// analysis, e.g. reconstruct's; the entry stays in the bag).
nlohmann::json orient_mesh_input(ArtifactBag& bag, const std::string& port, const RunContext& ctx,
                                 const std::string& stage, TopologyReport* topology = nullptr);
// The bag's topology_entry(port), or null when it has none (not checked against the mesh).
const TopologyReport* handed_topology_entry(const ArtifactBag& bag, const std::string& port);
// The same on a mesh already taken from the bag as bag_mesh_for_orienting(bag, port): what a stage
// calls to orient its input on another thread (nothing else may touch the bag's entry meanwhile).
nlohmann::json orient_mesh(Mesh& mesh, const RunContext& ctx, const std::string& stage, const std::string& port,
                           TopologyReport* topology = nullptr);
// The bag's mesh `port`, to be oriented in place by orient_mesh (throws when it is not a mesh).
Mesh& bag_mesh_for_orienting(ArtifactBag& bag, const std::string& port);

// A mesh input as a stage that reads its stand-in (Port::reads_stand_in) finds it in the bag:
// exactly one of the two is set (the Mesh, or in `colonflat run` the TriangleList stand-in).
struct BagSurface {
  Mesh* mesh = nullptr;
  TriangleList* triangles = nullptr;
  explicit operator bool() const { return mesh || triangles; }  // false: the bag has no such entry
};
// The bag's mesh or stand-in `port`, to be oriented in place by orient_surface (throws when it is
// neither).
BagSurface bag_surface_for_orienting(ArtifactBag& bag, const std::string& port);
// orient_mesh on either: a triangle list is analysed (analyze_topology, into `topology` when given)
// and its inward components reversed (orient_outward), with the same notes and report. `known`
// (optional): the surface's topology when the caller has it (handed_topology_entry); used instead of
// analysing when it fits the surface (topology_fits), the same report and surface either way.
nlohmann::json orient_surface(const BagSurface& surface, const RunContext& ctx, const std::string& stage,
                              const std::string& port, TopologyReport* topology = nullptr,
                              const TopologyReport* known = nullptr);

// The bag entry in which a stage may leave analyze_topology of its mesh output `port` for the next
// stages ("<port>.topology", a TopologyReport; reconstruct leaves its final check's of "surface",
// read by denoise's orient_mesh_input and render's snapshot; denoise leaves its verification's of
// "denoised", read by flatten's oriented_mesh_input and render's snapshot). Not a port: never
// written; it stays in the bag, and each reader uses it only when it fits the mesh (topology_fits).
std::string topology_entry(const std::string& port);

// A stage's input mesh as orient_mesh_input leaves it, as a triangle list with its topology.
struct OrientedMesh {
  // to_triangle_list of the bag's mesh after orienting (same order); or, when the bag holds the
  // mesh's stand-in, that list itself, oriented in place (no copy; it lives as long as the bag's entry).
  const TriangleList& triangles() const { return converted ? *converted : *held; }
  std::optional<TriangleList> converted;  // the list made from the bag's Mesh
  const TriangleList* held = nullptr;     // the bag's stand-in when there was no Mesh
  TopologyReport topology;     // analyze_topology(triangles())
  nlohmann::json orientation;  // OrientationReport::to_json(), as orient_mesh_input returns it
};
// orient_mesh_input for a stage that works on a triangle list: the same orientation, notes and
// bag mesh (or stand-in), and the list and its topology without converting or analysing twice. The topology is
// the bag's topology_entry(port) when one is there and fits the mesh (topology_fits, topology.h), else a new
// analysis; the entry stays in the bag either way.
OrientedMesh oriented_mesh_input(ArtifactBag& bag, const std::string& port, const RunContext& ctx,
                                 const std::string& stage);

nlohmann::json topology_to_json(const TopologyReport& t);
nlohmann::json diagnosis_to_json(const MeshDiagnosis& d);
// Human-readable report, one fact per line.
std::string topology_to_text(const TopologyReport& t);

}  // namespace cf
