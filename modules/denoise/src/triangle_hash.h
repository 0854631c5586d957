#pragma once
// Internal to the denoise module: triangles given by mesh vertex ids (faces or not yet) in a hash
// of cubic cells by their bounding boxes, to test other triangles against them (the minimum-cut
// caps' checks, surgery_mincut.cpp and surgery_mincut_strip.cpp).
#include <array>
#include <unordered_map>
#include <vector>

#include "colonflat/core/mesh.h"

namespace cf::detail {

class TriangleHash {
 public:
  TriangleHash(const Mesh& mesh, double cell) : mesh_(mesh), cell_(cell) {}
  // Adds `t` (its points as the mesh holds them now); returns its index.
  int insert(const std::array<int, 3>& t);
  // The index of an inserted triangle `t` intersects improperly (triangles_intersect_improperly:
  // shared vertices and edges allowed), or -1.
  int crossing(const std::array<int, 3>& t) const;
  std::size_t size() const { return tris_.size(); }

 private:
  struct Box {
    Vec3 lo, hi;
  };
  std::array<Vec3, 3> points(const std::array<int, 3>& t) const;
  static Box box_of(const std::array<Vec3, 3>& p);
  template <class F>
  void for_cells(const Box& b, F&& f) const;

  const Mesh& mesh_;
  double cell_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<Box> boxes_;
  std::unordered_map<long long, std::vector<int>> grid_;
  mutable std::vector<int> stamp_;  // per inserted triangle: the last query that tested it
  mutable int query_ = 0;
};

}  // namespace cf::detail
