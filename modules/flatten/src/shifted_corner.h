#pragma once
// A face's corner in the map: its vertex's position p shifted by the face's y offset dy (Embedding,
// flatten_internal.h), as (p.x + 0, p.y + dy): the same two IEEE additions as p + Vector2d(0, dy),
// hence the same bits, but built in registers. GCC -O3 (SSE2) builds Vector2d(0, dy) on the stack
// from two 8-byte stores and reads it back with one 16-byte load, which cannot be forwarded from
// them: a stall of ~a dozen cycles for each corner of each face (perf on the grown CT mask row,
// issue 26 session 36 "compact": ~37 % of the area energy's samples and ~56 % of the fold limit's
// sit right after those loads).
#include <Eigen/Core>

#include <array>
#include <vector>

namespace cf::flat_detail {

inline Eigen::Vector2d shifted_corner(const Eigen::Vector2d& p, double dy) {
  return Eigen::Vector2d(p.x() + 0.0, p.y() + dy);  // + 0.0 kept: -0 + 0 is +0, as in p + (0, dy)
}

// p - Vector2d(0, dy), built the same way: (p.x - 0, p.y - dy), the same two IEEE subtractions
// (x - 0 is x for every x, -0 included). The stall is the same (perf, issue 26 session 37 "stall":
// RegionSystem::solve's target edges, a third of its samples after those loads).
inline Eigen::Vector2d unshifted_corner(const Eigen::Vector2d& p, double dy) {
  return Eigen::Vector2d(p.x() - 0.0, p.y() - dy);
}

// The three map corners of a face with vertices t: positions pos[t[k]] shifted by the face's dy[k].
inline std::array<Eigen::Vector2d, 3> shifted_corners(const std::array<int, 3>& t, const std::vector<Eigen::Vector2d>& pos,
                                                      const std::array<double, 3>& dy) {
  return {shifted_corner(pos[t[0]], dy[0]), shifted_corner(pos[t[1]], dy[1]), shifted_corner(pos[t[2]], dy[2])};
}

}  // namespace cf::flat_detail
