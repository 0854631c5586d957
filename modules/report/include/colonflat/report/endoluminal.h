#pragma once
// Endoluminal (virtual colonoscopy) views with VTK: the colon surface seen from inside the lumen,
// the camera placed on the lumen side of a wall point and looking at it along the wall normal,
// lit by a head light. Each view renders only the wall within `radius_mm` of its target (what a
// camera inside a colon of normal calibre can see), so a view costs the same on any colon size.
// Needs an X display or Xvfb (render module's ensure_display()).
#include <array>
#include <memory>

#include "colonflat/core/soup.h"
#include "colonflat/render/artifacts.h"

namespace cf {

struct EndoluminalOptions {
  int size = 256;                // pixels (square)
  double view_angle_deg = 75;    // vertical field of view
  double distance_mm = 22;       // camera distance from the target, shortened to 60 % of the free
                                 // distance to the opposite wall
  double min_distance_mm = 4;    // closest camera distance
  double radius_mm = 70;         // wall rendered around the target
};

class EndoluminalRenderer {
 public:
  // `surface`: LPS mm; `normals`: unit vertex normals pointing out of the lumen (may be empty:
  // computed by VTK). Throws Error when no display can be had.
  EndoluminalRenderer(const TriangleList& surface, const std::vector<std::array<double, 3>>& normals,
                      const EndoluminalOptions& opts = {});
  ~EndoluminalRenderer();
  // The view of `target` (LPS mm) from the lumen side of `normal_out` (unit, out of the lumen).
  // `camera_distance_mm` (optional) receives the distance used.
  ImagePtr render(const std::array<double, 3>& target, const std::array<double, 3>& normal_out,
                  double* camera_distance_mm = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cf
