#pragma once
// A synthetic colon for tests and benchmarks (test-support library colonflat_testdata): a tube of radius `radius` along a bent 3D
// centreline, with haustral folds (ridges across the tube, height varying around it) and polyps
// (hemispheres of known diameter, protruding into the lumen), closed by hemispherical caps or
// left open. Triangle size ~`spacing` mm. Genus 0; outward normals (out of the lumen).
#include <array>
#include <vector>

#include "colonflat/core/soup.h"

namespace cf::synthetic {

struct PolypSpec {
  double s = 100;        // mm along the centreline
  double angle = 0;      // radians around it
  double diameter = 8;   // mm
};

struct ColonOptions {
  double length = 400;        // mm of centreline (caps excluded)
  double radius = 20;         // mm
  double spacing = 1.0;       // mm, target edge length
  int around = 0;             // vertices per ring (0: from spacing)
  bool closed = true;         // hemispherical caps at both ends
  bool bent = true;           // S-shaped 3D centreline, else straight along z
  double fold_height = 5;     // mm (0: no folds)
  double fold_spacing = 35;   // mm between folds
  double fold_width = 2.5;    // mm (Gaussian sigma across the fold)
  std::vector<PolypSpec> polyps;
};

struct ColonPolyp {
  int id = 0;
  std::array<double, 3> center{0, 0, 0};  // apex, LPS mm
  double diameter = 0;                     // mm
};

struct Colon {
  TriangleList mesh;
  std::vector<ColonPolyp> polyps;
  std::vector<std::array<double, 3>> fold_crests;  // points on fold crests (for tests)
  double circumference = 0;                       // 2 pi radius
};

Colon colon(const ColonOptions& o);

// The options of a test colon: centreline length and radius (mm), edge length (mm), polyps; the
// other fields keep their defaults (bent, closed, with folds).
ColonOptions colon_options(double length, double radius, double spacing, std::vector<PolypSpec> polyps);

}  // namespace cf::synthetic
