#include "colonflat/core/mesh_artifact.h"

#include <iomanip>
#include <sstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/orientation.h"
#include "mesh_read.h"

namespace cf {
namespace {
// Whether the reader's note of what it turned or reversed is still on the mesh (a stage reports it).
bool has_read_orientation(const Mesh& mesh) {
  OpenMesh::MPropHandleT<std::string> h;
  return const_cast<Mesh&>(mesh).get_property_handle(h, kReadOrientationProperty);
}
}  // namespace

const ArtifactType& mesh_artifact() {
  static const ArtifactType t{
      "mesh", "triangle mesh (" + mesh_format_list() + "), LPS mm",
      // Stage inputs are read strictly: a degenerate face (fewer than 3 vertices, a repeated
      // corner) is refused with its count and examples rather than silently dropped.
      // Faces turned and components reversed at read time travel with the mesh until the stage's
      // orient_mesh_input() reports them.
      [](const std::filesystem::path& p) {
        LoadPolicy strict;
        strict.drop_degenerate = false;
        LoadedMesh l = load_mesh_oriented(p, strict, true);
        if (!l.orientation.empty()) {
          OpenMesh::MPropHandleT<std::string> h;
          l.mesh.add_property(h, kReadOrientationProperty);
          l.mesh.property(h) = l.orientation.to_json().dump();
        }
        return std::any(std::move(l.mesh));
      },
      [](const std::any& v, const std::filesystem::path& tmp, const std::filesystem::path& target) {
        // write_mesh renames atomically itself; the caller's transaction renames tmp later.
        (void)target;
        if (const auto* list = std::any_cast<TriangleList>(&v)) return write_mesh(*list, tmp);
        write_mesh(std::any_cast<const Mesh&>(v), tmp);
      },
      {".vtp", ".vtk", ".off", ".obj", ".ply", ".stl"},
      [](const std::any& v) -> std::optional<std::any> {
        const Mesh& mesh = std::any_cast<const Mesh&>(v);
        if (has_read_orientation(mesh)) return std::nullopt;
        if (has_deleted_elements(mesh)) return std::nullopt;
        return std::any(to_triangle_list(mesh));
      },
      [](const std::any& v) { return std::any(build_mesh(std::any_cast<const TriangleList&>(v))); }};
  return t;
}

namespace {
// What the reader turned or reversed (kReadOrientationProperty), taken off the mesh.
OrientationReport read_orientation(Mesh& mesh) {
  OrientationReport r;
  OpenMesh::MPropHandleT<std::string> h;
  if (mesh.get_property_handle(h, kReadOrientationProperty)) {
    r = OrientationReport::from_json(nlohmann::json::parse(mesh.property(h)));
    mesh.remove_property(h);
  }
  return r;
}

// The bag's mesh `port`, in place: the bag's value is not const (ArtifactBag::take does the
// same), and a copy of a 1.4 M-face mesh costs more than the check.
nlohmann::json noted(const OrientationReport& r, const RunContext& ctx, const std::string& stage,
                     const std::string& port) {
  for (const std::string& note : r.notes()) ctx.progress(stage + ": " + port + ": " + note);
  return r.to_json();
}
}  // namespace

Mesh& bag_mesh_for_orienting(ArtifactBag& bag, const std::string& port) { return const_cast<Mesh&>(bag.get<Mesh>(port)); }

BagSurface bag_surface_for_orienting(ArtifactBag& bag, const std::string& port) {
  BagSurface s;
  if (std::any_cast<TriangleList>(&bag.raw(port))) s.triangles = &const_cast<TriangleList&>(bag.get<TriangleList>(port));
  else s.mesh = &bag_mesh_for_orienting(bag, port);
  return s;
}

namespace {
// orient_mesh with the mesh's topology when known (`known`, used only when topology_fits the mesh;
// null: analysed): the same report, notes and mesh either way. `list` (optional): the mesh's
// triangle list as it is left (orient_outward's).
nlohmann::json orient_mesh_known(Mesh& mesh, const TopologyReport* known, const RunContext& ctx,
                                 const std::string& stage, const std::string& port, TopologyReport* topology,
                                 std::optional<TriangleList>* list = nullptr) {
  OrientationReport r = read_orientation(mesh);
  r.append(orient_outward(mesh, topology, known, list));
  return noted(r, ctx, stage, port);
}
}  // namespace

nlohmann::json orient_surface(const BagSurface& surface, const RunContext& ctx, const std::string& stage,
                              const std::string& port, TopologyReport* topology, const TopologyReport* known) {
  if (surface.mesh) return orient_mesh_known(*surface.mesh, known, ctx, stage, port, topology);
  TopologyReport topo = known_or_analysed(known, *surface.triangles);
  const OrientationReport r = orient_outward(*surface.triangles, topo);
  if (topology) *topology = std::move(topo);
  return noted(r, ctx, stage, port);
}

nlohmann::json orient_mesh(Mesh& mesh, const RunContext& ctx, const std::string& stage, const std::string& port,
                           TopologyReport* topology) {
  return orient_mesh_known(mesh, nullptr, ctx, stage, port, topology);
}

const TopologyReport* handed_topology_entry(const ArtifactBag& bag, const std::string& port) {
  const std::string entry = topology_entry(port);
  return bag.has(entry) ? &bag.get<TopologyReport>(entry) : nullptr;
}

nlohmann::json orient_mesh_input(ArtifactBag& bag, const std::string& port, const RunContext& ctx,
                                 const std::string& stage, TopologyReport* topology) {
  return orient_mesh_known(bag_mesh_for_orienting(bag, port), handed_topology_entry(bag, port), ctx, stage, port,
                           topology);
}

std::string topology_entry(const std::string& port) { return port + ".topology"; }

OrientedMesh oriented_mesh_input(ArtifactBag& bag, const std::string& port, const RunContext& ctx,
                                 const std::string& stage) {
  const BagSurface held = bag_surface_for_orienting(bag, port);
  const TopologyReport* known = handed_topology_entry(bag, port);
  OrientedMesh in;
  if (held.triangles) {  // the stand-in: oriented in place, no copy
    in.held = held.triangles;
    in.orientation = orient_surface(held, ctx, stage, port, &in.topology, known);
    return in;
  }
  in.orientation = orient_mesh_known(*held.mesh, known, ctx, stage, port, &in.topology, &in.converted);
  return in;
}

namespace {
nlohmann::json opt_int(const std::optional<int>& g) { return g ? nlohmann::json(*g) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json topology_to_json(const TopologyReport& t) {
  nlohmann::json comps = nlohmann::json::array();
  for (std::size_t i = 0; i < t.components.size(); ++i) {
    const auto& c = t.components[i];
    comps.push_back({{"id", i},
                     {"vertices", c.vertices},
                     {"edges", c.edges},
                     {"faces", c.faces},
                     {"boundary_edges", c.boundary_edges},
                     {"boundary_loops", c.boundary_loops},
                     {"euler_characteristic", c.euler},
                     {"genus", opt_int(c.genus)},
                     {"closed", c.closed},
                     {"manifold", c.manifold},
                     {"orientable", c.orientable}});
  }
  return {{"vertices", t.vertices},
          {"edges", t.edges},
          {"faces", t.faces},
          {"unreferenced_vertices", t.unreferenced_vertices},
          {"components", t.components.size()},
          {"boundary_edges", t.boundary_edges},
          {"boundary_loops", t.boundary_loops},
          {"nonmanifold_edges", t.nonmanifold_edges},
          {"nonmanifold_vertices", t.nonmanifold_vertices},
          {"inconsistently_oriented_edges", t.inconsistent_edges},
          {"euler_characteristic", t.euler},
          {"genus", opt_int(t.genus)},
          {"closed", t.closed},
          {"manifold", t.manifold},
          {"orientable", t.orientable},
          {"bounding_box", {{"min", t.bbox_min}, {"max", t.bbox_max}}},
          {"mean_edge_length", t.mean_edge_length},
          {"per_component", comps},
          {"conventions",
           "chi = V - E + F over referenced vertices; per component g = (2 - chi - b) / 2 with b boundary loops; "
           "total genus = sum over components; genus null where a component is non-manifold or non-orientable"}};
}

nlohmann::json diagnosis_to_json(const MeshDiagnosis& d) {
  static const char* names[] = {"note", "repaired", "defect", "fatal"};
  nlohmann::json a = nlohmann::json::array();
  for (const auto& f : d.findings)
    a.push_back({{"code", f.code}, {"severity", names[static_cast<int>(f.severity)]}, {"count", f.count}, {"message", f.message}});
  return a;
}

std::string topology_to_text(const TopologyReport& t) {
  std::ostringstream s;
  auto yn = [](bool b) { return b ? "yes" : "no"; };
  auto g = [](const std::optional<int>& x) { return x ? std::to_string(*x) : std::string("undefined"); };
  s << "vertices        " << t.vertices;
  if (t.unreferenced_vertices) s << " (+" << t.unreferenced_vertices << " unreferenced, not counted)";
  s << "\nedges           " << t.edges << "\nfaces           " << t.faces
    << "\ncomponents      " << t.components.size() << "\nboundary loops  " << t.boundary_loops
    << " (" << t.boundary_edges << " boundary edges)"
    << "\neuler char.     " << t.euler << "   (V - E + F)"
    << "\ngenus           " << g(t.genus) << "   (sum over components of (2 - chi - b) / 2)"
    << "\nclosed          " << yn(t.closed) << "\nmanifold        " << yn(t.manifold);
  if (!t.manifold) s << " (" << t.nonmanifold_edges << " non-manifold edges, " << t.nonmanifold_vertices << " non-manifold vertices)";
  s << "\norientable      " << yn(t.orientable);
  if (t.orientable && t.inconsistent_edges) s << " (" << t.inconsistent_edges << " edges inconsistently oriented)";
  s << std::setprecision(6) << "\nbounding box    [" << t.bbox_min[0] << ", " << t.bbox_min[1] << ", " << t.bbox_min[2]
    << "] .. [" << t.bbox_max[0] << ", " << t.bbox_max[1] << ", " << t.bbox_max[2] << "]"
    << "\nmean edge       " << t.mean_edge_length << "\n";
  if (t.components.size() > 1) {
    s << "per component (largest first):\n";
    const std::size_t shown = std::min<std::size_t>(t.components.size(), 20);
    for (std::size_t i = 0; i < shown; ++i) {
      const auto& c = t.components[i];
      s << "  #" << i << ": V=" << c.vertices << " E=" << c.edges << " F=" << c.faces << " chi=" << c.euler
        << " b=" << c.boundary_loops << " genus=" << g(c.genus) << (c.manifold ? "" : " non-manifold") << "\n";
    }
    if (shown < t.components.size()) s << "  ... " << (t.components.size() - shown) << " more (see --json)\n";
  }
  return s.str();
}

}  // namespace cf
