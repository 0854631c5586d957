#pragma once
// The side branches cut off a band, flattened as bands of their own (flatten, internal): side by
// side, and a long one (a colon stretch a severed colon hangs off a contact) given the colon band's
// axis instead of a pouch's (issue 26, docs/flatten.md session 28 "branch").
#include <functional>
#include <vector>

#include "flatten_internal.h"

namespace cf::flat_detail {

// One side branch cut off an annulus: its surface and its neck's vertices in what remains.
struct BranchPiece {
  Surface surface;
  std::vector<int> neck;
  double neck_mm = 0;
  bool tissue = false;  // holds tissue (a strand stump), not lumen
  bool limb = false;    // limb-sized: its neck at least kLimbNeck x the band's period (a fork of the lumen)
  std::size_t loops = 1;  // open ends of `surface`: 1 (a branch, a patch that is a disk) or 2 (a patch that is an annulus)
  Surface disk;           // a disk patch before its slit (patch_slit.h); empty: none, or `surface` itself when loops == 1
  // The piece as a disk (disk_map.h): `disk`, else `surface` when it has one open end; null: not a disk.
  const Surface* as_disk() const { return !disk.t.empty() ? &disk : loops == 1 ? &surface : nullptr; }
};

// A branch whose neck is at least this fraction of its band's period (mm around) is limb-sized: the
// lumen forks there (the figure of cut_rims.cpp's long rims). Only a limb-sized branch can be a colon
// stretch: a thin strand or small bowel-like tube off the colon keeps a pouch's map.
constexpr double kLimbNeck = 0.5;

// The 3D area of s (mm^2; its faces' areas summed in face order).
double surface_area(const Surface& s);

// A branch's band is a colon stretch (a tube much longer than it is wide: a severed colon's loop
// hanging off a fused contact, not a pouch) when its conformal rectangle is at least this many
// periods (its mean girth) long: the conformal modulus, well defined on any annulus. A pouch behind
// a neck (a diverticulum) is about 1, the grown real mask's cut-off colon stretches 2.2-3.4 and its
// pouches <= 1.1 (docs/flatten.md session 28 "branch").
constexpr double kColonStretchAspect = 2.0;
// ... and its centreline (from the level sets of u) is within this factor of the conformal length:
// the band's length is the centreline's (within 8 %), so a centreline the level sets make up (a
// stump whose neck is a hole in its side) keeps the pouch's conformal spacing.
constexpr double kCentrelineAgreement = 1.5;
// Pre: lengths >= 0 (mm). True when the band is a colon stretch (COLONFLAT_FLATTEN_DEBUG: a line
// with its `faces` and figures).
bool colon_stretch(double centreline_mm, double conformal_mm, double period_mm, std::size_t faces);

// Flattens one branch's surface (nloops = 1: its neck open) as a band and its own branches: the
// works, its own first (parents relative to the list, the first's -1).
using FlattenBand = std::function<std::vector<SegmentWork>(const BranchPiece&)>;

// The works of the cut-off `pieces` flattened by `band` (side by side on up to thread_count()
// threads, the largest first; each on its own, so the same works for any thread count), each
// branch's list after the previous one's in piece order, its first work's parent -1 (the caller's
// segment) and its fields set from the piece (neck, neck mm, what it holds, its tip's cap counted
// as wall not shown). A piece that cannot be flattened (band throws) counts as wall not shown.
// `placed` += the wall area of the pieces flattened (summed in piece order).
std::vector<SegmentWork> flatten_branch_pieces(const std::vector<BranchPiece>& pieces, const FlattenBand& band,
                                               double& placed);

// A piece's map misses the coverage target (issue 26: 99.5 % shown) when it leaves more than this share
// of its wall not shown: then its disk map is tried (tube_or_disk).
constexpr double kDiskMapTrigger = 2 * kHiddenWallTolerance;

// A disk piece's shape, known before it is mapped: its wall (mm^2), its rim's length (mm, the
// boundary edges summed) and the largest distance along edges from the rim (mm).
struct DiskShape {
  double area_mm2 = 0, rim_mm = 0, depth_mm = 0;
  // 4 pi area / rim^2: 1 for a flat round disk, < 1 for a flat strip, 2 for a hemisphere, about
  // 2 h / r + 2 for a pouch of length h and radius r (infinity without a rim).
  double isoperimetric() const;
};
DiskShape disk_shape(const Surface& s);

// A disk piece of more faces than this keeps its tube map: its disk map is not tried. Measured
// (docs/history/flatten.md session 34 "grown"): on the grown CT mask, grown real mask and raw CT mask
// rows the disk map won on pieces of 270-8 532 faces and on none above: every one of 10 291-285 943
// faces (7, all on the grown CT mask) was refused or showed less (the 285 943-face one 54 % of its
// wall, against its tube map's 99.47 %), and they took 19 of the 26 thread-CPU s its disk maps cost.
constexpr std::size_t kDiskMapMaxFaces = 20000;

// Maps a disk as one band (disk_map.h flatten_disk; empty: refused).
using FlattenDisk = std::function<std::vector<SegmentWork>(const Surface&)>;

// A cut-off piece's works: `tube` (its tube map and the bands below it: flatten_surface's, from its
// rim to a tip cap or a slit) or, for a disk piece (piece.as_disk()) whose tube map misses the
// coverage target (kDiskMapTrigger) and has at most kDiskMapMaxFaces faces, its disk map `disk`
// instead when that shows more wall with an area p05 no lower than the tube map's lowest band p05
// (issue 26, session 33 "patchmap"). COLONFLAT_FLATTEN_DEBUG: one line per disk map tried (`depth`:
// the piece's band depth; its shape and the disk map's thread CPU) or skipped for its size.
std::vector<SegmentWork> tube_or_disk(const BranchPiece& piece, std::vector<SegmentWork> tube, const FlattenDisk& disk,
                                      int depth);

}  // namespace cf::flat_detail
