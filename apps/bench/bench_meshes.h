#pragma once
// Large synthetic surfaces for the benchmark apps.
#include <cstddef>

#include "colonflat/core/mesh.h"

namespace cf::bench {

// A sphere of radius `radius` mm with `handles` small tori (ring radius 3 mm, tube 1 mm) half
// sunk into its surface, each adding one handle, extracted with VTK flying edges at voxel size
// `voxel` mm (faces ~ 7e5 * (radius / 100)^2 / (voxel / 0.42)^2). Genus = handles (checked by
// the caller). Deterministic for a seed.
Mesh sphere_with_handles(double radius, int handles, double voxel, unsigned seed = 1);

// A ball of radius `radius` mm pierced by a straight strand of radius `strand_radius` mm along a
// chord (the lumen with a tissue bridge across it): genus 1, the strand a tunnel through the
// ball. Flying edges at `voxel` mm.
Mesh sphere_with_strand(double radius, double strand_radius, double voxel);

// A colon-like surface with the kinds of handles real CT colonography surfaces have, from the
// binary mask (voxel `voxel` mm) of a U-shaped colon (two limbs of radius 18 mm, 200 mm long,
// 3 mm apart, joined by a bend) extracted with VTK flying edges (stair-cased like a real mask):
//   contact: the limbs touch over `contact_length` mm (a 4 mm-wide air channel overlapping both
//            walls by 0.5 mm): one long handle (loop ~2 x contact_length) plus the small handles
//            voxel noise makes along it;
//   bridge:  an air bridge (radius 4 mm) to a small-bowel loop (radius 10 mm) that returns to
//            the colon through a second bridge;
//   strands: a straight tissue strand (radius 6 mm) and a curved one (radius 4 mm) across the
//            lumen: tunnel loops of 25-40 mm around wide, curved walls;
//   hooks:   two diverticulum-like tubes (radius 2 mm) leaving the wall and re-entering it.
// Genus follows from the mask (measured by the caller). Deterministic.
struct ColonLikeOptions {
  double voxel = 0.5;            // mm
  double contact_length = 60;    // mm; 0 = no contact
  bool bridge = true, strands = true, hooks = true;
};
Mesh colon_like_surface(const ColonLikeOptions& options);

// A torus (axis z, major radius 4 mm, tube radius 1 mm - 15 % at angle u = 0, so its shortest
// loop is the meridian there; 64 x 16 quads) with a blocker inside its tube that every cap of
// that meridian must cross:
//  - kRod: a thin ellipsoid along the tube core (0.15 mm thick, +-1.4 mm along the tube);
//  - kCoreBlob: a small ellipsoid at the tube core (0.6 mm across the tube, +-0.6 mm along it):
//    a disk of the meridian bulged along the tube by more than 0.6 mm at its centre passes it;
//  - kCoreRing: a thin torus along the whole core (tube 0.15 mm - 15 % at u = pi, so it is cut
//    there): it links every meridian, so no meridian has a clean cap; the longitude's has;
//  - kCoreAndLinkRings: that ring and a second thin ring (radius 2.5 mm, tube 0.15 mm) around the
//    tube at u = 0, through the hole: it links every loop crossing a meridian, so no loop that
//    removes the torus' handle has a clean cap;
//  - kWaistPlugAndRod: a plug filling the tube at u = 0 (a tube of radius 0.72 mm between the
//    sections at u = -+1 of 64, flat ends), a rod of radius 0.15 mm along the core from section 4
//    to section 60, and the link ring: the meridians one section from the thinnest one (or
//    closer) cross the plug, those 4 sections or more away the rod, every loop crossing a
//    meridian the ring; the meridians 2-3 sections away have clean caps (a wall's rim with
//    remnants beside it, where only a loop a few edges off the rim can be capped).
// Closed and embedded; genus 1 + one per ring.
enum class Blocker { kRod, kCoreBlob, kCoreRing, kCoreAndLinkRings, kWaistPlugAndRod };
Mesh blocked_torus(Blocker blocker);

}  // namespace cf::bench
