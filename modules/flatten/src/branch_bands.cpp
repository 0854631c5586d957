// The side branches cut off a band, flattened as bands of their own (see branch_bands.h).
#include "branch_bands.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>

#include "colonflat/core/threads.h"
#include "factor_schedule.h"  // thread_cpu_seconds

namespace cf::flat_detail {
double surface_area(const Surface& s) {
  double a = 0;
  for (std::size_t f = 0; f < s.t.size(); ++f) a += face_area_3d(s, int(f));
  return a;
}

double DiskShape::isoperimetric() const {
  return rim_mm > 0 ? 4 * 3.14159265358979323846 * area_mm2 / (rim_mm * rim_mm) : std::numeric_limits<double>::infinity();
}

DiskShape disk_shape(const Surface& s) {
  DiskShape d;
  d.area_mm2 = surface_area(s);
  const Edges E = build_edges(s.t);
  std::vector<int> rim;
  for (std::size_t e = 0; e < E.ev.size(); ++e)
    if (E.ef[e][1] < 0)
      d.rim_mm += (s.p[std::size_t(E.ev[e][0])] - s.p[std::size_t(E.ev[e][1])]).norm(), rim.push_back(E.ev[e][0]);
  if (rim.empty()) return d;
  const std::vector<double> dist = dijkstra(build_csr(s, E), rim);
  d.depth_mm = dist[std::size_t(argmax_finite(dist))];
  return d;
}

namespace {

// Appends the works of a flattened branch (its own first, parents relative to the list) to `out`,
// the branch hanging from the work at index -1 (the caller's segment).
void append_branch(std::vector<SegmentWork>& sub, std::vector<SegmentWork>& out) {
  const int base = int(out.size());
  for (std::size_t i = 0; i < sub.size(); ++i) {
    if (i > 0) sub[i].parent += base;
    out.push_back(std::move(sub[i]));
  }
  out[base].parent = -1;
}

// The wall (end caps aside), the wall shown and the lowest band area p05 of a piece's works.
struct WorksShown {
  double wall = 0, shown = 0, p05 = 1e300;
};
WorksShown works_shown(const std::vector<SegmentWork>& works) {
  WorksShown r;
  for (const SegmentWork& w : works)
    r.wall += w.seg.coverage.wall_area_mm2, r.shown += w.seg.coverage.shown_area_mm2,
        r.p05 = std::min(r.p05, w.seg.stats.area_p05);
  return r;
}

}  // namespace

std::vector<SegmentWork> tube_or_disk(const BranchPiece& piece, std::vector<SegmentWork> tube, const FlattenDisk& disk,
                                      int depth) {
  const Surface* d = piece.as_disk();
  const WorksShown t = works_shown(tube);
  if (!d || !(t.wall - t.shown > kDiskMapTrigger * t.wall)) return tube;
  const bool debug = std::getenv("COLONFLAT_FLATTEN_DEBUG") != nullptr;
  if (d->t.size() > kDiskMapMaxFaces) {
    if (debug)
      std::fprintf(stderr, "flatten debug disk piece of %zu faces (depth %d): tube map shows %.1f of %.1f mm2 (%zu bands), "
                   "disk map not tried (more than %zu faces)\n", d->t.size(), depth, t.shown, t.wall, tube.size(),
                   kDiskMapMaxFaces);
    return tube;
  }
  const DiskShape shape = debug ? disk_shape(*d) : DiskShape{};
  const double cpu0 = thread_cpu_seconds();
  std::vector<SegmentWork> flat = disk(*d);
  const double cpu = thread_cpu_seconds() - cpu0;
  const double shown = flat.empty() ? 0.0 : flat[0].seg.coverage.shown_area_mm2;
  const bool better = shown > t.shown && flat[0].seg.stats.area_p05 >= t.p05;
  if (debug)
    std::fprintf(stderr, "flatten debug disk piece of %zu faces (depth %d): tube map shows %.1f of %.1f mm2 (%zu bands), "
                 "disk map %.1f of %.1f (p05 %.3f, tube's lowest p05 %.3f): %s; shape: area %.1f mm2, rim %.1f mm, "
                 "depth %.2f mm, isoperimetric %.3f; disk map thread CPU %.3f s\n", d->t.size(), depth, t.shown, t.wall,
                 tube.size(), shown, flat.empty() ? 0.0 : flat[0].seg.coverage.wall_area_mm2,
                 flat.empty() ? 0.0 : flat[0].seg.stats.area_p05, t.p05, better ? "disk" : "tube", shape.area_mm2,
                 shape.rim_mm, shape.depth_mm, shape.isoperimetric(), cpu);
  return better ? flat : tube;
}

bool colon_stretch(double centreline_mm, double conformal_mm, double period_mm, std::size_t faces) {
  const bool stretch = period_mm > 0 && conformal_mm >= kColonStretchAspect * period_mm &&
                       centreline_mm <= kCentrelineAgreement * conformal_mm &&
                       conformal_mm <= kCentrelineAgreement * centreline_mm;
  if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
    std::fprintf(stderr, "flatten debug branch band: %zu faces, centreline %.1f mm, conformal length %.1f mm, period %.1f mm: %s\n",
                 faces, centreline_mm, conformal_mm, period_mm, stretch ? "a colon stretch (the band's axis)" : "a pouch");
  return stretch;
}

std::vector<SegmentWork> flatten_branch_pieces(const std::vector<BranchPiece>& pieces, const FlattenBand& band,
                                               double& placed) {
  std::vector<std::vector<SegmentWork>> subs(pieces.size());
  std::vector<char> done(pieces.size(), 0);
  std::vector<std::size_t> by_size(pieces.size());  // the largest first: the longest task starts first
  std::iota(by_size.begin(), by_size.end(), std::size_t(0));
  std::stable_sort(by_size.begin(), by_size.end(), [&](std::size_t a, std::size_t b) {
    return pieces[a].surface.t.size() > pieces[b].surface.t.size();
  });
  std::vector<std::function<void()>> tasks;
  for (std::size_t i : by_size)
    tasks.emplace_back([&, i] {
      try {
        subs[i] = band(pieces[i]);
        done[i] = 1;
      } catch (const std::exception& e) {  // not flattenable as a band: its wall counts as not shown
        if (std::getenv("COLONFLAT_FLATTEN_DEBUG"))
          std::fprintf(stderr, "flatten debug branch of %zu faces (%zu open ends) not flattened: %s\n",
                       pieces[i].surface.t.size(), pieces[i].loops, e.what());
      }
    });
  parallel_tasks(tasks);
  std::vector<SegmentWork> out;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    if (!done[i]) continue;
    std::vector<SegmentWork>& sub = subs[i];
    const BranchPiece& piece = pieces[i];
    sub[0].lost_area += sub[0].cap_area;  // the tip's cap counts as wall not shown
    sub[0].cap_area = 0;
    sub[0].seg.neck_mm = piece.neck_mm;
    sub[0].seg.holds = piece.tissue ? "tissue" : "lumen";
    sub[0].neck = piece.neck;
    placed += surface_area(sub[0].seg.map == "disk" ? *piece.as_disk() : piece.surface);  // (a disk band holds the unslit disk)
    append_branch(sub, out);
  }
  return out;
}

}  // namespace cf::flat_detail
