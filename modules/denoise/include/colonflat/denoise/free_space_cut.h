#pragma once
// A disk through empty space: the minimum cut of a graph of cubic cells (issue 26, session 31).
//
// The cells of a box whose closed cube meets no surface triangle are free; two 6-adjacent free
// cells share a square that lies in their union, so it meets no triangle either (exact, up to the
// triangle-box test's rounding; the test is made on cubes grown by a millionth of a cell). A free
// cell next to a blocked cell whose triangles are all on the source side is a source terminal, on
// the sink side a sink terminal; Boost.Graph's Boykov-Kolmogorov max-flow (unit capacity per
// square) separates them, and the squares between the source set and the rest are the cut. The
// cut's connected pieces that are disks (Euler characteristic 1, one boundary loop, every edge in
// at most two squares, every vertex's squares one fan), or disks with small holes (each hole's rim
// at most a quarter of the outer boundary's vertices; the surgery closes them), are returned: the
// surgery's minimum-cut caps (surgery_mincut.cpp) are made from one of them.
#include <array>
#include <cstddef>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf {

// True when triangle t meets the closed axis-aligned box [lo, hi] (separating axes: the box's
// three, the triangle's normal and the nine cross products of box axes and triangle edges).
bool triangle_meets_box(const std::array<Vec3, 3>& t, const Vec3& lo, const Vec3& hi);

struct FreeSpaceBox {
  Vec3 lo{0, 0, 0};               // mm: corner of cell (0, 0, 0)
  double cell = 0.25;             // mm: cell edge
  std::array<int, 3> n{0, 0, 0};  // cells per axis
};

// A surface triangle and its side: 1 source, 2 sink, 0 neither (its cells make no terminal).
struct SidedTriangle {
  std::array<Vec3, 3> p;
  int side = 0;
};

// One piece of the cut as a disk of lattice squares.
struct CutDisk {
  std::vector<Vec3> points;               // mm
  std::vector<Vec3> normals;              // per point: unit, its squares' mean smoothed (free_space_disks.cpp)
  std::vector<std::array<int, 4>> quads;  // corners; right-hand normal towards the sink side;
                                          // in breadth-first order from the boundary
  std::vector<int> boundary;              // the boundary loop, in the direction the quads give it
  std::vector<std::vector<int>> holes;    // the rims of the piece's small holes, in the direction the quads give them
};

struct FreeSpaceCutStats {
  std::size_t cells = 0, free = 0, sources = 0, sinks = 0, squares = 0, pieces = 0, disks = 0;
  long long flow = 0;
};

// The disks of the minimum cut between the box's source and sink terminals (none when either
// side has no terminal).
std::vector<CutDisk> free_space_cut(const FreeSpaceBox& box, const std::vector<SidedTriangle>& tris,
                                    FreeSpaceCutStats* stats = nullptr);

}  // namespace cf
