#pragma once
// Constrained fairing of a binary mask's surface (docs/reconstruct.md, "Constrained fairing").
//
// A binary mask's surface is a staircase. Smoothing it freely removes the steps but moves real
// walls by whole voxels; clamping each vertex back after a smoothing filter leaves small kinks
// where the clamp holds, and keeps the wide terraces of a gently sloping wall (the "ripples" of
// the flat image). Constrained fairing instead finds the *smoothest* surface inside the tolerance:
//
//   minimise   E(x) = 1/2 * sum_i |U(x)_i|^2,   U(x)_i = mean_{j in N(i)} x_j - x_i   (umbrella)
//   subject to |M (x_i - a_i)| <= radius        for every vertex i,
//
// where a_i is the vertex's staircase position (LPS mm), M maps LPS mm to voxel (index) units and
// radius is just below half a voxel. E is a discrete thin-plate energy: a plane has E = 0, so a
// tilted wall whose staircase lies within half a voxel of a plane becomes that plane; its solution
// touches the constraint smoothly (C1), without the clamp's kinks. Connectivity is not changed.
//
// Solver: accelerated projected gradient (FISTA with adaptive restart). The step is 1 / (1.05 *
// the largest eigenvalue of U^T U, from power iterations); the projection scales each vertex's
// offset from its anchor radially to the ellipsoid |M d| <= radius.
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

#include "colonflat/core/soup.h"

namespace cf::reconstruct_detail {

struct FairingOptions {
  int iterations = 100;                        // projected-gradient iterations in all (0 = off)
  double radius_voxels = 0.5 * (1.0 - 1e-6);   // largest offset from the anchor, voxels (index units)
};

struct FairingResult {
  int iterations = 0;
  double energy_before = 0, energy_after = 0;  // E at the start / end, mm^2
  std::size_t vertices_at_limit = 0;           // vertices on the constraint at the end
};

// surface: #P points (LPS mm, moved in place) and #T triangles of a closed manifold mesh (every
// point in some triangle). anchors: #P staircase positions (LPS mm); every point must already lie
// within radius_voxels of its anchor (it stays so). lps_to_index: 3x3, LPS mm -> voxel offsets.
// Post: the same triangles; every point within radius_voxels of its anchor; E not larger.
FairingResult fair_within_tolerance(TriangleList& surface, const std::vector<std::array<double, 3>>& anchors,
                                    const Eigen::Matrix3d& lps_to_index, const FairingOptions& options);

}  // namespace cf::reconstruct_detail
