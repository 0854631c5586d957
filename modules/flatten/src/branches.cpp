// Side branches of a colon segment: regions the conformal map collapses (a pouch behind a neck).
//
// A blind pouch hanging off the tube through a neck of length l is shrunk by the conformal map by
// a factor that falls exponentially with its depth (about exp(-2 pi depth / l)), so no single map
// onto a rectangle can show it. Each such pouch is found and cut off at its neck, to be flattened as
// a band of its own:
//  1. collapsed clusters: edge-connected faces whose 2D/3D area ratio is below 0.01, by area;
//  2. the flat distance d(v) = |f(v) - c| from the cluster's centre c (periodic in y). Because the
//     conformal map f is a bijection, each sub-level set {d < r} is a topological disk around the
//     pouch, and its rim a closed curve on the surface;
//  3. the neck: the radius r >= the cluster's extent whose rim is shortest in 3D (inside the pouch
//     the rim runs around its body, beyond the neck it grows with the tube wall);
//  4. the branch: faces with d < r connected to the cluster, with any enclosed island added; kept
//     when it is a disk holding lumen (a polyp on a stalk, tissue, stays on the colon band), or
//     when the cluster is crushed below what the map resolves (a fold in it: a long strand stump,
//     tissue, that the colon band could only leave out of its map).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "colonflat/core/threads.h"
#include "branch_ends.h"
#include "flatten_internal.h"

namespace cf::flat_detail {
namespace {

constexpr double kCollapsedRatio = 0.01;  // 2D/3D area ratio below which a face is collapsed
// Islands of a candidate branch's outside are looked for from its border, each piece flooded up to
// twice the branch's faces + this many (enclosed_by: the budget sets only the speed, not the result).
constexpr std::size_t kIslandBudgetMin = 4096;
constexpr int kRadii = 64;                 // radii sampled between the cluster's extent and the limit

struct Cluster {
  std::vector<int> faces;
  double area = 0;
};

// One cluster's search: the branch (when kept), every face inside its neck (kept or not) and the
// debug line.
struct Candidate {
  BranchCut cut;
  bool kept = false;
  std::vector<int> region;
  std::string debug;
};

class BranchFinder {
 public:
  BranchFinder(const Surface& s, const Edges& E, const Embedding& emb, double length, double lumen_sign)
      : s_(s), E_(E), emb_(emb), length_(length), lumen_sign_(lumen_sign), area3_(s.t.size()), taken_(s.t.size(), 0) {
    parallel_for(s.t.size(), [&](std::size_t b, std::size_t e) {
      for (std::size_t f = b; f < e; ++f) area3_[f] = face_area_3d(s, int(f));
    });
  }

  // Every cluster searched side by side as if nothing were taken; then, largest first, a cluster
  // meeting a branch taken before is skipped and a search whose faces meet one is done again
  // against the taken faces. A search that met no taken face is the one-by-one search's: its flood
  // (the only step that reads the taken faces) never reached one. A search done again holds a taken
  // branch only as an island (its flood stops at taken faces): a pouch nested inside this one's
  // neck, which this branch then replaces (absorb()).
  std::vector<BranchCut> run(double min_area, BranchSearch& search) {
    const std::vector<Cluster> clusters = collapsed_clusters(min_area);
    search.clusters = clusters.size();
    std::vector<Candidate> ahead(clusters.size());
    const std::vector<char> none(s_.t.size(), 0);
    std::vector<std::function<void()>> tasks;
    for (std::size_t i = 0; i < clusters.size(); ++i)
      tasks.emplace_back([&, i] { ahead[i] = candidate(clusters[i], none); });
    parallel_tasks(tasks);
    const bool debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
    std::vector<BranchCut> cuts;
    for (std::size_t i = 0; i < clusters.size(); ++i) {
      if (any_taken(clusters[i].faces)) continue;
      Candidate& c = ahead[i];
      if (any_taken(c.region)) c = candidate(clusters[i], taken_), ++search.searched_again;
      if (debug) std::fputs(c.debug.c_str(), stderr);
      if (!c.kept || !absorb(c, cuts, search)) continue;
      for (int f : c.cut.faces) taken_[f] = 1;
      cuts.push_back(std::move(c.cut));
    }
    return cuts;
  }

 private:
  // Step 1: edge-connected clusters of collapsed faces with at least `min_area` mm^2, largest first.
  std::vector<Cluster> collapsed_clusters(double min_area) const {
    std::vector<char> collapsed(s_.t.size(), 0);
    parallel_for(s_.t.size(), [&](std::size_t b, std::size_t e) {
      for (std::size_t f = b; f < e; ++f) collapsed[f] = area3_[f] > 0 && emb_.area2(s_, int(f)) < kCollapsedRatio * area3_[f];
    });
    std::vector<int> label(s_.t.size(), -1);
    std::vector<Cluster> out;
    for (std::size_t f0 = 0; f0 < s_.t.size(); ++f0) {
      if (!collapsed[f0] || label[f0] >= 0) continue;
      Cluster c;
      std::vector<int> stack{int(f0)};
      label[f0] = 1;
      while (!stack.empty()) {
        const int f = stack.back();
        stack.pop_back();
        c.faces.push_back(f);
        c.area += area3_[f];
        for (int e : E_.fe[f])
          for (int g : E_.ef[e])
            if (g >= 0 && collapsed[g] && label[g] < 0) label[g] = 1, stack.push_back(g);
      }
      if (c.area >= min_area) out.push_back(std::move(c));
    }
    std::sort(out.begin(), out.end(), [](const Cluster& a, const Cluster& b) { return a.area > b.area; });
    return out;
  }

  // Step 2: flat distance of every vertex from `centre`, y taken modulo the period.
  std::vector<double> flat_distance(const V2& centre) const {
    const double P = emb_.period;
    std::vector<double> d(s_.p.size());
    for (std::size_t v = 0; v < s_.p.size(); ++v) {
      const V2 q = emb_.pos[v] - centre;
      const double dy = q.y() - P * std::round(q.y() / P);
      d[v] = std::hypot(q.x(), dy);
    }
    return d;
  }

  // The cluster's centre: the corner mean of its most collapsed face.
  V2 centre_of(const Cluster& c) const {
    int best = c.faces.front();
    double best_ratio = 1e300;
    for (int f : c.faces) {
      const double r = emb_.area2(s_, f) / area3_[f];
      if (r < best_ratio) best_ratio = r, best = f;
    }
    const auto k = emb_.corners(s_, best);
    return (k[0] + k[1] + k[2]) / 3;
  }

  // 3D length of the level set {d = r} inside face f (0 when it does not cross).
  double crossing_length(int f, const std::vector<double>& d, double r) const {
    const Tri& t = s_.t[f];
    V3 pts[3];
    int n = 0;
    for (int k = 0; k < 3 && n < 2; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if ((d[a] < r) == (d[b] < r)) continue;
      const double w = (r - d[a]) / (d[b] - d[a]);
      pts[n++] = s_.p[a] + w * (s_.p[b] - s_.p[a]);
    }
    return n == 2 ? (pts[1] - pts[0]).norm() : 0.0;
  }

  // Step 3: the radius in [extent, limit] whose rim is shortest in 3D; 0 when there is no room.
  double neck_radius(const Cluster& c, const std::vector<double>& d, double& neck_mm) const {
    double extent = 0;
    for (int f : c.faces)
      for (int v : s_.t[f]) extent = std::max(extent, d[v]);
    const V2 centre = centre_of(c);
    const double limit = 0.95 * std::min({0.4 * emb_.period, centre.x(), length_ - centre.x()});
    if (!(extent > 0) || extent >= limit) return 0;
    std::vector<int> near;
    for (std::size_t f = 0; f < s_.t.size(); ++f) {
      const Tri& t = s_.t[f];
      if (std::min({d[t[0]], d[t[1]], d[t[2]]}) < limit) near.push_back(int(f));
    }
    std::array<double, kRadii> radius, len{};
    for (int k = 0; k < kRadii; ++k) radius[k] = extent * std::pow(limit / extent, double(k) / (kRadii - 1));
    for (int f : near) {  // a face crosses the level sets min d < r <= max d only: usually one radius
      const Tri& t = s_.t[f];
      const double lo = std::min({d[t[0]], d[t[1]], d[t[2]]}), hi = std::max({d[t[0]], d[t[1]], d[t[2]]});
      for (int k = int(std::upper_bound(radius.begin(), radius.end(), lo) - radius.begin()); k < kRadii && radius[k] <= hi; ++k)
        len[k] += crossing_length(f, d, radius[k]);
    }
    double best_r = 0;
    neck_mm = 1e300;
    for (int k = 0; k < kRadii; ++k)
      if (len[k] > 0 && len[k] < neck_mm) neck_mm = len[k], best_r = radius[k];
    return best_r;
  }

  // Step 4: faces inside radius r connected to the cluster, plus enclosed islands.
  std::vector<char> inside(const Cluster& c, const std::vector<double>& d, double r, const std::vector<char>& taken) const {
    std::vector<char> in(s_.t.size(), 0);
    auto within = [&](int f) {
      const Tri& t = s_.t[f];
      return std::max({d[t[0]], d[t[1]], d[t[2]]}) < r;
    };
    std::vector<int> stack;
    for (int f : c.faces)
      if (within(f)) in[f] = 1, stack.push_back(f);
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int e : E_.fe[f])
        for (int g : E_.ef[e])
          if (g >= 0 && !in[g] && !taken[g] && within(g)) in[g] = 1, stack.push_back(g);
    }
    // The outside must be one piece holding the annulus' own boundary: other pieces are islands
    // (found from the region's border: a flood of the whole band per candidate branch was 7 % of
    // the real CT colon's flatten CPU, on the path before the re-solve).
    const std::size_t faces_in = std::size_t(std::count(in.begin(), in.end(), 1));
    for (int f : enclosed_by(E_, in, 2 * faces_in + kIslandBudgetMin)) in[std::size_t(f)] = 1;
    return in;
  }

  // A disk: one boundary loop and Euler characteristic 1.
  bool is_disk(const std::vector<char>& in) const {
    long long V = 0, Ed = 0, F = 0;
    std::vector<char> vin(s_.p.size(), 0);
    for (std::size_t f = 0; f < s_.t.size(); ++f)
      if (in[f]) {
        ++F;
        for (int v : s_.t[f]) vin[v] = 1;
      }
    for (char c : vin) V += c;
    std::size_t boundary = 0;
    for (std::size_t e = 0; e < E_.ev.size(); ++e) {
      const int f0 = E_.ef[e][0], f1 = E_.ef[e][1];
      const int k = (f0 >= 0 && in[f0]) + (f1 >= 0 && in[f1]);
      Ed += k > 0;
      boundary += k == 1;
    }
    return V - Ed + F == 1 && boundary >= 3;
  }

  // Lumen (a pouch of the lumen: diverticulum, blind loop) or tissue (a polyp on a stalk)? The
  // region closed by a cone over its neck encloses a positive volume, counted with the normals out
  // of the lumen, when it holds lumen.
  bool holds_lumen(const std::vector<char>& in) const {
    V3 apex = V3::Zero();
    std::size_t n = 0;
    for (std::size_t e = 0; e < E_.ev.size(); ++e) {
      const int f0 = E_.ef[e][0], f1 = E_.ef[e][1];
      if ((f0 >= 0 && in[f0]) != (f1 >= 0 && in[f1])) apex += s_.p[E_.ev[e][0]] + s_.p[E_.ev[e][1]], n += 2;
    }
    if (n == 0) return false;
    apex /= double(n);
    double vol = 0;
    for (std::size_t f = 0; f < s_.t.size(); ++f)
      if (in[f]) {
        const Tri& t = s_.t[f];
        vol += (s_.p[t[0]] - apex).dot((s_.p[t[1]] - apex).cross(s_.p[t[2]] - apex));
      }
    return vol * lumen_sign_ > 0;
  }

  // A collapsed cluster holding a fold (negative 2D area) is crushed below what the map's doubles
  // resolve: its corners' flat positions differ by a few units in the last place and their rounding
  // decides the sign. Untangling cannot lift it (its ring is as crushed) and the area correction
  // only moves a map with positive areas, so it is cut off, lumen or tissue (a long strand stump).
  bool crushed(const Cluster& c) const {
    return std::any_of(c.faces.begin(), c.faces.end(), [&](int f) { return emb_.area2(s_, f) < 0; });
  }

  // A face's smallest height in the map (2 |area| / longest side), in units of the spacing of the
  // doubles at its corners' largest coordinate: how finely the map's numbers resolve its shape.
  double height_in_ulps(int f) const {
    const auto c = emb_.corners(s_, f);
    double side = 0, coord = 0;
    for (int k = 0; k < 3; ++k) {
      side = std::max(side, (c[(k + 1) % 3] - c[k]).norm());
      coord = std::max({coord, std::abs(c[k].x()), std::abs(c[k].y())});
    }
    const double ulp = std::nextafter(coord, 2 * coord + 1) - coord;
    return side > 0 ? 2 * std::abs(emb_.area2(s_, f)) / side / ulp : 0;
  }

  // COLONFLAT_FLATTEN_DEBUG=1: each candidate cluster, its neck and why it is kept or not ("" without).
  std::string debug_line(const Cluster& c, const BranchCut& b, double r, const std::vector<char>& in) const {
    if (!std::getenv("COLONFLAT_FLATTEN_DEBUG")) return std::string();
    V3 m = V3::Zero();
    double lowest = 1e300, finest = 1e300;
    for (int f : c.faces) {
      m += s_.p[s_.t[f][0]], lowest = std::min(lowest, emb_.area2(s_, f) / area3_[f]);
      finest = std::min(finest, height_in_ulps(f));
    }
    m /= double(c.faces.size());
    const bool found = !in.empty();
    char line[512];
    std::snprintf(line, sizeof line, "flatten debug cluster %zu faces %.1f mm2 min ratio %.2g height %.3g ulp LPS %.1f %.1f %.1f centre x %.2f: "
                 "neck radius %.3g, %.1f mm, disk %d, lumen %d, crushed %d\n", c.faces.size(), c.area, lowest, finest, m.x(), m.y(),
                 m.z(), b.centre.x(), r, b.neck_mm, found ? int(is_disk(in)) : -1, found ? int(holds_lumen(in)) : -1,
                 int(crushed(c)));
    return line;
  }

  // The branches taken before that `c`'s region holds (islands of its outside: pouches nested
  // inside its neck) are dropped from `cuts`, `c`'s band holds them (and finds them again when it is
  // flattened). False (c not taken) if a taken branch lay only partly in the region: never two
  // branches share a face.
  bool absorb(const Candidate& c, std::vector<BranchCut>& cuts, BranchSearch& search) const {
    if (!any_taken(c.region)) return true;
    std::vector<char> in(s_.t.size(), 0);
    for (int f : c.region) in[std::size_t(f)] = 1;
    std::vector<char> held(cuts.size(), 0);
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      const std::size_t n = std::size_t(std::count_if(cuts[k].faces.begin(), cuts[k].faces.end(), [&](int f) { return in[f] != 0; }));
      if (n > 0 && n < cuts[k].faces.size()) return false;
      held[k] = n > 0;
    }
    std::vector<BranchCut> rest;
    for (std::size_t k = 0; k < cuts.size(); ++k)
      if (!held[k]) rest.push_back(std::move(cuts[k]));
    cuts = std::move(rest);
    search.absorbed += std::size_t(std::count(held.begin(), held.end(), 1));
    return true;
  }

  bool any_taken(const std::vector<int>& faces) const {
    return std::any_of(faces.begin(), faces.end(), [&](int f) { return taken_[f] != 0; });
  }

  // Steps 2-4 for one cluster, the faces `taken` by larger branches closed to its flood.
  Candidate candidate(const Cluster& c, const std::vector<char>& taken) const {
    Candidate k;
    BranchCut& b = k.cut;
    b.centre = centre_of(c);
    const std::vector<double> d = flat_distance(b.centre);
    const double r = neck_radius(c, d, b.neck_mm);
    const std::vector<char> in = r > 0 ? inside(c, d, r, taken) : std::vector<char>();
    for (std::size_t f = 0; f < in.size(); ++f)
      if (in[f]) k.region.push_back(int(f));
    k.debug = debug_line(c, b, r, in);
    if (in.empty() || !is_disk(in)) return k;
    b.tissue = !holds_lumen(in);
    if (b.tissue && !crushed(c)) return k;
    for (int f : k.region) b.area_mm2 += area3_[f];
    b.faces = k.region;
    k.kept = !b.faces.empty();
    return k;
  }

  const Surface& s_;
  const Edges& E_;
  const Embedding& emb_;
  double length_;
  double lumen_sign_;
  std::vector<double> area3_;
  std::vector<char> taken_;
};

}  // namespace

std::vector<BranchCut> find_branches(const Surface& s, const Edges& E, const Embedding& emb, double length,
                                     double lumen_sign, double min_area_mm2, BranchSearch* search) {
  BranchSearch done;
  std::vector<BranchCut> cuts = BranchFinder(s, E, emb, length, lumen_sign).run(min_area_mm2, done);
  if (search) *search = done;
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug branches: %zu clusters searched side by side, %zu searched again, %zu held by a "
                 "later branch, %zu cut\n", done.clusters, done.searched_again, done.absorbed, cuts.size());
  return cuts;
}

namespace {

// Per vertex of s: 1 for a vertex of `loops` that no face with keep 1 has as a corner.
std::vector<char> loop_vertices_lost(const Surface& s, const std::vector<char>& keep,
                                     const std::vector<std::vector<int>>& loops) {
  std::vector<char> kept_corner(s.p.size(), 0), lost(s.p.size(), 0);
  for (std::size_t f = 0; f < s.t.size(); ++f)
    if (keep[f])
      for (int v : s.t[f]) kept_corner[std::size_t(v)] = 1;
  for (const auto& loop : loops)
    for (int v : loop) lost[std::size_t(v)] = !kept_corner[std::size_t(v)];
  return lost;
}

// The removed faces (keep 0) joined through edges to a removed face at a `lost` vertex.
std::vector<char> removed_region_at(const Surface& s, const Edges& E, const std::vector<char>& keep,
                                    const std::vector<char>& lost) {
  std::vector<char> reached(s.t.size(), 0);
  std::vector<int> stack;
  for (std::size_t f = 0; f < s.t.size(); ++f) {
    const Tri& t = s.t[f];
    if (!keep[f] && (lost[std::size_t(t[0])] || lost[std::size_t(t[1])] || lost[std::size_t(t[2])]))
      reached[f] = 1, stack.push_back(int(f));
  }
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    for (int e : E.fe[std::size_t(f)])
      for (int g : E.ef[std::size_t(e)])
        if (g >= 0 && !keep[std::size_t(g)] && !reached[std::size_t(g)]) reached[std::size_t(g)] = 1, stack.push_back(g);
  }
  return reached;
}

}  // namespace

std::vector<char> band_faces_after_cuts(const Surface& s, const Edges& E, const std::vector<std::vector<int>>& loops,
                                        std::vector<BranchCut>& cuts) {
  while (!cuts.empty()) {
    std::vector<char> keep(s.t.size(), 1);
    for (const auto& cut : cuts)
      for (int f : cut.faces) keep[std::size_t(f)] = 0;
    clean_selection(s, E, keep);
    const std::vector<char> lost = loop_vertices_lost(s, keep, loops);
    if (std::find(lost.begin(), lost.end(), 1) == lost.end()) return keep;
    const std::vector<char> reached = removed_region_at(s, E, keep, lost);
    const std::size_t before = cuts.size();
    cuts.erase(std::remove_if(cuts.begin(), cuts.end(), [&](const BranchCut& c) {
                 return std::any_of(c.faces.begin(), c.faces.end(), [&](int f) { return reached[std::size_t(f)] != 0; });
               }), cuts.end());
    if (cuts.size() == before) cuts.clear();  // the clean-up alone took them: no cut is safe to make
    if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
      std::fprintf(stderr, "flatten debug branches: %zu cut(s) dropped, they reached the band's end\n",
                   before - cuts.size());
  }
  return std::vector<char>(s.t.size(), 1);
}

}  // namespace cf::flat_detail
