#pragma once
// The colon of a scan as pieces (docs/register.md, "Pieces"): each colon band of the flat map
// (segment_id, its own centreline_mm from its x0 end, FlatSegments order) is a piece; a collapse
// splits the colon into several, a stretch left out of the segmentation (fully tagged fluid, the
// rectum cut short by the catheter) is missing from one scan. The two scans' pieces are put on one
// axis along the colon ("common s"):
//   1. the scan with fewer pieces is the reference: its pieces in the flat map's order, each gap
//      as long as the straight line between the ends it joins (a lower bound of the missing colon);
//   2. the rigid shift between the two scans (patient on the table) by trimmed nearest-point fits
//      of the pieces' centre lines (LPS is patient-fixed: only the table position differs);
//   3. every piece of the other scan is placed by projecting its centre line onto the reference's
//      (the nearest reference point within `place_radius_mm` gives its common s): its start and
//      direction come from these projections, so a missing, split or merged piece needs no rule
//      of its own; a piece with no counterpart (small bowel, a stretch present in one scan only)
//      is left unregistered. The reference's side-branch bands are projection targets too, at their
//      neck's s: a stretch one scan's flatten cut off as a side branch and the other's kept in a
//      colon band (another cut end changes what is a pouch) is then placed at that neck, not
//      counted as colon length. Each placed piece maps its own mm to the common s through its
//      projections (running median, monotone), so its own centreline's length errors do not push
//      the pieces after it.
// A side-branch band of colon length (longer than `min_branch_piece_mm`) is a piece too: flatten
// cuts a colon stretch off as a side branch where the lumen touches itself or forks (the real mask's
// 204 mm stretch behind a 12 mm neck, the painted supine's 407, 481 and 207 mm stretches). In the
// reference it is inserted into the colon's course at its neck (the colon runs out along the branch
// from the neck, then on along its band: the band's s after the neck moves by the branch's length);
// in the other scan it is placed by its projections like any piece. Shorter branches (pouches,
// diverticula, a polyp on a stalk) stay at their neck, and so does a band that holds tissue
// (FlatSegments "holds": a strand stump cut off because its map was crushed), whatever its length.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "colonflat/register/scan.h"

namespace cf {

struct PieceOptions {
  double bin_mm = 2.0;            // mm; sampling of each piece's centre line
  double place_radius_mm = 50;    // mm; a centre point with a reference point this close projects onto it
  double min_placed_fraction = 0.3;  // a piece with fewer projecting centre points has no counterpart
  double follow_mm = 40;          // mm; half window of the running median of a placed piece's projections:
                                  // it must outvote a neighbouring loop lying alongside over a colon's
                                  // diameter or more (10 mm lost a phantom polyp: 4/5 on seed 1, 25 % dropped)
  double min_branch_piece_mm = 60;  // mm; a side branch this long is a piece of the colon's course: longer
                                    // than a haustral pouch or a diverticulum (< 3 cm deep) or a polyp on
                                    // a stalk, twice the colon's diameter
  double same_neck_mm = 50;       // mm; long side branches whose necks lie this close along their band hang
                                  // at one neck (one opening where the walls touch: at most the colon's
                                  // diameter wide) and are ordered as one tour (branch_order.h)
  double jump_mm = 30;            // mm; the two halves of a placed piece's follow window differing by more
                                  // is a jump of its map (a stretch one scan holds as an inserted branch
                                  // or skips): more than the wall slides along between the positions
                                  // (1-2 cm) and than the colon's diameter
};

struct ColonPiece {
  int segment = 0;                // segment_id of the band
  double length_mm = 0;           // centre-line length (largest centreline_mm of its vertices)
  double start_mm = 0;            // common s of its x0 end (flipped: of its x1 end)
  bool flipped = false;           // its centreline_mm runs against the common s
  bool registered = true;         // false: no counterpart in the other scan
  double placed_fraction = 1;     // share of its centre points that projected onto the reference
  std::string x0_end, x1_end;     // FlatSegments labels ("" when absent)
  bool branch = false;            // a side-branch band of colon length (PieceOptions::min_branch_piece_mm)
  int parent = -1;                // branch: the colon band it hangs on (a branch of a branch: its ancestor's)
  double attach_mm = 0;           // branch: the neck's centreline mm on `parent`
  int neck_rank = 0;              // branch: its place among the long branches inserted at one neck
  bool on_band = true;            // branch: FlatSegments parent is its band (not another branch)
  double from_mm = 0;             // own mm of its band where it starts (a band cut where it turns back, piece_split.h)
  // Reference band: its long branches inserted at their necks (own mm of the neck, branch length);
  // the band's s after a neck moves on by the branch's length.
  std::vector<std::pair<double, double>> inserts;
  std::vector<Eigen::Vector3d> centre;  // LPS mm, centroid per bin of its own centreline_mm
  // Common s per centre bin where the piece was placed by its projections (empty: the reference,
  // s = start_mm + own mm). A stretch of it that the reference holds as a side branch sits at the
  // branch's neck, as the reference's own branch vertices do (its own mm then over-measures the
  // colon: see layout_pieces).
  std::vector<double> s_bin;
  std::vector<char> on_branch;    // per centre bin: it projected onto a side branch of the reference
  double bin_mm = 2;
  double s_of(double local_mm) const;
  double first_mm() const { return std::min(s_of(0), s_of(length_mm)); }  // common s range it covers
  double end_mm() const { return std::max(s_of(0), s_of(length_mm)); }
  double span_mm() const;   // common s it spans in the reference: its length plus its inserts
  void move_by(double mm);  // moves the piece along the common s
};

struct PieceLayout {
  std::vector<ColonPiece> supine, prone;  // in order along the common s
  bool supine_is_reference = true;
  Eigen::Vector3d prone_to_supine{0, 0, 0};  // LPS mm: prone point + this ~ the supine point
  double fit_residual_mm = 0;                // trimmed mean distance after the shift
};

// True when the scan can be laid out as pieces (per-vertex centreline_mm present).
bool has_pieces(const ColonScan& scan);

// The colon bands of a scan in the flat map's order (FlatSegments "order", else segment id), then
// its side-branch bands of colon length (branch = true, flipped when their own mm runs towards the
// neck); shorter side branches excluded. Precondition: has_pieces(scan).
std::vector<ColonPiece> colon_pieces(const ColonScan& scan, const PieceOptions& opts);

// Both scans' pieces on the common axis (steps 1-3 above).
PieceLayout layout_pieces(const ColonScan& supine, const ColonScan& prone, const PieceOptions& opts);

// Common s per vertex of a scan laid out as `pieces` (NaN: unregistered piece or no centreline);
// the vertices of a side branch that is no piece sit at their neck on the nearest ancestor that is
// one (FlatSegments parent, attach_mm).
std::vector<double> common_s(const ColonScan& scan, const std::vector<ColonPiece>& pieces);

// Per vertex: 1 when it lies on a stretch of a placed piece that the layout holds at one common s
// (its centre point projected onto a side branch of the reference, or the local slope of s over own
// mm is below 1/2: the other scan keeps that stretch as a side branch, so along the colon nothing is
// aligned there), else 0.
std::vector<char> held_at_neck(const ColonScan& scan, const std::vector<ColonPiece>& pieces);

// Rigid shift t with b + t ~ a by trimmed nearest-point iterations (the better of starting at 0 and
// at the centroid difference). `residual` receives the trimmed mean distance.
Eigen::Vector3d fit_shift(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                          double* residual = nullptr);

}  // namespace cf
