#pragma once
// Internal pieces of the flatten stage (not installed): the local surface of one colon segment,
// its edge graph, the harmonic (conformal) solve, the 2D embedding on the periodic cylinder,
// the centreline, the area balancing and the distortion measures. See docs/flatten.md.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "colonflat/core/orientation.h"
#include "colonflat/core/topology.h"
#include "colonflat/flatten/flatten.h"
#include "debug_clock.h"
#include "segment_order.h"
#include "shifted_corner.h"

namespace cf::flat_detail {

using V3 = Eigen::Vector3d;
using V2 = Eigen::Vector2d;
using Tri = std::array<int, 3>;

// One colon segment as an indexed triangle surface (LPS mm).
struct Surface {
  std::vector<V3> p;
  std::vector<Tri> t;
  std::vector<int> src;  // input vertex id of each local vertex
};

// Which components of the input are flattened (component_screen.cpp). admit() says whether
// component c is colon wall to flatten; a component that is not is skipped with its reason (too
// small, a cavity's wall) or refused with a PreconditionError naming it, its size and the cause
// (not a 2-manifold, genus > 0, open in more than 2 places, normals into the lumen).
class ComponentScreen {
 public:
  ComponentScreen(const TriangleList& mesh, const TopologyReport& topo, const FlattenOptions& o);
  bool admit(std::size_t c);
  double lumen_sign(std::size_t c) const;  // +1 when normals point out of the lumen
  const std::vector<std::string>& skipped() const { return skipped_; }
  // Throws the PreconditionError for an input with no component to flatten, naming each skipped one.
  [[noreturn]] void nothing_flattened() const;
  std::string name(std::size_t c) const;  // "component 0 (1460112 faces, 52341 mm2, encloses 3800.0 mL)"

 private:
  bool skip(std::size_t c, const std::string& why);
  const TriangleList& mesh_;
  const TopologyReport& topo_;
  const FlattenOptions& o_;
  std::vector<ComponentSide> sides_;
  std::vector<std::string> skipped_;
};

// Edge graph: edges lo < hi, sorted by (lo, hi), their one or two faces, and the edge opposite
// each face corner.
struct Edges {
  std::vector<std::array<int, 2>> ev;
  std::vector<std::array<int, 2>> ef;  // [1] = -1 on the boundary
  std::vector<std::array<int, 3>> fe;
};
Edges build_edges(const std::vector<Tri>& t);  // throws PreconditionError on a non-manifold edge
std::size_t build_edges_count();               // how many edge graphs build_edges built (process)
// The edges of sub_surface(s, keep, &new_of_old) taken from E = build_edges(s.t): equal to
// build_edges of the sub-surface's faces, without walking its corners again. Pre: keep has one entry
// per face of s, new_of_old is sub_surface's vertex map.
Edges sub_edges(const Edges& E, const std::vector<char>& keep, const std::vector<int>& new_of_old);

struct Csr {  // vertex adjacency with edge lengths (mm)
  std::vector<int> start, nbr;
  std::vector<double> len;
};
Csr build_csr(const Surface& s, const Edges& E);
// Geodesic distance along edges from the nearest source. Distances <= settle_up_to (mm) are final;
// the search stops beyond: any other vertex holds infinity or a value above settle_up_to.
std::vector<double> dijkstra(const Csr& g, const std::vector<int>& sources, double settle_up_to = std::numeric_limits<double>::infinity());
int argmax_finite(const std::vector<double>& d);
std::vector<std::vector<int>> boundary_loops(const Surface& s, const Edges& E);
double face_area_3d(const Surface& s, int f);

// The segment opened into an annulus: caps of geodesic radius <= `radius` removed at closed ends.
struct Opened {
  Surface annulus;
  std::size_t removed = 0;
  std::vector<int> new_of_old;  // per vertex of the surface: its id on the annulus, -1 when removed
  Edges edges;                  // the annulus' edges (= build_edges(annulus.t))
};
Opened open_ends(const Surface& s, const Edges& E, std::size_t nloops, double radius);
// Keeps the largest edge-connected set of faces among `keep`.
void keep_largest_component(const Edges& E, std::vector<char>& keep);
// The faces keep_largest_component would drop from the complement of `in` (the pieces of !in other
// than its largest: islands `in` encloses), ascending. Pre: the surface is edge-connected. The
// complement is flooded only from the faces next to `in`, each piece up to `budget` faces: when
// exactly one piece reaches it, that piece is the largest and is walked no further (for a pouch
// the complement is the whole band); else, or when pieces are left unwalked, the whole complement
// is searched as keep_largest_component does. The same faces either way.
std::vector<int> enclosed_by(const Edges& E, const std::vector<char>& in, std::size_t budget);
// The kept faces (`keep[f]`), reindexed; src carried over; `new_of_old` (optional): new vertex id
// of each old one, -1 when dropped.
Surface sub_surface(const Surface& s, const std::vector<char>& keep, std::vector<int>* new_of_old = nullptr);
// The same for the faces `faces` (ascending, no repeats): sub_surface of their mask.
Surface sub_surface(const Surface& s, const std::vector<int>& faces, std::vector<int>* new_of_old = nullptr);
// Drops kept faces at pinch vertices and faces with all corners on the boundary, and keeps the
// largest edge-connected piece, until the selection's boundary is a set of simple loops.
void clean_selection(const Surface& s, const Edges& E, std::vector<char>& keep);
// clean_selection of the faces `faces` (any order, repeats allowed): the faces it keeps, ascending. Walks
// only these faces and their edges (a side branch is a small part of its annulus). `scratch`
// (optional): per face 0 / -1 and per vertex 0 between calls (sized on first use; the cuts of one
// annulus share it instead of each allocating three arrays the size of the annulus).
struct FaceSetScratch {
  std::vector<char> keep;
  std::vector<int> comp, bcount;
};
std::vector<int> clean_face_set(const Surface& s, const Edges& E, std::vector<int> faces, FaceSetScratch* scratch = nullptr);

// Conformal coordinates: u harmonic (0 on loop A, 1 on loop B), v its conjugate with unit period,
// eta the cut cocycle (per edge, lo -> hi), period = the conformal period in u units.
struct ConformalFactor;  // conformal_factor.h: the factorisation of a conformal solve
// What a conformal solve leaves for the next one on the same surface or on the part of it that
// remains after side branches are cut off.
struct PriorSolve {
  std::vector<int> vertex_order;            // the vertices in a fill-reducing elimination order (empty: none)
  std::shared_ptr<ConformalFactor> factor;  // the factorisation (null: none)
  std::vector<int> new_of_old;              // per vertex of the factor's surface: its id here, -1 when cut off
  // The order while it is still being computed (a segment's first solve: beside the opening of its
  // ends): gives vertex_order's value, waiting for it; asked only once a new factorisation needs the
  // order, so the system is assembled meanwhile. Empty: vertex_order is final.
  std::function<std::vector<int>()> order_when_ready;
};
struct Harmonic {
  Eigen::VectorXd u, v;
  std::vector<signed char> eta;
  double period = 0;
  double energy_u = 0;
  std::string weights;
  std::vector<int> vertex_order;            // the fill-reducing elimination order used (all vertices; empty: none)
  std::shared_ptr<ConformalFactor> factor;  // its factorisation, when new (null when an earlier one was updated)
};
// `prior` (optional): an earlier solve's vertex order (e.g. on a surface this one is a subset of;
// AMD when there is none; prior->order_when_ready is asked for it after the system is assembled) and, with the same weights (`clamp`) and `new_of_old` set, its factor,
// updated to this surface (conformal_update.cpp) instead of a new factorisation; consumed.
Harmonic solve_harmonic(const Surface& s, const Edges& E, const std::vector<int>& loop_a,
                        const std::vector<int>& loop_b, bool clamp, PriorSolve* prior = nullptr);
// The elimination orders of a segment's systems: segment_order.h.

// A map of the annulus onto the periodic cylinder [0, L] x R/(period): vertex positions (mm) and,
// per face, the y offset of each corner (a whole number of periods) so that every face is contiguous.
struct Embedding {
  std::vector<V2> pos;
  std::vector<std::array<double, 3>> dy;
  double period = 0;
  std::array<V2, 3> corners(const Surface& s, int f) const { return shifted_corners(s.t[f], pos, dy[f]); }
  double area2(const Surface& s, int f) const {  // signed 2D area
    const auto c = corners(s, f);
    const V2 a = c[1] - c[0], b = c[2] - c[0];
    return 0.5 * (a.x() * b.y() - a.y() * b.x());
  }
};
// A face whose 2D area is at most this fraction of its 3D area is not in the map ("crowded": a
// sliver or fold-over). untangle() repairs exactly these; measure() counts what is left.
constexpr double kMinInMapAreaRatio = 1e-7;
inline bool too_small_in_map(double area2, double area3) { return area2 <= kMinInMapAreaRatio * area3; }
// Wall a band (or a local piece of it) may leave shown below coverage_min_ratio before a local
// area correction pass works on it: 0.25 % of its 3D area, half of what the coverage target
// (99.5 % shown) allows, so a band passed over still meets the target with a margin.
constexpr double kHiddenWallTolerance = 0.0025;
// (u, sign * v * period) * scale, corners lifted so that each face's centroid y lies in [0, P).
Embedding embed_conformal(const Surface& s, const Edges& E, const Harmonic& h, double sign, double scale);
// Re-places each corner offset so that every face's centroid y lies in [0, period).
void normalise_corner_offsets(const Surface& s, Embedding& emb);

// A side branch of an annulus: a pouch reached through a neck (a diverticulum, a colon loop left
// blind by a cut, the appendix), where the conformal map collapses exponentially. `faces` (of the
// annulus) form a topological disk whose rim is the neck: the shortest level set of the flat
// distance from the collapse (see docs/flatten.md, "Side branches").
struct BranchCut {
  std::vector<int> faces;
  double area_mm2 = 0;  // 3D area of the branch
  double neck_mm = 0;   // 3D length of the neck
  V2 centre;            // flat position of the collapse in the conformal embedding (mm)
  bool tissue = false;  // the region closed over the neck holds tissue (a crushed strand stump), not lumen
};
// Branches whose collapsed part (area ratio < 0.01) covers at least `min_area_mm2`; in the order
// taken, disjoint; pouches of the lumen (face normals x `lumen_sign` point out of the lumen), not tissue
// protrusions (a polyp on a stalk) unless their cluster holds a fold (negative 2D area: crushed
// below what the map's doubles resolve, e.g. a long strand stump). `emb`: conformal embedding at
// the area-preserving scale (not untangled), band [0, length] in x.
// The clusters' branches are searched side by side on thread_count() threads, each as if no other
// branch were cut, then taken in order (largest cluster first); a search whose faces meet a branch
// taken before it is done again against those faces. A branch taken before that such a search
// holds as an island (a pouch nested inside the later branch's neck) is dropped: the later
// branch's band holds it (its own flatten finds it again). The cuts are those of a one-by-one
// search, for any thread count, in the order taken. `search` (optional): what was done.
struct BranchSearch {
  std::size_t clusters = 0;        // collapsed clusters of at least min_area_mm2 (all searched side by side)
  std::size_t searched_again = 0;  // searches done again against the faces of branches taken before
  std::size_t absorbed = 0;        // branches taken before that a later branch's neck enclosed (dropped: its band holds them)
};
std::vector<BranchCut> find_branches(const Surface& s, const Edges& E, const Embedding& emb, double length,
                                     double lumen_sign, double min_area_mm2, BranchSearch* search = nullptr);

// Vertex -> incident faces.
std::vector<std::vector<int>> vertex_faces(const Surface& s);

// Re-embeds the vertices of flipped faces and rings around them with uniform (Tutte) weights,
// the ends and the ring around the region fixed. Returns the number of vertices moved.
std::size_t untangle(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                     const std::vector<char>& fixed, const std::vector<char>& degenerate);

// Per-face quadratic system on a region: minimises sum_f sum_k w_fk |c_a - c_b - t_fk|^2 over the
// free vertices (c = corner positions, (a, b) = the corners after k), the others fixed.
// The lower triangle (compressed columns, rows ascending, the diagonal first) of
// sum_f sum_k w_fk (e_a - e_b)(e_a - e_b)^T over the unknowns `index` (per vertex of s, -1: fixed;
// n of them) for the faces `faces` (w: per face of `faces`, the weight of the edge opposite each
// corner): each entry summed in face order, so bit for bit the matrix Eigen's setFromTriplets
// gives from the terms in face order (what RegionSystem::build assembled before).
Eigen::SparseMatrix<double> region_lower(const Surface& s, const std::vector<int>& faces,
                                         const std::vector<std::array<double, 3>>& w, const std::vector<int>& index, int n);

class RegionSystem {
 public:
  // `free_vertex[v]` true for unknowns; `faces`: faces with at least one free vertex; `w`: per face
  // of `faces`, the weight of the edge opposite each corner (> 0).
  // `vertex_order` (optional): a fill-reducing order of the surface's vertices, restricted to the
  // unknowns (else AMD's on the system).
  bool build(const Surface& s, const std::vector<char>& free_vertex, const std::vector<int>& faces,
             const std::vector<std::array<double, 3>>& w, const std::vector<int>* vertex_order = nullptr);
  // New positions of the free vertices for targets t (per face of `faces`, per corner k: the
  // target of c_{k+1} - c_{k+2}); returns them as a full-size copy of emb.pos.
  std::vector<V2> solve(const Surface& s, const Embedding& emb, const std::vector<std::array<V2, 3>>& t) const;
  // x = A^-1 b for the system matrix A (n x 2, rows in the order of unknowns()).
  Eigen::MatrixXd solve_raw(const Eigen::MatrixXd& b) const;
  // Unknown index of a vertex (-1 when fixed).
  int index(int v) const { return index_[v]; }
  const std::vector<int>& faces() const { return faces_; }
  const std::vector<int>& unknowns() const { return vars_; }

 private:
  struct Impl;
  std::vector<int> faces_, vars_, index_;
  std::vector<std::array<double, 3>> w_;
  std::shared_ptr<Impl> impl_;
};

// Centreline of a segment from the level sets of u (per vertex in [0,1]): area-weighted
// centroids of slices, smoothed; s_of_u maps u to arc length (mm), strictly increasing.
struct Centreline {
  std::vector<std::array<double, 3>> points;  // LPS mm, end A first
  std::vector<double> knot_u, knot_s;         // s(u) piecewise linear through these knots
  double length = 0;                          // mm
  std::vector<double> area_cdf;               // wall area fraction with u' < k / (size - 1), increasing
  double s_of_u(double u) const;
  double area_fraction_of_u(double u) const;  // in [0, 1], strictly increasing
  // x(u) / L of a band whose slices are (dA/du)^beta wide: beta = 0 the conformal spacing (u),
  // 1 the area fraction; sampled at the area_cdf knots, strictly increasing from 0 to 1.
  std::vector<double> blended_axis(double beta) const;
};
double interpolate_axis(const std::vector<double>& axis, double u);  // axis at u in [0, 1]
// `use_face`: faces taken into the slices and the area function (the conformal map's crowded
// faces, area ratio < 0.05, are left out: they sit at single u values and would make jumps).
Centreline centreline_from_u(const Surface& s, const std::vector<double>& u, const std::vector<char>& use_face,
                             const V3& end_a, const V3& end_b);

// Labels the segments' ends (rectum: inferior, near the midline x; cecum: the patient's right),
// with a margin of 25 mm, else "end A" / "end B"; orients each segment so that x0 is the rectal
// end (`reversed`: swap x, end_a/end_b already swapped) and orders the segments rectum -> cecum.
void label_ends(std::vector<FlatSegment>& segs, double midline_x, std::vector<char>& reversed);

// Local area balancing: symmetric Dirichlet energy minimised on the regions whose area ratio is
// out of [lo, hi], grown until their 2D area is comparable to their 3D area, boundary fixed;
// Laplacian-preconditioned descent with a flip-preventing, Armijo line search.
struct BalanceResult {
  std::size_t vertices = 0, faces = 0, iterations = 0;
  std::size_t systems_built = 0;  // regions' systems factorised (a pass whose region is the last one's reuses it)
};
// `vertex_order` (optional): a fill-reducing order of the band's vertices for the regions' systems.
BalanceResult balance_area(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                           const std::vector<char>& fixed, const std::vector<char>& degenerate,
                           const FlattenOptions& o, const std::vector<int>* vertex_order = nullptr);

// Largest t in [0, 1] such that moving the vertices along pos + t (next - pos) keeps every face of
// `faces` that is positive now above min(half its area, floor_ratio x its 3D area `area3[f]`).
// Per face of `faces`, the weight of the edge opposite each corner: half the corner's cotangent in
// the 3D triangle, clamped to [0.01, 100] (the quadratic proxy of the balancing and the area
// correction: positive, so their systems are M-matrices).
std::vector<std::array<double, 3>> corner_weights(const Surface& s, const std::vector<int>& faces);

// Smallest t in (0, 1] at which face f, moving along pos + t (next - pos), is down to `keep` (in
// [0, 1)) x its current 2D area; a value above 1 when none is; 1e300 for a face not positive now.
double face_step_limit(const Surface& s, const Embedding& emb, const std::vector<V2>& next, int f, double keep);
double max_area_step(const Surface& s, const Embedding& emb, const std::vector<V2>& next, const std::vector<int>& faces,
                     const std::vector<double>& area3, double floor_ratio);

// Wall seconds of the parts of descent steps (proxy_descent.h): gradients (per face and gathered),
// solves, largest fold-free step, line search (energy_evals energies), the caller's stop check.
struct StepTimes {
  double gradient = 0, solve = 0, step_limit = 0, line_search = 0, check = 0;
  int energy_evals = 0;
};
// The area correction's penalty term of a face with area ratio r: log r minus log r clamped to
// [log lo, log hi] (signed; 0 inside). A ratio inside [lo, hi] by the relative margin
// kInsideMargin has its logarithm inside [log lo, log hi] whatever the last bits of the three
// logarithms (each within an ulp, ~1e-16, of the true value; the margin moves log r by 1e-9), so
// its excess is 0 without calling log: bit for bit the full formula, which most faces of a
// correction region skip (docs/flatten.md, session 20). Pre: 0 < lo <= hi.
class LogRatioExcess {
 public:
  static constexpr double kInsideMargin = 1e-9;
  LogRatioExcess(double lo, double hi)
      : log_lo_(std::log(lo)), log_hi_(std::log(hi)), inside_lo_(lo * (1 + kInsideMargin)),
        inside_hi_(hi * (1 - kInsideMargin)) {}
  double operator()(double ratio) const {
    if (ratio > 0 && ratio >= inside_lo_ && ratio <= inside_hi_) return 0.0;
    const double l = std::log(ratio);
    return l - std::clamp(l, log_lo_, log_hi_);
  }

 private:
  double log_lo_, log_hi_, inside_lo_, inside_hi_;
};

// What correct_area() did: steps, faces, energies, why it stopped.
struct AreaCorrection {
  int iterations = 0;
  std::size_t faces = 0;  // faces the correction worked on
  double energy_before = 0, energy_after = 0;
  const char* stop = "";  // why the (last) descent stopped (proxy_descent.h)
};
// Where a correct_area() call's wall time went (COLONFLAT_FLATTEN_DEBUG; filled only when asked
// for): seconds of the system build (assembly, order, factorisation) and of the steps, of the
// whole band or of the local piece that took longest (its faces, steps and place in the order the
// pieces start), and the pieces' wall seconds summed.
struct CorrectionTimes {
  double build_s = 0, longest_s = 0, pieces_s = 0;
  StepTimes steps;
  std::size_t longest_faces = 0, longest_place = 0, pieces = 0;
  int longest_steps = 0;
};
// Area correction (area_correct.cpp): the map as conformal as possible with every face's area
// ratio within [area_ratio_low, area_ratio_high]: minimises the cotangent Dirichlet energy of the
// 2D positions plus area_weight x sum_f A3_f (log ratio outside the bounds)^2, at most
// area_correction_iterations Newton steps on the quadratic part, each cut so that no face folds.
// Fixed vertices (the band's ends, the rims of cut-off branches) stay. Post: bijective if `emb` was.
// `local`: only the faces not shown (ratio below coverage_min_ratio) grown by 12 vertex rings
// move (their rim fixed): for a band whose distortion is within bounds except for pockets; up to
// 10 x area_correction_iterations steps there while faces x steps <= 1e7, each vertex-connected
// piece on its own (`iterations`: the most steps any piece took); with `grow`, a piece that leaves
// over half of its hidden wall hidden and holds faces crushed below ratio 1e-4 has them (with 2
// rings) corrected on their own and runs again (a crushed spot bounds every step of the piece:
// docs/flatten.md, session 21).
// `grow` (local): a piece whose region has no room (2D area < 0.6 x 3D) grows by 12 rings more, up
// to 3 times (the second local pass, for pockets the first one could not open); a grown piece that
// hides at most kHiddenWallTolerance of its wall is left as it is.
// `enough` (whole band only, optional): asked after each step; true ends the pass (its goal met).
// `vertex_order` (whole band only, optional): a fill-reducing order of the band's vertices for its
// system (else AMD's). `times` (optional): where the time went; the map does not depend on it.
AreaCorrection correct_area(const Surface& s, const std::vector<std::vector<int>>& vf, Embedding& emb,
                            const std::vector<char>& fixed, const std::vector<char>& degenerate, bool local,
                            const FlattenOptions& o, bool grow = false, const std::function<bool()>& enough = {},
                            const std::vector<int>* vertex_order = nullptr, CorrectionTimes* times = nullptr);

// The local pass's bound on a piece's work (faces x steps) with `iterations` =
// area_correction_iterations: faces x iterations when that is over 1e7, faces x 60 iterations when
// that is under it, else 1e7 (the step budget 1e7 / faces, not rounded to whole steps).
double piece_work_bound(std::size_t faces, int iterations);
// The order the local pieces (faces of each) start in: the largest work bound first, then more
// faces (a permutation of 0 .. pieces.size() - 1). Pre: iterations >= 1.
std::vector<std::size_t> most_work_first(const std::vector<std::vector<int>>& pieces, int iterations);

struct SegmentWork;
// Area-balanced map of a segment from its conformal embedding (band_axis.cpp): x = B F(u) with
// the least angle-distorting axis F whose area ratios stay in bounds, B the band length (the
// centreline length within 8 %; a branch's conformal length), y scaled to the wall area, folds
// untangled, out-of-bounds regions balanced. `ends`: the band's two end loops (vertex ids of w.ann);
// `E`: w.ann's edges; `fixed`: every boundary vertex (the ends and the rims of cut-off branches). The
// rims move in the local area correction passes only (cut_rims.h: local_area_passes: freed, or a
// short one widened as one curve first), the ends never.
void area_balanced_step(SegmentWork& w, const Centreline& cl, const std::vector<std::vector<int>>& ends, const Edges& E,
                        const std::vector<std::vector<int>>& vf, const std::vector<char>& fixed,
                        const std::vector<char>& degenerate, const FlattenOptions& o, bool branch);
// COLONFLAT_FLATTEN_DEBUG=1: distortion after each step on stderr.
void debug_stats(const char* step, const SegmentWork& w, const std::vector<char>& degenerate);

// Per-face distortion of a map triangle.
struct FaceDistortion {
  double qc, area3, area2;
  bool degenerate = false;
};
FaceDistortion face_distortion(const V3& p0, const V3& p1, const V3& p2, const V2& q0, const V2& q1, const V2& q2);
// The 3D half of face_distortion (a face's area and the inverse of its edge matrix in its own
// plane; valid false for a degenerate triangle), for a caller that measures the same faces after
// every step of a descent: face_distortion(face_frame(p0, p1, p2), q0, q1, q2) is, bit for bit,
// face_distortion(p0, p1, p2, q0, q1, q2).
struct FaceFrame {
  Eigen::Matrix2d s_inv = Eigen::Matrix2d::Zero();
  double area3 = 0;
  bool valid = false;
};
FaceFrame face_frame(const V3& p0, const V3& p1, const V3& p2);
FaceDistortion face_distortion(const FaceFrame& frame, const V2& q0, const V2& q1, const V2& q2);
DistortionStats stats_of(const std::vector<FaceDistortion>& fd);
// The area ratio 5th / 95th percentiles and the quasi-conformal mean of stats_of(the faces of fd in
// the map: not degenerate, not too_small_in_map), the same numbers, without copying the faces or
// computing the other statistics (the area correction's trigger, asked after every whole-band step).
struct BoundStats {
  double area_p05 = 0, area_p95 = 0, qc_mean = 0;
};
// `scratch` (optional): the area ratios' vector, kept by a caller that asks every step (no fresh pages).
BoundStats bound_stats_in_map(const std::vector<FaceDistortion>& fd, std::vector<double>* scratch = nullptr);
// The ks[i]-th smallest values of v (0-based, each < v.size()): what std::nth_element leaves at
// v[k]. At least 65 536 values >= 0 (not NaN) are counted per bucket of their top 16 bits on the worker threads
// (integer counts: the same for any thread count) and nth_element runs only among the values of
// the bucket holding k; other values: nth_element over v. v's order is not kept.
// searched: the values nth_element looked at, summed over ks.
struct OrderStatistics {
  std::vector<double> values;
  std::size_t searched = 0;
};
OrderStatistics order_statistics(std::vector<double>& v, const std::vector<std::size_t>& ks);
double percentile(std::vector<double> v, double p);

// Coverage of the 3D wall by the map (faces shown: in the map, area ratio >= min_ratio).
Coverage coverage_of(const Surface& s, const Edges& E, const std::vector<char>& in_map,
                     const std::vector<double>& ratio, double min_ratio, double removed_cap_area);

// One flattened segment before the layout.
struct SegmentWork {
  FlatSegment seg;
  Surface ann;
  Embedding emb;
  std::vector<char> in_map;   // per face: in the map (positive area)
  std::vector<double> along;  // per vertex: centreline arc length from end A (mm)
  double lumen_sign = 1;      // face normals x sign point out of the lumen
  int parent = -1;            // side branch: index of the parent's work in the segment list
  std::vector<int> neck;      // side branch: its neck's vertices in the parent's annulus
  double cap_area = 0;        // mm^2 of wall removed to open the ends (caps)
  double lost_area = 0;       // mm^2 of wall in no band (faces dropped when a branch was cut off)
  bool branch = false;        // a side branch's band (flattened from its neck)
  bool folds_pending = false; // the map's folds are not untangled yet (a colon map that may be re-solved)
  PriorSolve prior;           // the last conformal solve's order and factor, for the next one
  // The segment's order (closed surface's vertices; invalid: none), for the band's systems when nested
  // dissection's, and each vertex's id on the annulus now (-1: removed with a cap or a side branch).
  std::shared_future<SegmentOrder> dissection;
  std::vector<int> dissection_to_annulus;
  bool has_band_order() const { return dissection.valid() && dissection.get().nested; }
  // The nested dissection order restricted to the annulus now (empty: none).
  void keep_order(std::shared_future<SegmentOrder> order, std::vector<int> to_annulus) {
    dissection = std::move(order);
    dissection_to_annulus = std::move(to_annulus);
  }
  std::vector<int> band_order() const {
    std::vector<int> order;
    if (!has_band_order()) return order;
    for (int v : dissection.get().order)
      if (dissection_to_annulus[std::size_t(v)] >= 0) order.push_back(dissection_to_annulus[std::size_t(v)]);
    return order;
  }
};

// 3D / map area of the band w.ann in w.emb (each face's map area counted when positive; the faces
// marked in `degenerate` left out, every face when it is null): the scale at which an area ratio
// of 1 preserves area. 1 for an empty map.
double band_area_scale(const SegmentWork& w, const std::vector<char>* degenerate);
// Per face of the segment's annulus: the distortion of its current embedding, `degenerate` carried.
// `frames` (optional): face_frame() of every face of the annulus (the same numbers, without the 3D half).
std::vector<FaceDistortion> band_distortion(const SegmentWork& w, const std::vector<char>& degenerate,
                                            const std::vector<FaceFrame>* frames = nullptr);
// The same into `fd` (resized; a caller that measures every step keeps its pages).
void band_distortion(const SegmentWork& w, const std::vector<char>& degenerate, const std::vector<FaceFrame>* frames,
                     std::vector<FaceDistortion>& fd);
// face_frame() of every face of the segment's annulus (on the worker threads).
std::vector<FaceFrame> band_frames(const SegmentWork& w);
// Distortion, faces left out (zero or negative area) and coverage of a segment (distortion.cpp): w.in_map,
// w.seg's stats, crowded and inverted faces and coverage (its caps w.cap_area aside, w.lost_area not shown).
void measure(SegmentWork& w, const Edges& E, const std::vector<char>& degenerate, const FlattenOptions& o);

// Labels and orders the colon segments (rectum -> cecum); side branches follow, by the order of
// their parent and their neck's position on it, labelled "neck" -> "tip" ("rim" for a patch).
// Returns per work whether its band is reversed (flatten_layout.cpp).
std::vector<char> label_and_order(std::vector<SegmentWork>& work, double midline_x);

// Lays the segments out in their order (stacked in y, `segment_gap` apart), reverses those
// flagged (x -> L - x, y -> P - y), and writes vertices (one per vertex and sheet), triangles,
// per-vertex data, overall distortion and coverage into `out`.
void emit_segments(std::vector<SegmentWork>& work, const std::vector<char>& reversed, const FlattenOptions& o,
                   FlatMap& out);

}  // namespace cf::flat_detail
