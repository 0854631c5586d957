#pragma once
// Internal to the denoise module: cut_and_cap() as named steps (surgery.cpp: the cut;
// surgery_caps.cpp: cap placement). One Surgery object per call; each method is one step.
#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <unordered_map>
#include <vector>

#include "colonflat/denoise/cap_triangulation.h"
#include "colonflat/denoise/free_space_cut.h"
#include "colonflat/denoise/homology.h"
#include "colonflat/denoise/surgery.h"

namespace cf::detail {

class TriangleHash;  // triangle_hash.h

// A disk of concentric rings around a centre vertex spanning one cut ring (the fallback cap).
struct ConcentricCap {
  std::vector<std::vector<Mesh::VertexHandle>> rings;  // rings[0] = the cut ring, boundary order
  Mesh::VertexHandle centre;
  std::vector<Mesh::FaceHandle> faces;
};

// Mean distance of the closed polygon p's points from their centroid, and its mean edge length;
// the centroid too when `centroid` is given.
void loop_radius_and_edge(const std::vector<Vec3>& p, double* radius, double* edge, Vec3* centroid = nullptr);

// Positions of a concentric disk over the closed polygon p (n >= 3 points), m >= 1 rings:
// rows[j][i] for j = 0..m-1 (row 0 = p, fixed) interpolated towards p's centroid (t = j/m) and
// the centre as the last single row, then relaxed to a discrete minimal surface by 20 m Jacobi
// sweeps of a uniform Laplacian over the disk's strips (surgery_caps.cpp: the concentric caps of
// step 8 and the relaxed closings of step 7c). Post: m + 1 rows, rows[m].size() == 1.
std::vector<std::vector<Vec3>> concentric_disk_rows(const std::vector<Vec3>& p, int m);

// Sum of the cross products of v's faces (twice their vector area): v's normal, not normalised.
Vec3 vertex_area_normal(const Mesh& mesh, Mesh::VertexHandle v);

class Surgery {
 public:
  Surgery(Mesh& mesh, const std::vector<Mesh::VertexHandle>& loop, const SurgeryOptions& opts, HomologyBasis* homology)
      : mesh_(mesh), loop_(loop), opts_(opts), homology_(homology), k_(loop.size()),
        words_(homology ? homology->words() : 0) {}
  SurgeryResult run();

 private:
  // The cut (surgery.cpp).
  void check_loop();
  void gather_left_side();
  void record_undo();
  void add_left_copies();
  void repoint_left_fans();
  void relink_left_faces();
  void link_boundary_rings();
  void copy_loop_classes();
  // Caps (surgery_caps.cpp).
  std::vector<Vec3> side_targets(const std::vector<Mesh::VertexHandle>& ring) const;
  std::vector<Vec3> edge_targets(const std::vector<Mesh::VertexHandle>& ring) const;
  void place_rings(double pull, const std::vector<Vec3>& left_target, const std::vector<Vec3>& right_target);
  std::vector<Mesh::FaceHandle> faces_around_rings() const;
  struct Placement {
    double pull;
    bool along_edge;
  };
  std::vector<Placement> placements() const;
  bool place_checked(const Placement& tr);
  // Crossings the input already had (surgery.cpp). The cap checks count only pairs this surgery
  // makes: a pair of faces older than it that intersected before the cut (the surface's own
  // crossings, e.g. the folds of a mask grown until its walls fuse) is not the caps' doing, and
  // no placement can remove it.
  bool intersected_before(int f, int g) const;
  void original_triangle(int f, std::array<int, 3>* ids, std::array<Vec3, 3>* p) const;
  // Intersecting pairs of `faces` (inserted in the guard at their current place) that are not
  // intersected_before(), at most stop_at.
  std::size_t new_pairs(const std::vector<Mesh::FaceHandle>& faces, std::size_t stop_at = SIZE_MAX) const;
  bool try_triangulated_caps();
  bool mirror_cap(const std::vector<std::array<int, 3>>& right, std::vector<std::array<int, 3>>* left);
  void add_triangulated_caps(const std::vector<std::array<int, 3>>& right, const std::vector<std::array<int, 3>>& left);
  void set_cap_classes(const std::vector<Mesh::VertexHandle>& ring, const std::vector<Mesh::HalfedgeHandle>& ring_halfedges,
                       const std::vector<Mesh::VertexHandle>& inner);
  // Both caps added with interior vertices (front and minimum-cut caps): their edge classes and the result's caps.
  void finish_caps_with_interior(const std::vector<Mesh::VertexHandle>& right_inner,
                                 const std::vector<Mesh::VertexHandle>& left_inner);
  // Restricted caps (surgery_restricted.cpp).
  struct LeftAhead {  // left_first()'s first triangulation, made on the helper thread (run_both)
    std::vector<std::array<int, 3>> tris;
    long long queries = -1;  // grid queries it made; -1: called off (or not run)
    std::atomic<bool> cancel{false};
  };
  bool triangulate_both(bool avoid, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left);
  bool right_then_left(bool avoid, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left);
  void left_ahead(long long budget, LeftAhead* ahead) const;
  bool left_first(const LeftAhead& ahead, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left);
  void set_chord_classes(const std::vector<Mesh::VertexHandle>& ring);
  std::unordered_map<int, std::vector<std::uint64_t>> ring_potentials(const std::vector<Mesh::VertexHandle>& ring) const;
  // A left-side ring as its hole runs: x_0, x_(k-1), ..., x_1 (the left ring itself, or its collar).
  static std::vector<Mesh::VertexHandle> left_cap_order(const std::vector<Mesh::VertexHandle>& ring);
  // Collar caps (surgery_collar.cpp).
  struct CollarShape {
    double sign;                   // -1: against the normals (into the enclosed solid), +1: along them
    double right_frac, left_frac;  // fraction of each ring's collar height used
  };
  bool try_collar_caps();
  double disk_side() const;
  std::vector<Vec3> unit_normals(const std::vector<Mesh::VertexHandle>& ring) const;
  std::vector<double> collar_heights(const std::vector<Mesh::VertexHandle>& ring, const std::vector<Vec3>& normals,
                                     double sign) const;
  bool collar_caps(const CollarShape& shape, const std::vector<double>& h_right, const std::vector<double>& h_left);
  std::vector<std::array<int, 3>> collar_right_triangles(const std::vector<Mesh::VertexHandle>& collar);
  bool clean(const std::vector<std::array<int, 3>>& tris) const;
  void set_collar_classes(const std::vector<Mesh::VertexHandle>& ring, const std::vector<Mesh::VertexHandle>& collar);
  // Front caps (surgery_front.cpp). Sides: the unit normals of both rings at a loop vertex,
  // times the side of the surface the cap's disk lies on.
  using Sides = std::array<Vec3, 2>;
  bool try_front_caps();
  bool front_caps(double sign);
  struct FrontCap {
    std::vector<std::array<int, 3>> tris;  // mesh vertex ids, in ear order
    std::vector<Mesh::VertexHandle> inner;  // interior vertices
  };
  bool front_cap_pair(double sign, FrontCap* right, FrontCap* left);
  bool close_front(const std::vector<std::array<int, 3>>& disk, FrontCap* right, FrontCap* left);
  bool left_front_cap(const FrontCap& right, double fraction, FrontCap* left);
  // Relaxed closings (surgery_relaxed.cpp).
  void add_relaxed_disk(const std::vector<Mesh::VertexHandle>& front, const std::vector<std::vector<Vec3>>& rows,
                        FrontCap* right);
  bool close_front_relaxed(const std::vector<Mesh::VertexHandle>& front, FrontCap* right, FrontCap* left);
  std::vector<Vec3> front_inward(const std::vector<Mesh::VertexHandle>& f, const std::vector<std::array<int, 3>>& disk) const;
  std::vector<Vec3> front_directions(const std::vector<Mesh::VertexHandle>& f, const std::vector<std::array<int, 3>>& disk,
                                     double step, const std::vector<Sides>& side) const;
  double front_free(const Vec3& p, const Vec3& d, double step) const;
  static std::vector<int> front_groups(const std::vector<Vec3>& g, double step);
  std::vector<Mesh::VertexHandle> advance_front(const std::vector<Mesh::VertexHandle>& f, const std::vector<Vec3>& dir,
                                                const std::vector<double>& scale, double step,
                                                std::vector<std::array<int, 3>>* strip);
  std::vector<Mesh::VertexHandle> clean_layer(const std::vector<Mesh::VertexHandle>& f, const std::vector<Vec3>& dir,
                                              double step, std::vector<std::array<int, 3>>* tris);
  bool clean_from(const std::vector<std::array<int, 3>>& tris, std::size_t from,
                  const std::vector<std::array<int, 3>>& others) const;
  // Minimum-cut caps (surgery_mincut.cpp).
  bool try_mincut_caps();
  FreeSpaceBox mincut_box() const;
  std::vector<SidedTriangle> sided_faces(const FreeSpaceBox& box, std::vector<int>* ids = nullptr) const;
  double place_mincut_caps(const CutDisk& disk, const FreeSpaceBox& box);
  double widened_mincut_caps(const CutDisk& first, const FreeSpaceBox& box, std::vector<SidedTriangle> sided,
                             std::vector<int> ids, bool* hole_free);
  // Wall widening at a disk's holes (surgery_mincut_widen.cpp).
  std::unordered_map<int, int> vertex_sides(const std::vector<SidedTriangle>& sided, const std::vector<int>& ids) const;
  std::vector<std::pair<Mesh::VertexHandle, Vec3>> widening_moves(const CutDisk& disk, const std::unordered_map<int, int>& side,
                                                                  double shift) const;
  std::vector<Mesh::FaceHandle> set_points(const std::vector<std::pair<Mesh::VertexHandle, Vec3>>& points);
  bool widen_at_holes(const CutDisk& disk, const std::vector<SidedTriangle>& sided, const std::vector<int>& ids, double shift,
                      std::vector<std::pair<Mesh::VertexHandle, Vec3>>* before, double* largest);
  void flood_sides(const std::vector<int>& local, std::deque<Mesh::FaceHandle>* queue,
                   std::vector<SidedTriangle>* out) const;
  const CutDisk* ring_disk(const std::vector<CutDisk>& disks, double cell) const;
  bool disk_runs_with_loop(const CutDisk& disk) const;
  // Strips (surgery_mincut_strip.cpp).
  bool mincut_strip(const std::vector<Mesh::VertexHandle>& ring, const std::vector<int>& inner,
                    const std::vector<char>& forbidden, std::vector<std::array<int, 3>>* tris,
                    std::vector<std::size_t>* keys) const;
  bool mincut_strips(const std::vector<int>& inner, const std::unordered_map<int, int>& mirror, const TriangleHash& disks,
                     double cell, std::vector<std::array<int, 3>>* right, std::vector<std::array<int, 3>>* left,
                     std::vector<int>* disk_hits) const;
  std::vector<std::size_t> failed_strip_triangles(const std::vector<std::array<int, 3>>& right,
                                                  const std::vector<std::array<int, 3>>& left, const TriangleHash& disks,
                                                  double cell, std::vector<int>* disk_hits) const;
  FrontCap mincut_cap(const CutDisk& disk, double shift, int rim_passes, bool flip);
  FrontCap mincut_mirror(const CutDisk& disk, const FrontCap& right, double shift, int rim_passes, bool flip);
  bool close_hole(const std::vector<int>& rim, const std::vector<int>& id, bool flip,
                  const std::vector<std::array<int, 3>>& others, std::vector<std::array<int, 3>>* tris) const;
  bool close_mincut_holes(const CutDisk& disk, bool flip, double cell, FrontCap* right, FrontCap* left) const;
  bool mirrored_fill(const std::vector<int>& rim, const std::vector<int>& from, const std::vector<int>& to, bool flip,
                     const std::vector<std::array<int, 3>>& own, const std::vector<std::array<int, 3>>& all,
                     std::vector<std::array<int, 3>>* fill, std::vector<std::array<int, 3>>* mirrored) const;
  bool join_mincut_rims(const CutDisk& disk, bool flip, double cell, FrontCap* right, FrontCap* left,
                        std::vector<int>* disk_hits) const;
  bool mincut_caps(const CutDisk& disk, double shift, double left_shift, int rim_passes, double cell);
  bool mincut_caps_once(const CutDisk& disk, double shift, double left_shift, int rim_passes, double cell,
                        std::vector<int>* disk_hits);
  void add_ordered(const std::vector<std::array<int, 3>>& tris);
  ConcentricCap make_concentric_cap(const std::vector<Mesh::HalfedgeHandle>& ring_halfedges);
  void set_concentric_classes(const ConcentricCap& cap, const std::vector<Mesh::HalfedgeHandle>& ring_halfedges);
  void shape_concentric_cap(ConcentricCap& cap, double dome);
  void place_concentric(double pull, double dome);
  void concentric_caps();
  void search_concentric_placement();

  Mesh& mesh_;
  const std::vector<Mesh::VertexHandle>& loop_;
  const SurgeryOptions& opts_;
  HomologyBasis* homology_;
  const std::size_t k_;
  const int words_;
  int first_new_vertex_ = 0, first_new_face_ = 0;  // the mesh's counts before the cut (elements are only appended)
  std::vector<Mesh::HalfedgeHandle> loop_halfedges_;       // h_i: loop_i -> loop_(i+1), left face = left side
  std::vector<std::vector<Mesh::HalfedgeHandle>> fan_;     // interior outgoing halfedges of each left fan
  std::vector<Mesh::FaceHandle> left_faces_;               // faces left of some h_i
  std::vector<std::array<Mesh::HalfedgeHandle, 3>> face_cycle_;
  std::vector<Mesh::HalfedgeHandle> new_halfedges_, new_opposites_;  // y_i (copies of h_i) and x_i = opp(y_i)
  std::unordered_map<int, Mesh::HalfedgeHandle> replaced_;  // h_i -> y_i
  std::vector<Vec3> original_;                               // loop positions before any move
  std::vector<Vec3> target_left_, target_right_, edge_left_, edge_right_;
  std::vector<Mesh::FaceHandle> ring_faces_;                 // faces around the two rings
  std::vector<Vec3> normal_left_, normal_right_;             // unit normals of the placed rings' own sides
  ConcentricCap cap_left_, cap_right_;
  SurgeryResult result_;
  RingQueryCache right_cache_, left_cache_;  // grid answers of each ring's restricted triangulations, this placement
  bool gave_up_ = false;                // no more restricted triangulations (budget spent, or the right ring has none)
  long long query_budget_ = 0;          // grid queries left for them (kMaxGridQueries per surgery)
  int peel_rounds_left_ = 0;            // minimum-cut caps: disk peelings left for this loop (surgery_mincut.cpp)
  const char* cap_kind_ = "concentric";  // which step made the caps (COLONFLAT_DENOISE_DEBUG)
};

}  // namespace cf::detail
