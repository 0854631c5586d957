#pragma once
// Internal model of the phantom generator (docs/phantom.md): random numbers, the voxel grid, the
// colon path with rotation-minimising frames, the placed features (folds, pools, polyps, strands,
// holes, bulges, fully tagged stretches, small bowel, bladder, vessels, rectal tube) and the builder
// that places and paints them step by step. Units: LPS millimetres; +y posterior, +z superior.
#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "colonflat/phantom/phantom.h"

namespace cf::phantom_detail {

using V3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

// Deterministic random numbers (splitmix64; independent of the standard library's distributions).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) { next(); }
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double normal() {
    double u1 = uniform(), u2 = uniform();
    if (u1 < 1e-300) u1 = 1e-300;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * kPi * u2);
  }

 private:
  std::uint64_t s_;
};

// Materials of the label volume; kFluid0 + k is fluid body k (pools, then fully tagged stretches).
enum Material : unsigned char {
  kOutsideAir = 0, kSubcutFat, kMuscle, kVisceralFat, kLiver, kKidney, kSpineCancellous, kSpineCortex, kLung,
  kColonWall, kColonGas, kOtherGas, kPolyp,
  kBowelWall, kBowelContrast, kBowelGas, kBladderWall, kUrine, kBladderContrast, kTubeWall, kTubeAir, kAorta,
  kFluid0
};

// Ground-truth labels written to labels.nrrd.
enum TruthLabel : unsigned char {
  kTruthOther = 0, kTruthColonGas = 1, kTruthColonFluid = 2, kTruthBowelContrast = 3, kTruthBowelGas = 4,
  kTruthBladder = 5, kTruthTube = 6, kTruthOtherGas = 7, kTruthVessel = 8
};

struct ControlPoint {
  V3 p;
  double r;
  int seg;  // index into kSegmentNames
};
extern const char* const kSegmentNames[6];

// The centreline resampled every 1 mm of the supine arc length s (a material coordinate kept in
// the prone position); arc = true arc length of this (possibly deformed) path.
struct Path {
  std::vector<V3> p, T, N, B;
  std::vector<double> s, r, arc;
  std::vector<int> seg;
  double length = 0;
};
std::vector<ControlPoint> base_path();
Path make_path(const std::vector<ControlPoint>& cps, double step);
void compute_frames(Path& path);  // T, N, B (rotation minimising) and arc from p

struct Grid {
  std::array<int, 3> n;
  std::array<double, 3> sp, org;
  V3 point(int i, int j, int k) const { return {org[0] + i * sp[0], org[1] + j * sp[1], org[2] + k * sp[2]}; }
  std::size_t index(int i, int j, int k) const { return (std::size_t(k) * n[1] + j) * n[0] + i; }
  std::size_t voxels() const { return std::size_t(n[0]) * n[1] * n[2]; }
  // Index range [lo, hi) covering [a, b] mm along axis d.
  void range(int d, double a, double b, int& lo, int& hi) const {
    lo = std::max(0, int(std::ceil((a - org[d]) / sp[d])));
    hi = std::min(n[d], int(std::floor((b - org[d]) / sp[d])) + 1);
  }
};

struct Fold {
  double s, depth, width, theta0;  // arclength, depth fraction of radius, half-width mm, crescent phase
};
struct Pool {
  double s0, s1;  // arclength range of the segment it lies in
  double level_y, hu;
  V3 seed;  // a point below the level in the lumen: the pool is the lumen below the level connected to it
  std::size_t voxels = 0;
};
struct TaggedStretch {  // a colon stretch completely filled with tagged fluid between two collapsed necks
  double s0, s1, hu;
  std::size_t voxels = 0;
};
struct Collapse {
  double s, len;
};
struct Bulge {
  double s, amp, sigma_s;
  V3 toward;  // unit direction the bulge points to
};
struct Polyp {
  PhantomPolyp gt;
  V3 center, base, axis;  // head centre, wall attachment point, axis (wall -> lumen)
  double stalk_r = 0;
};
struct Capsule {  // a segment with a radius (strands, holes, tube pieces, small-bowel pieces)
  V3 a, b;
  double r;
  double s = 0;
};
struct BowelLoop {  // a small-bowel loop: centreline samples, radius, gas above `gas_level` (non-dependent)
  std::vector<V3> pts;
  double r = 12, hu = 400, gas_level = 0;
};

struct Model {
  Grid g;
  Path path, supine_path;
  double gravity = 1;  // +1: supine (posterior, +y, down); -1: prone (anterior down)
  std::vector<Fold> folds;
  std::vector<Pool> pools;
  std::vector<TaggedStretch> stretches;
  std::vector<Collapse> collapses;
  std::vector<Bulge> bulges;
  std::size_t touch_i = 0, touch_j = 0;
  double touch_gap = 0;
  std::vector<Polyp> polyps;
  std::vector<Capsule> strands, holes, tube;
  std::vector<BowelLoop> bowel;
  bool bladder = false, aorta = false;
  V3 bladder_c{0, 0, 0}, bladder_r{0, 0, 0};  // bladder centre and radii (mm)
  Capsule aorta_seg{};
  double wall = 3.0;
  std::vector<std::pair<V3, V3>> gas;  // other gas: centre, radii
  std::vector<NoiseSite> sites;
};

double seg_point_dist2(const V3& p, const V3& a, const V3& b, double* tout = nullptr);
void parallel_for(int n, const std::function<void(int, int)>& body);
double open_radius_at(const Model& m, std::size_t i, double t);
double radius_at(const Model& m, std::size_t i, double t);
double lumen_radius(const Model& m, double s, double r, double theta, const V3& u);
void paint_body(const Grid& g, std::vector<unsigned char>& mat);
double hu_of(unsigned char m, const Model& md);
bool is_lumen(unsigned char m);
unsigned char body_material(double x, double y, double z);
TruthLabel truth_of(unsigned char m);

// Places the features of one case (layout) from the options and the seed.
class PhantomLayout {
 public:
  PhantomLayout(const PhantomOptions& o, Model& md);
  void run();

 private:
  void make_grid();
  void make_colon_path();
  void place_folds();
  void place_collapse();
  void place_near_touch();
  void place_pools(Rng& rng, bool prone);
  void place_polyps();
  void place_strands_and_holes();
  void place_other_gas();
  void place_tagged_stretches();
  void place_small_bowel();
  bool add_bowel_loop();
  void place_bladder_and_aorta();
  void place_rectal_tube();
  void make_prone_path();
  void deform_to_prone();
  V3 to_prone(const V3& q, std::size_t i, bool direction) const;
  double seg_start(int seg) const;
  double seg_end(int seg) const;
  std::size_t index_at(double s) const;
  double nearest_fold_gap(double s) const;
  bool in_pool_s(double s) const;
  bool free_s(double s, double clearance) const;
  V3 cross_dir(std::size_t i, const V3& want) const;
  double colon_clearance(const V3& q) const;  // distance from q to the outer colon wall, both positions

  const PhantomOptions& o_;
  Model& md_;
  Rng rng_, extra_rng_;
  double hmax_ = 1;
  std::vector<double> used_s_;
  Path prone_path_;
};

// Paints the label volume of a placed model.
class PhantomPainter {
 public:
  PhantomPainter(Model& md, std::vector<unsigned char>& mat) : md_(md), mat_(mat) {}
  void run();

 private:
  void paint_other_gas();
  void paint_vessels_and_bladder();
  void nearest_centreline();
  void paint_colon();
  void paint_polyps();
  void paint_capsules(const std::vector<Capsule>& caps, unsigned char from_lumen_to);
  void paint_holes();
  void fill_stretches();
  void fill_pools();
  void paint_small_bowel();
  void paint_rectal_tube();
  struct Local {
    double s, d, R, Reff, theta;
    double outer;  // outer wall radius (mm): the open colon's wall area kept where the lumen collapses
    std::size_t i;
    V3 u;
  };
  bool local_at(int i, int j, int k, Local& L) const;

  Model& md_;
  std::vector<unsigned char>& mat_;
  int blo_[3] = {0, 0, 0}, bhi_[3] = {0, 0, 0}, bn_[3] = {0, 0, 0};
  std::vector<float> best_s_;
  std::size_t bidx(int i, int j, int k) const {
    return (std::size_t(k - blo_[2]) * bn_[1] + (j - blo_[1])) * bn_[0] + (i - blo_[0]);
  }
};

}  // namespace cf::phantom_detail
