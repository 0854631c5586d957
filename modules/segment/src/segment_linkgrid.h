#pragma once
// The coarse grid on which fully tagged stretches are linked to colon segments (docs/segment.md
// step 6): cells of about 2.5 mm hold the colon segment and the candidate body they overlap; the
// contacts between candidates and segments are found through the gap by breadth-first growth, and
// each body's shape near a contact is measured in its own geodesic neighbourhood (the body's cells
// within a path length inside the body), so that a bending colon or another loop of colon passing
// nearby does not disturb it.
//
//   LinkGrid g(fine_dims, 2.5);
//   g.mark(q, segment, candidate) for every fine voxel; g.contacts(...); g.shape(...); g.absorb(...)
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "segment_internal.h"

namespace cf::segment_detail {

// The link-grid segment id a kept candidate l takes (absorb(l, kKeptCandidateId + l)): above every
// gas segment's id, so that the segment and candidate id spaces never meet.
constexpr std::uint32_t kKeptCandidateId = 0x80000000u;

// A contact between a candidate body and a colon segment across the gap (coarse cells).
struct Contact {
  std::uint32_t candidate = 0, segment = 0;
  std::size_t from = 0, to = 0;  // the candidate's cell and the segment's cell
  double gap_mm = 0;
};

// A geodesic front: the body's cells whose path length from the start lies in [radius - width, radius).
struct Front {
  double radius_mm = 0;
  std::size_t cells = 0;
  int pieces = 0;                                     // 26-connected pieces holding >= 15 % of its cells
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // relative to the start (mm)
};

// A body's local shape seen from a cell on it, measured along paths inside the body: at the end of
// a tube every front is one disc moving away from the start; on a tube's side the fronts beyond the
// tube's diameter split in two (one piece each way).
struct LocalShape {
  std::size_t cells = 0;
  double reach_mm = 0;        // largest path length reached (<= the radius asked for)
  std::vector<Front> fronts;  // at radius/3, 2 radius/3 and radius (those reached)
  std::vector<std::pair<std::size_t, double>> region;  // the cells reached and their path lengths, sorted by cell
  // Whether `cell` lies within `mm` of path from the start.
  bool within(std::size_t cell, double mm) const {
    auto it = std::lower_bound(region.begin(), region.end(), std::make_pair(cell, -1.0));
    return it != region.end() && it->first == cell && it->second <= mm;
  }
};

class LinkGrid {
 public:
  // fine: the crop's voxel grid; cell_mm: target cell size (each axis gets a whole number of voxels).
  LinkGrid(const Dims& fine, double cell_mm);
  const Dims& dims() const { return d_; }
  // Marks the cell of fine voxel (i, j, k) with a segment id and/or a candidate id (0 = none).
  void mark(std::size_t i, std::size_t j, std::size_t k, std::uint32_t segment, std::uint32_t candidate) {
    const std::size_t c = d_.idx(i / f_[0], j / f_[1], k / f_[2]);
    if (segment) seg_[c] = segment;
    if (candidate) cand_[c] = candidate;
  }
  // The segment id of the cell holding fine voxel q (0: none).
  std::uint32_t segment_at(std::size_t q, const Dims& fine) const {
    std::size_t i, j, k;
    fine.coords(q, i, j, k);
    return seg_[d_.idx(i / f_[0], j / f_[1], k / f_[2])];
  }
  // Contacts of the eligible candidates with the segments within gap_mm: per (candidate, segment)
  // up to max_per_pair contacts, nearest first, at least separation_mm apart on the candidate.
  std::vector<Contact> contacts(const std::vector<unsigned char>& eligible, double gap_mm, std::size_t max_per_pair,
                                double separation_mm) const;
  // Local shape of the segment (or candidate) with this id around `start`, within radius_mm of path.
  LocalShape segment_shape(std::uint32_t id, std::size_t start, double radius_mm) const;
  LocalShape candidate_shape(std::uint32_t id, std::size_t start, double radius_mm) const;
  // A kept candidate becomes part of colon segment `segment` (colon for later contacts).
  void absorb(std::uint32_t candidate, std::uint32_t segment);
  Eigen::Vector3d mm(std::size_t cell) const;
  // Width of a geodesic front (two cells along the coarsest axis, mm).
  double front_width_mm() const { return 2.0 * std::max({d_.sp[0], d_.sp[1], d_.sp[2]}); }
  // Equivalent diameter (mm) of a front of `cells` cells: the disc whose area times the front's width
  // holds the cells' volume (a tube's cross-section; where the body is wider than the front's radius
  // the front is a cap and this over-reads).
  double front_diameter_mm(std::size_t cells) const {
    return 2.0 * std::sqrt(double(cells) * d_.sp[0] * d_.sp[1] * d_.sp[2] / (front_width_mm() * 3.14159265358979));
  }
  // The fine voxels of `cell`: [lo, hi) along each axis of `fine`.
  void fine_box(std::size_t cell, const Dims& fine, std::size_t lo[3], std::size_t hi[3]) const {
    std::size_t c[3];
    d_.coords(cell, c[0], c[1], c[2]);
    for (int a = 0; a < 3; ++a) lo[a] = c[a] * std::size_t(f_[a]), hi[a] = std::min(fine.n[a], lo[a] + std::size_t(f_[a]));
  }
  // The centre of `cell` in fine voxel coordinates (continuous).
  Eigen::Vector3d fine_centre(std::size_t cell) const {
    std::size_t c[3];
    d_.coords(cell, c[0], c[1], c[2]);
    return {double(c[0]) * f_[0] + 0.5 * (f_[0] - 1), double(c[1]) * f_[1] + 0.5 * (f_[1] - 1), double(c[2]) * f_[2] + 0.5 * (f_[2] - 1)};
  }

 private:
  LocalShape shape(const std::vector<std::uint32_t>& labels, std::uint32_t id, std::size_t start, double radius_mm) const;
  std::vector<std::pair<std::size_t, double>> geodesic(const std::vector<std::uint32_t>& labels, std::uint32_t id,
                                                       std::size_t start, double radius_mm) const;
  Front front(const std::vector<std::pair<std::size_t, double>>& settled, std::size_t start, double radius_mm, double width_mm) const;
  void grow(std::vector<std::uint32_t>& source, std::vector<Contact>& found, const std::vector<unsigned char>& eligible,
            double gap_mm) const;

  Dims d_{};
  int f_[3] = {1, 1, 1};
  std::vector<std::uint32_t> seg_, cand_;
};

}  // namespace cf::segment_detail
