#include "colonflat/core/orientation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <sstream>

#include "colonflat/core/bucket_slots.h"
#include "colonflat/core/error.h"

namespace cf {
namespace {

using P3 = std::array<double, 3>;

P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const P3& a) { return std::sqrt(dot(a, a)); }

// Solid angle of triangle (a, b, c) seen from p (Van Oosterom & Strackee 1983), signed by the
// triangle's orientation; over a closed surface it sums to +-4 pi inside and 0 outside.
double solid_angle(const P3& a0, const P3& b0, const P3& c0, const P3& p) {
  const P3 a = sub(a0, p), b = sub(b0, p), c = sub(c0, p);
  const double la = norm(a), lb = norm(b), lc = norm(c);
  const double num = dot(a, cross(b, c));
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

// The faces of each component, as offsets into one list.
struct FacesByComponent {
  std::vector<std::size_t> start;
  std::vector<std::uint32_t> face;
  FacesByComponent(const TopologyReport& topo) : face(topo.face_component.size()) {
    BucketSlots<std::size_t> slots(topo.components.size());
    for (int c : topo.face_component) slots.count(std::size_t(c));
    slots.close();
    for (std::size_t f = 0; f < face.size(); ++f) face[slots.place(std::size_t(topo.face_component[f]))] = std::uint32_t(f);
    start = std::move(slots).take_starts();
  }
};

// Area, signed volume (relative to the component's first vertex, for precision), bounding box and
// a probe vertex per component.
struct Extent {
  P3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  P3 probe{0, 0, 0};
  bool inside(const Extent& o) const {
    for (int k = 0; k < 3; ++k)
      if (lo[k] < o.lo[k] || hi[k] > o.hi[k]) return false;
    return true;
  }
};

void measure_components(const TriangleList& t, const TopologyReport& topo, const FacesByComponent& fc,
                        std::vector<ComponentSide>& sides, std::vector<Extent>& ext) {
  for (std::size_t c = 0; c < sides.size(); ++c) {
    ComponentSide& s = sides[c];
    s.faces = topo.components[c].faces;
    s.closed = topo.components[c].closed;
    if (fc.start[c] == fc.start[c + 1]) continue;
    const P3 ref = t.points[std::size_t(t.triangles[fc.face[fc.start[c]]][0])];
    ext[c].probe = ref;
    double vol6 = 0, area2 = 0;
    for (std::size_t i = fc.start[c]; i < fc.start[c + 1]; ++i) {
      const auto& tr = t.triangles[fc.face[i]];
      const P3& a = t.points[std::size_t(tr[0])];
      const P3 &b = t.points[std::size_t(tr[1])], &cc = t.points[std::size_t(tr[2])];
      const P3 n = cross(sub(b, a), sub(cc, a));
      area2 += norm(n);
      vol6 += dot(sub(a, ref), cross(sub(b, ref), sub(cc, ref)));
      for (const P3* q : {&a, &b, &cc})
        for (int k = 0; k < 3; ++k) ext[c].lo[k] = std::min(ext[c].lo[k], (*q)[k]), ext[c].hi[k] = std::max(ext[c].hi[k], (*q)[k]);
    }
    s.area_mm2 = area2 / 2;
    if (!s.closed) continue;
    s.volume_mm3 = vol6 / 6;
    s.determined = std::abs(s.volume_mm3) > kFlatVolumeRatio * std::pow(s.area_mm2, 1.5);
  }
}

// Nesting depth: for every closed component d, the generalised winding number of d at the probe
// vertex of each component whose box lies in d's box; |w| > 1/2 means inside.
void nesting_depths(const TriangleList& t, const FacesByComponent& fc, const std::vector<Extent>& ext,
                    std::vector<ComponentSide>& sides) {
  for (std::size_t d = 0; d < sides.size(); ++d) {
    if (!sides[d].closed) continue;
    std::vector<std::size_t> probes;
    for (std::size_t c = 0; c < sides.size(); ++c)
      if (c != d && sides[c].faces > 0 && ext[c].inside(ext[d])) probes.push_back(c);
    if (probes.empty()) continue;
    std::vector<double> w(probes.size(), 0.0);
    for (std::size_t i = fc.start[d]; i < fc.start[d + 1]; ++i) {
      const auto& tr = t.triangles[fc.face[i]];
      const P3 &a = t.points[std::size_t(tr[0])], &b = t.points[std::size_t(tr[1])], &c = t.points[std::size_t(tr[2])];
      for (std::size_t k = 0; k < probes.size(); ++k) w[k] += solid_angle(a, b, c, ext[probes[k]].probe);
    }
    for (std::size_t k = 0; k < probes.size(); ++k)
      if (std::abs(w[k]) > 2 * M_PI) ++sides[probes[k]].depth;  // |w| / (4 pi) > 1/2
  }
}

std::string fixed(double x, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << x;
  return s.str();
}

// "3.80 L", "12.5 mL", "40 mm3": a volume in the unit that reads best.
std::string volume_text(double mm3) {
  const double a = std::abs(mm3);
  if (a >= 1e6) return fixed(mm3 / 1e6, 2) + " L";
  if (a >= 1e3) return fixed(mm3 / 1e3, 1) + " mL";
  return fixed(mm3, 0) + " mm3";
}

double component_area(const TriangleList& t, const FacesByComponent& fc, std::size_t c) {
  double a2 = 0;
  for (std::size_t i = fc.start[c]; i < fc.start[c + 1]; ++i) {
    const auto& tr = t.triangles[fc.face[i]];
    const P3& a = t.points[std::size_t(tr[0])];
    a2 += norm(cross(sub(t.points[std::size_t(tr[1])], a), sub(t.points[std::size_t(tr[2])], a)));
  }
  return a2 / 2;
}

// Faces sharing a manifold edge (two faces), as offsets into one list.
struct FaceAdjacency {
  std::vector<std::uint32_t> start, next;
  explicit FaceAdjacency(const TriangleList& t) {
    const std::size_t F = t.triangles.size();
    std::vector<std::pair<std::uint64_t, std::uint32_t>> recs;
    recs.reserve(3 * F);
    for (std::size_t f = 0; f < F; ++f)
      for (int k = 0; k < 3; ++k) {
        std::uint64_t a = std::uint32_t(t.triangles[f][k]), b = std::uint32_t(t.triangles[f][(k + 1) % 3]);
        if (a > b) std::swap(a, b);
        recs.emplace_back((a << 32) | b, std::uint32_t(f));
      }
    std::sort(recs.begin(), recs.end());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::size_t i = 0; i + 1 < recs.size(); ++i)
      if (recs[i].first == recs[i + 1].first && (i + 2 >= recs.size() || recs[i + 2].first != recs[i].first) &&
          (i == 0 || recs[i - 1].first != recs[i].first))
        pairs.emplace_back(recs[i].second, recs[i + 1].second);
    BucketSlots<std::uint32_t> slots(F);
    for (auto& p : pairs) slots.count(p.first), slots.count(p.second);
    slots.close();
    next.resize(slots.total());
    for (auto& p : pairs) next[slots.place(p.first)] = p.second, next[slots.place(p.second)] = p.first;
    start = std::move(slots).take_starts();
  }
};

// Whether triangle `tr` traverses the directed edge a -> b.
bool traverses(const std::array<int, 3>& tr, int a, int b) {
  for (int k = 0; k < 3; ++k)
    if (tr[k] == a && tr[(k + 1) % 3] == b) return true;
  return false;
}

// Turns the faces of one edge-connected piece (from `seed`) to agree with the seed; then, if more
// than half of the piece was turned, turns the piece back so that its majority keeps its
// orientation. Returns the piece's faces; `turn` marks the faces to turn.
std::vector<std::uint32_t> agree_piece(const TriangleList& t, const FaceAdjacency& adj, std::uint32_t seed,
                                       std::vector<std::uint8_t>& seen, std::vector<std::uint8_t>& turn) {
  std::vector<std::uint32_t> piece{seed};
  seen[seed] = 1;
  std::size_t turned = 0;
  for (std::size_t q = 0; q < piece.size(); ++q) {
    const std::uint32_t f = piece[q];
    std::array<int, 3> tf = t.triangles[f];
    if (turn[f]) std::swap(tf[1], tf[2]);
    for (std::uint32_t i = adj.start[f]; i < adj.start[f + 1]; ++i) {
      const std::uint32_t g = adj.next[i];
      if (seen[g]) continue;
      seen[g] = 1;
      for (int k = 0; k < 3; ++k)
        if (traverses(t.triangles[g], tf[k], tf[(k + 1) % 3])) {  // same direction as f: turn g
          turn[g] = 1;
          ++turned;
          break;
        }
      piece.push_back(g);
    }
  }
  if (2 * turned > piece.size())
    for (std::uint32_t f : piece) turn[f] ^= 1;
  return piece;
}

}  // namespace

std::vector<ComponentSide> component_sides(const TriangleList& t, const TopologyReport& topo) {
  std::vector<ComponentSide> sides(topo.components.size());
  if (sides.empty()) return sides;
  const FacesByComponent fc(topo);
  std::vector<Extent> ext(sides.size());
  measure_components(t, topo, fc, sides, ext);
  nesting_depths(t, fc, ext, sides);
  return sides;
}

std::string OrientationChange::note() const {
  std::string s = "component " + std::to_string(component) + " (" + std::to_string(faces) + " faces, " +
                  (volume_mm3 != 0 ? volume_text(std::abs(volume_mm3)) : fixed(area_mm2, 0) + " mm2") + "): ";
  if (flipped_faces)
    s += std::to_string(flipped_faces) + (flipped_faces == 1 ? " face was" : " faces were") +
         " oriented against their neighbours; turned" + (reversed ? "; " : "");
  if (reversed) s += "normals pointed into the lumen; reversed";
  return s;
}

std::size_t OrientationReport::reversed_components() const {
  return std::size_t(std::count_if(changes.begin(), changes.end(), [](const auto& c) { return c.reversed; }));
}

std::size_t OrientationReport::flipped_faces() const {
  std::size_t n = 0;
  for (const auto& c : changes) n += c.flipped_faces;
  return n;
}

std::vector<std::string> OrientationReport::notes() const {
  std::vector<std::string> out;
  for (const auto& c : changes) out.push_back(c.note());
  return out;
}

nlohmann::json OrientationReport::to_json() const {
  nlohmann::json comps = nlohmann::json::array();
  for (const auto& c : changes)
    comps.push_back({{"component", c.component}, {"faces", c.faces}, {"area_mm2", c.area_mm2},
                     {"volume_mm3", c.volume_mm3}, {"flipped_faces", c.flipped_faces}, {"reversed", c.reversed}});
  return {{"reversed_components", reversed_components()}, {"flipped_faces", flipped_faces()},
          {"notes", notes()}, {"components", comps}};
}

OrientationReport OrientationReport::from_json(const nlohmann::json& j) {
  OrientationReport r;
  for (const auto& c : j.value("components", nlohmann::json::array()))
    r.changes.push_back({c.at("component").get<int>(), c.at("faces").get<std::size_t>(), c.at("area_mm2").get<double>(),
                         c.at("volume_mm3").get<double>(), c.at("flipped_faces").get<std::size_t>(),
                         c.at("reversed").get<bool>()});
  return r;
}

void OrientationReport::append(const OrientationReport& other) {
  for (const auto& c : other.changes) {
    auto it = std::find_if(changes.begin(), changes.end(), [&](const auto& x) { return x.component == c.component; });
    if (it == changes.end()) {
      changes.push_back(c);
      continue;
    }
    it->flipped_faces += c.flipped_faces;
    it->reversed = it->reversed != c.reversed;
    if (c.volume_mm3 != 0) it->volume_mm3 = c.volume_mm3;
  }
}

OrientationReport make_consistent(TriangleList& t, const TopologyReport& topo) {
  OrientationReport r;
  const FacesByComponent fc(topo);
  for (std::size_t c = 0; c < topo.components.size(); ++c)
    if (!topo.components[c].orientable)
      throw PreconditionError("component " + std::to_string(c) + " (" + std::to_string(topo.components[c].faces) +
                              " faces, " + fixed(component_area(t, fc, c), 0) +
                              " mm2) is not orientable: no orientation of its faces agrees across every edge "
                              "(a Moebius-like twist), so it has no inside and no outside");
  if (topo.inconsistent_edges == 0) return r;
  const std::size_t F = t.triangles.size();
  const FaceAdjacency adj(t);
  std::vector<std::uint8_t> seen(F, 0), turn(F, 0);
  std::vector<std::size_t> turned(topo.components.size(), 0);
  for (std::size_t s = 0; s < F; ++s) {
    if (seen[s]) continue;
    for (std::uint32_t f : agree_piece(t, adj, std::uint32_t(s), seen, turn))
      if (turn[f]) std::swap(t.triangles[f][1], t.triangles[f][2]), ++turned[std::size_t(topo.face_component[f])];
  }
  for (std::size_t c = 0; c < turned.size(); ++c)
    if (turned[c]) r.changes.push_back({int(c), topo.components[c].faces, component_area(t, fc, c), 0.0, turned[c], false});
  return r;
}

OrientationReport orient_outward(TriangleList& t, const TopologyReport& topo) {
  OrientationReport r;
  const std::vector<ComponentSide> sides = component_sides(t, topo);
  std::vector<std::uint8_t> flip(sides.size(), 0);
  for (std::size_t c = 0; c < sides.size(); ++c) {
    if (!sides[c].inward()) continue;
    flip[c] = 1;
    r.changes.push_back({int(c), sides[c].faces, sides[c].area_mm2, sides[c].volume_mm3, 0, true});
  }
  if (r.empty()) return r;
  for (std::size_t f = 0; f < t.triangles.size(); ++f)
    if (flip[std::size_t(topo.face_component[f])]) std::swap(t.triangles[f][1], t.triangles[f][2]);
  return r;
}

OrientationReport orient_outward(Mesh& mesh, TopologyReport* topology, const TopologyReport* known,
                                 std::optional<TriangleList>* list) {
  TriangleList t = to_triangle_list(mesh);
  TopologyReport topo = known_or_analysed(known, t);
  OrientationReport r = orient_outward(t, topo);
  if (!r.empty()) {
    mesh = build_mesh(t);
    if (list) t = to_triangle_list(mesh);
  }
  if (list) *list = std::move(t);
  if (topology) *topology = std::move(topo);
  return r;
}

Mesh build_mesh(const TriangleList& t) {
  Mesh mesh;
  mesh.reserve(t.points.size(), t.triangles.size() * 3 / 2, t.triangles.size());
  for (const auto& p : t.points) mesh.add_vertex(Vec3(p[0], p[1], p[2]));
  for (std::size_t f = 0; f < t.triangles.size(); ++f) {
    const auto& tr = t.triangles[f];
    auto fh = mesh.add_face(Mesh::VertexHandle(tr[0]), Mesh::VertexHandle(tr[1]), Mesh::VertexHandle(tr[2]));
    if (!fh.is_valid())
      throw PreconditionError("face " + std::to_string(f) + " could not be added to the halfedge mesh");
  }
  return mesh;
}

}  // namespace cf
