// Which components of flatten's input are colon wall to flatten, and why the others are not: each
// rejected component is named with its size and the cause (see docs/flatten.md, "Input").
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "colonflat/core/error.h"
#include "colonflat/core/orientation.h"
#include "flatten_internal.h"

namespace cf::flat_detail {
namespace {

std::string fixed(double x, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, x);
  return text;
}

// Signed volume (x6) of the surface closed by cones to its centroid: > 0 when normals point out
// (also a fair sign for a tube open at its two ends).
double cone_volume(const TriangleList& mesh, const TopologyReport& topo, int c) {
  V3 centroid = V3::Zero();
  std::size_t n = 0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    if (topo.face_component[f] == c)
      for (int v : mesh.triangles[f]) centroid += V3(mesh.points[v][0], mesh.points[v][1], mesh.points[v][2]), ++n;
  centroid /= double(std::max<std::size_t>(n, 1));
  double vol = 0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (topo.face_component[f] != c) continue;
    V3 q[3];
    for (int k = 0; k < 3; ++k) {
      const auto& p = mesh.points[mesh.triangles[f][k]];
      q[k] = V3(p[0], p[1], p[2]) - centroid;
    }
    vol += q[0].dot(q[1].cross(q[2]));
  }
  return vol;
}

}  // namespace

ComponentScreen::ComponentScreen(const TriangleList& mesh, const TopologyReport& topo, const FlattenOptions& o)
    : mesh_(mesh), topo_(topo), o_(o), sides_(component_sides(mesh, topo)) {}

std::string ComponentScreen::name(std::size_t c) const {
  const ComponentSide& s = sides_[c];
  std::string t = "component " + std::to_string(c) + " (" + std::to_string(s.faces) + " faces, " +
                  fixed(s.area_mm2, 0) + " mm2";
  if (s.closed) t += ", encloses " + fixed(std::abs(s.volume_mm3) / 1e3, 1) + " mL";
  return t + ")";
}

bool ComponentScreen::admit(std::size_t c) {
  const ComponentTopology& ct = topo_.components[c];
  const std::size_t largest = topo_.components[0].faces;
  if (ct.faces < 8) return skip(c, "too small: fewer than 8 faces");
  if (double(ct.faces) < o_.min_segment_fraction * double(largest))
    return skip(c, "too small: under --min-segment-fraction " + fixed(o_.min_segment_fraction, 3) +
                       " of the largest component (" + std::to_string(largest) + " faces)");
  if (!ct.genus) throw PreconditionError(name(c) + " is not an orientable 2-manifold");
  if (*ct.genus > 0)
    throw PreconditionError(name(c) + " has genus " + std::to_string(*ct.genus) +
                            " (handles); flatten needs genus 0: run denoise first");
  if (ct.boundary_loops > 2)
    throw PreconditionError(name(c) + " is open in " + std::to_string(ct.boundary_loops) +
                            " places (boundary loops); flatten needs a closed surface or a tube open at its two ends");
  const ComponentSide& s = sides_[c];
  if (s.closed && s.inward())
    throw PreconditionError(name(c) + ": its normals point into the lumen (signed volume " +
                            fixed(s.volume_mm3 / 1e3, 1) + " mL" + (s.depth ? ", inside another component" : "") +
                            "); orient it outward (colonflat flatten does: core orient_outward)");
  if (s.closed && s.cavity())
    return skip(c, "the wall of a cavity inside another component (normals into the cavity): not colon wall");
  return true;
}

double ComponentScreen::lumen_sign(std::size_t c) const {
  const ComponentSide& s = sides_[c];
  if (s.closed && s.determined) return s.volume_mm3 >= 0 ? 1.0 : -1.0;
  return cone_volume(mesh_, topo_, int(c)) >= 0 ? 1.0 : -1.0;
}

bool ComponentScreen::skip(std::size_t c, const std::string& why) {
  skipped_.push_back(name(c) + ": " + why);
  return false;
}

void ComponentScreen::nothing_flattened() const {
  std::string list;
  const std::size_t shown = std::min<std::size_t>(skipped_.size(), 3);
  for (std::size_t i = 0; i < shown; ++i) list += (i ? "; " : "") + skipped_[i];
  if (skipped_.size() > shown) list += "; and " + std::to_string(skipped_.size() - shown) + " more";
  throw PreconditionError("no component to flatten: " + list);
}

}  // namespace cf::flat_detail
