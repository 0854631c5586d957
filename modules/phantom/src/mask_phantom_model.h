#pragma once
// Internal steps of paint_phantom_from_mask (docs/phantom.md, "Phantom from a mask"). The painter
// works in the mask's grid frame (index x spacing, origin 0; the phantom's Grid), maps it to LPS
// with the mask's origin and direction, and reuses the phantom's materials, HU table, body model,
// truth labels, image building, blur and noise.
#include <Eigen/Dense>

#include <cstdint>
#include <vector>

#include "colonflat/phantom/mask_phantom.h"
#include "phantom_model.h"

namespace cf::phantom_detail {

// Colon wall thickness (mm): the colon's wall is 2-3 mm when distended (docs/phantom.md).
constexpr double kMaskWallMm = 3.0;
// Bone and lung nearer the lumen than this (mm) become fat: a colon lies in the peritoneal
// cavity, separated from the skeleton by muscle (psoas, iliacus) and from the lungs by the diaphragm.
constexpr double kOrganClearanceMm = 10.0;
constexpr int kPoolSlots = 200;  // fluid materials for pools (pools beyond share a slot's HU)

class MaskPainter {
 public:
  MaskPainter(const MaskImage* mask, const MaskPhantomOptions& o, MaskPhantom& out);
  void run();

 private:
  // mask_phantom.cpp: frame, body, wall, clearance, images, description
  void make_frame();
  void map_body();
  void paint_body_around();
  void paint_wall();
  void make_clearance();
  void clear_near_colon();
  void make_images();
  nlohmann::json describe() const;
  // mask_phantom_fluid.cpp: fully tagged stretches and pools
  void place_stretches();
  std::vector<float> path_distance(std::size_t start) const;
  // mask_phantom_beside.cpp: where a long stretch lies beside other parts of the colon
  std::pair<double, double> beside_range(const std::vector<float>& dist, double D, double len);
  void place_pools();
  void fill_pocket(std::size_t bottom, double level, int body);
  double pocket_height(int i, int j, int k) const;
  // mask_phantom_organs.cpp: small bowel and bladder
  void place_bowel();
  bool try_bowel_loop(bool touching, BowelLoop& loop);
  void paint_bowel_loop(const BowelLoop& loop);
  void place_bladder();
  void paint_bladder(const V3& c, const V3& r);

  V3 lps(const V3& grid_point) const { return origin_ + dir_ * grid_point; }
  // Depth (mm) along gravity of a voxel centre: gravity . LPS position.
  double depth(int i, int j, int k) const { return depth0_ + down_.dot(g_.point(i, j, k)); }
  double clearance(const V3& grid_point) const;  // mm from the lumen (coarse, 0 inside)
  bool lumen(std::size_t q) const { return mask_buf_[q] != 0; }
  void ijk(std::size_t q, int& i, int& j, int& k) const {
    i = int(q % g_.n[0]);
    j = int((q / g_.n[0]) % g_.n[1]);
    k = int(q / (std::size_t(g_.n[0]) * g_.n[1]));
  }

  const MaskImage* mask_;
  const unsigned char* mask_buf_;
  const MaskPhantomOptions& o_;
  MaskPhantom& out_;
  Grid g_;
  Eigen::Matrix3d dir_;
  V3 origin_, down_;        // down_: gravity in the grid frame
  double depth0_ = 0;       // gravity . origin
  int lo_[3], hi_[3];       // lumen bounding box (index, [lo, hi))
  std::vector<unsigned char> mat_;
  Model md_;                // HU of fluids and bowel contrast (hu_of)
  Rng rng_;
  // Body mapping: phantom body coordinates = ((x - cx) / scale, (y - cy) / scale + 5, z0 + (z - zmin) * zscale).
  double cx_ = 0, cy_ = 0, scale_ = 1, zmin_ = 0, zscale_ = 1;
  // Coarse distance from the lumen.
  int cf_[3] = {1, 1, 1}, cn_[3] = {1, 1, 1};
  std::vector<float> clear_;
  std::size_t rectum_ = 0;  // most inferior lumen voxel
  V3 bladder_c_{0, 0, 0}, bladder_r_{0, 0, 0};
  std::vector<double> loop_clearance_;
};

}  // namespace cf::phantom_detail
