#include "colonflat/core/validation.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/orientation.h"

namespace cf {
namespace {

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

template <class T, class F>
std::string examples(const std::vector<T>& xs, F fmt) {
  if (xs.empty()) return "";
  std::ostringstream s;
  s << " (e.g. ";
  for (std::size_t i = 0; i < xs.size(); ++i) s << (i ? ", " : "") << fmt(xs[i]);
  s << ")";
  return s.str();
}

std::string edge_str(const std::array<int, 2>& e) {
  return std::to_string(e[0]) + "-" + std::to_string(e[1]);
}

}  // namespace

bool MeshDiagnosis::has(const std::string& code) const { return find(code) != nullptr; }

const Finding* MeshDiagnosis::find(const std::string& code) const {
  for (const auto& f : findings)
    if (f.code == code) return &f;
  return nullptr;
}

bool MeshDiagnosis::has_at_least(Severity s) const {
  for (const auto& f : findings)
    if (f.severity >= s) return true;
  return false;
}

std::string MeshDiagnosis::summary(Severity s) const {
  std::string out;
  for (const auto& f : findings) {
    if (f.severity < s) continue;
    if (!out.empty()) out += "; ";
    out += f.message;
  }
  return out;
}

namespace {

// diagnose_soup's checks, one per function, each adding at most one finding per defect kind.

// "vertex 3: y = nan": the vertex and its first coordinate that is not a finite number.
std::string nonfinite_vertex_words(std::size_t v, const std::array<double, 3>& p) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(p[k])) {
      std::ostringstream s;
      s << "vertex " << v << ": " << "xyz"[k] << " = " << p[k];  // prints nan, inf or -inf
      return s.str();
    }
  return "vertex " + std::to_string(v);
}

void check_nonfinite_coordinates(const PolygonSoup& soup, MeshDiagnosis& d) {
  std::vector<std::string> bad;
  std::size_t n = 0;
  for (std::size_t v = 0; v < soup.points.size(); ++v) {
    const auto& p = soup.points[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      ++n;
      if (bad.size() < 5) bad.push_back(nonfinite_vertex_words(v, p));
    }
  }
  if (n)
    d.findings.push_back({"nonfinite_coordinates", Severity::kFatal, n,
                          plural(n, "vertex", "vertices") + " with NaN or infinite coordinates" +
                              examples(bad, [](const std::string& s) { return s; })});
}

std::string listed(const std::vector<std::string>& v) {
  return examples(v, [](const std::string& s) { return s; });
}

// Per-face defects: counts and up to 5 examples of each kind.
struct FaceDefects {
  std::size_t out_of_range = 0, too_small = 0, polygons = 0, repeated = 0;
  std::vector<std::string> ex_range, ex_small, ex_poly, ex_rep;
};

// One face: ids in range (marking the vertices it uses), size, a repeated id.
void inspect_face(const PolygonSoup& soup, std::size_t f, std::vector<std::uint8_t>& used, FaceDefects& fd) {
  const std::size_t P = soup.points.size();
  const std::size_t n = soup.face_size(f);
  const std::int64_t* ids = soup.face(f);
  bool in_range = true;
  for (std::size_t k = 0; k < n; ++k) {
    if (ids[k] < 0 || static_cast<std::size_t>(ids[k]) >= P) {
      in_range = false;
      if (fd.ex_range.size() < 5) fd.ex_range.push_back("face " + std::to_string(f) + " -> " + std::to_string(ids[k]));
    } else {
      used[ids[k]] = 1;
    }
  }
  if (!in_range) ++fd.out_of_range;
  if (n < 3) {
    ++fd.too_small;
    if (fd.ex_small.size() < 5) fd.ex_small.push_back("face " + std::to_string(f));
    return;
  }
  if (n > 3) {
    ++fd.polygons;
    if (fd.ex_poly.size() < 5) fd.ex_poly.push_back("face " + std::to_string(f) + " has " + std::to_string(n));
  }
  bool rep = false;
  for (std::size_t a = 0; a < n && !rep; ++a)
    for (std::size_t b = a + 1; b < n && !rep; ++b) rep = ids[a] == ids[b];
  if (rep) {
    ++fd.repeated;
    if (fd.ex_rep.size() < 5) fd.ex_rep.push_back("face " + std::to_string(f));
  }
}

// Every face inspected; findings for ids out of range, small faces, polygons and repeated ids.
// `used` marks the vertices some face references. Returns false when an id is out of range.
bool check_faces(const PolygonSoup& soup, std::vector<std::uint8_t>& used, MeshDiagnosis& d) {
  const std::size_t P = soup.points.size();
  FaceDefects fd;
  for (std::size_t f = 0; f < soup.num_faces(); ++f) inspect_face(soup, f, used, fd);
  if (fd.out_of_range)
    d.findings.push_back({"index_out_of_range", Severity::kFatal, fd.out_of_range,
                          plural(fd.out_of_range, "face references", "faces reference") +
                              " vertex ids outside 0.." + std::to_string(P == 0 ? 0 : P - 1) + listed(fd.ex_range)});
  if (fd.too_small)
    d.findings.push_back({"faces_too_small", Severity::kDefect, fd.too_small,
                          plural(fd.too_small, "face has", "faces have") + " fewer than 3 vertices" + listed(fd.ex_small)});
  if (fd.polygons)
    d.findings.push_back({"non_triangle_faces", Severity::kRepaired, fd.polygons,
                          plural(fd.polygons, "face is a polygon", "faces are polygons") +
                              " with more than 3 vertices, fan-triangulated" + listed(fd.ex_poly)});
  if (fd.repeated)
    d.findings.push_back({"degenerate_faces", Severity::kDefect, fd.repeated,
                          plural(fd.repeated, "degenerate face repeats", "degenerate faces repeat") +
                              " a vertex id" + listed(fd.ex_rep)});
  return fd.out_of_range == 0;
}

// Duplicate faces: same vertex set (either orientation).
void check_duplicate_faces(const PolygonSoup& soup, MeshDiagnosis& d) {
  const std::size_t F = soup.num_faces();
  std::vector<std::pair<std::vector<std::int64_t>, std::size_t>> keys;
  keys.reserve(F);
  for (std::size_t f = 0; f < F; ++f) {
    std::vector<std::int64_t> k(soup.face(f), soup.face(f) + soup.face_size(f));
    std::sort(k.begin(), k.end());
    keys.emplace_back(std::move(k), f);
  }
  std::sort(keys.begin(), keys.end());
  std::size_t dup = 0;
  std::vector<std::string> ex_dup;
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i].first == keys[i - 1].first) {
      ++dup;
      if (ex_dup.size() < 5)
        ex_dup.push_back("face " + std::to_string(keys[i].second) + " = face " + std::to_string(keys[i - 1].second));
    }
  }
  if (dup)
    d.findings.push_back({"duplicate_faces", Severity::kDefect, dup,
                          plural(dup, "duplicate face uses", "duplicate faces use") +
                              " the same vertices as another face" + listed(ex_dup)});
}

void check_unreferenced_vertices(const std::vector<std::uint8_t>& used, MeshDiagnosis& d) {
  std::size_t n = 0;
  std::vector<std::string> exv;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (!used[v]) {
      ++n;
      if (exv.size() < 5) exv.push_back("v" + std::to_string(v));
    }
  if (n)
    d.findings.push_back({"unreferenced_vertices", Severity::kRepaired, n,
                          plural(n, "vertex is", "vertices are") + " not used by any face (ignored)" + listed(exv)});
}

// Coincident points: distinct referenced vertices at exactly the same position.
void check_coincident_vertices(const PolygonSoup& soup, const std::vector<std::uint8_t>& used, MeshDiagnosis& d) {
  std::vector<std::uint32_t> order;
  order.reserve(soup.points.size());
  for (std::size_t v = 0; v < soup.points.size(); ++v)
    if (used[v]) order.push_back(static_cast<std::uint32_t>(v));
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return soup.points[a] < soup.points[b] || (soup.points[a] == soup.points[b] && a < b);
  });
  std::size_t extra = 0;
  std::vector<std::string> exc;
  for (std::size_t i = 1; i < order.size(); ++i) {
    if (soup.points[order[i]] == soup.points[order[i - 1]]) {
      ++extra;
      if (exc.size() < 5) exc.push_back("v" + std::to_string(order[i]) + " = v" + std::to_string(order[i - 1]));
    }
  }
  if (extra)
    d.findings.push_back({"coincident_vertices", Severity::kNote, extra,
                          plural(extra, "vertex duplicates", "vertices duplicate") +
                              " the position of another (an unwelded seam? weld them before use)" + listed(exc)});
}

}  // namespace

MeshDiagnosis diagnose_soup(const PolygonSoup& soup) {
  MeshDiagnosis d;
  const std::size_t P = soup.points.size();
  if (soup.num_faces() == 0) {
    d.findings.push_back({"empty", Severity::kFatal, 0,
                          P == 0 ? "empty mesh: no vertices and no faces"
                                 : "empty mesh: " + plural(P, "vertex", "vertices") + " but no faces"});
    return d;
  }
  check_nonfinite_coordinates(soup, d);
  std::vector<std::uint8_t> used(P, 0);
  if (!check_faces(soup, used, d)) return d;  // the checks below index points
  check_duplicate_faces(soup, d);
  check_unreferenced_vertices(used, d);
  check_coincident_vertices(soup, used, d);
  return d;
}

void add_topology_findings(const TopologyReport& t, bool allow_boundary, MeshDiagnosis& d) {
  if (t.nonmanifold_edges)
    d.findings.push_back({"nonmanifold_edges", Severity::kDefect, t.nonmanifold_edges,
                          plural(t.nonmanifold_edges, "non-manifold edge has", "non-manifold edges have") +
                              " 3 or more faces" + examples(t.example_nonmanifold_edges, edge_str)});
  if (t.nonmanifold_vertices)
    d.findings.push_back({"nonmanifold_vertices", Severity::kDefect, t.nonmanifold_vertices,
                          plural(t.nonmanifold_vertices, "non-manifold vertex", "non-manifold vertices") +
                              " (faces around them form more than one fan)" +
                              examples(t.example_nonmanifold_vertices, [](int v) { return "v" + std::to_string(v); })});
  if (t.boundary_edges)
    d.findings.push_back({"boundary_edges", allow_boundary ? Severity::kNote : Severity::kDefect, t.boundary_edges,
                          "open surface: " + plural(t.boundary_edges, "boundary edge", "boundary edges") + " in " +
                              plural(t.boundary_loops, "boundary loop", "boundary loops") +
                              examples(t.example_boundary_edges, edge_str)});
  if (!t.orientable) {
    std::size_t c = 0;
    while (c + 1 < t.components.size() && t.components[c].orientable) ++c;
    d.findings.push_back({"non_orientable", Severity::kDefect, 1,
                          "the surface is not orientable: component " + std::to_string(c) + " (" +
                              std::to_string(t.components.empty() ? t.faces : t.components[c].faces) +
                              " faces) has no inside and no outside (a Moebius-like twist)"});
  }
  else if (t.inconsistent_edges)
    d.findings.push_back({"inconsistent_orientation", Severity::kRepaired, t.inconsistent_edges,
                          "inconsistent orientation: " +
                              plural(t.inconsistent_edges, "edge is", "edges are") +
                              " traversed the same way by both faces (faces re-oriented)" +
                              examples(t.example_inconsistent_edges, edge_str)});
  if (t.components.size() > 1)
    d.findings.push_back({"several_components", Severity::kNote, t.components.size(),
                          std::to_string(t.components.size()) + " connected components"});
}

void add_orientation_findings(TriangleList t, const TopologyReport& topo, MeshDiagnosis& d) {
  if (!topo.manifold || !topo.orientable || topo.components.empty()) return;
  make_consistent(t, topo);
  const std::vector<ComponentSide> sides = component_sides(t, topo);
  std::size_t n = 0;
  std::string first;
  for (std::size_t c = 0; c < sides.size(); ++c) {
    if (!sides[c].inward()) continue;
    if (n++ == 0) {
      std::ostringstream s;
      s.setf(std::ios::fixed);
      s.precision(1);
      s << "component " << c << " (" << sides[c].faces << " faces, signed volume " << sides[c].volume_mm3 / 1e3 << " mL"
        << (sides[c].depth ? ", inside another component" : "") << ")";
      first = s.str();
    }
  }
  if (n)
    d.findings.push_back({"inward_normals", Severity::kNote, n,
                          plural(n, "closed component has", "closed components have") +
                              " normals pointing into the lumen, e.g. " + first +
                              "; the stages reverse them (docs/conventions.md, Orientation)"});
}

TriangleList soup_to_triangles(const PolygonSoup& soup, const LoadPolicy& policy,
                               const MeshDiagnosis& diag) {
  for (const auto& f : diag.findings)
    if (f.severity == Severity::kFatal) throw PreconditionError(f.message);
  if (!policy.triangulate && diag.has("non_triangle_faces"))
    throw PreconditionError(diag.find("non_triangle_faces")->message);
  if (!policy.drop_degenerate && (diag.has("degenerate_faces") || diag.has("faces_too_small")))
    throw PreconditionError(diag.summary(Severity::kDefect));
  TriangleList t;
  const std::size_t P = soup.points.size();
  std::vector<int> remap(P, -1);
  std::vector<std::uint8_t> used(P, 0);
  auto keep_face = [&](const std::int64_t* ids, std::size_t n) {
    if (n < 3) return false;
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = a + 1; b < n; ++b)
        if (ids[a] == ids[b]) return false;
    return true;
  };
  for (std::size_t f = 0; f < soup.num_faces(); ++f)
    if (keep_face(soup.face(f), soup.face_size(f)))
      for (std::size_t k = 0; k < soup.face_size(f); ++k) used[soup.face(f)[k]] = 1;
  for (std::size_t v = 0; v < P; ++v) {
    if (used[v] || !policy.drop_unreferenced) {
      remap[v] = static_cast<int>(t.points.size());
      t.points.push_back(soup.points[v]);
    }
  }
  t.triangles.reserve(soup.num_faces());
  for (std::size_t f = 0; f < soup.num_faces(); ++f) {
    const std::int64_t* ids = soup.face(f);
    const std::size_t n = soup.face_size(f);
    if (!keep_face(ids, n)) continue;
    for (std::size_t k = 1; k + 1 < n; ++k)
      t.triangles.push_back({remap[ids[0]], remap[ids[k]], remap[ids[k + 1]]});
  }
  return t;
}

OrientationReport make_orientation_consistent(TriangleList& t, const TopologyReport& topo, bool fix_orientation) {
  if (!topo.manifold) {
    MeshDiagnosis d;
    add_topology_findings(topo, true, d);
    throw PreconditionError("not a 2-manifold: " + d.summary(Severity::kDefect));
  }
  if (topo.inconsistent_edges && !fix_orientation && topo.orientable)
    throw PreconditionError("inconsistent orientation on " + std::to_string(topo.inconsistent_edges) + " edges");
  return make_consistent(t, topo);  // refuses a non-orientable component with its size
}

Mesh triangles_to_mesh(TriangleList t, const TopologyReport& topo, bool fix_orientation) {
  make_orientation_consistent(t, topo, fix_orientation);
  return build_mesh(t);
}

}  // namespace cf
