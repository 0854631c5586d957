#pragma once
// Raw mesh data exactly as a file holds it, before any validation: polygons may have any size,
// indices may be out of range, coordinates may be NaN. Readers fill this; validation and
// conversion to a halfedge mesh come after (see validation.h, mesh_io.h).
#include <array>
#include <cstdint>
#include <vector>

namespace cf {

struct PolygonSoup {
  std::vector<std::array<double, 3>> points;  // #P points
  std::vector<std::int64_t> corners;          // vertex ids of all polygons, concatenated
  std::vector<std::size_t> face_start{0};     // #F+1 offsets into `corners`

  std::size_t num_faces() const { return face_start.size() - 1; }
  std::size_t face_size(std::size_t f) const { return face_start[f + 1] - face_start[f]; }
  const std::int64_t* face(std::size_t f) const { return corners.data() + face_start[f]; }
  void add_face(const std::int64_t* ids, std::size_t n) {
    corners.insert(corners.end(), ids, ids + n);
    face_start.push_back(corners.size());
  }
};

// An indexed triangle list: #P points, #T triangles (vertex ids into points, all in range).
struct TriangleList {
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 3>> triangles;
};

}  // namespace cf
