#pragma once
// A placed piece whose course runs back along the reference (docs/register.md, Pieces step 3):
// flatten's colon band can pass from one stretch of the colon into another where their walls touch
// and then run the other way along the colon (the painted supine's band: cecum -> 1288 mm of the
// course, then 405 -> 870 mm). One direction per piece would hold the second stretch at the turn;
// the band is cut there into two pieces, each placed by its own projections.
#include <map>
#include <vector>

#include "colonflat/register/pieces.h"

namespace cf {

// Own mm where the projections (own mm `local`, reference s `sref`, in order along the piece) turn:
// the cut whose two sides each run one way along the reference (correlation of own mm and reference
// s beyond 0.9 in size, opposite signs) over at least `min_run_mm` of projections; the clearest such
// cut (largest smaller correlation), NaN when there is none.
double reversal_cut_mm(const std::vector<double>& local, const std::vector<double>& sref, double min_run_mm);

// The two pieces of `p` before and after own mm `cut_mm` (each with its share of the centre line;
// from_mm says where it starts in the band's own mm; the labels stay at their ends).
std::vector<ColonPiece> split_piece(const ColonPiece& p, double cut_mm);

// The piece of band `seg` holding its own mm `c` (the last one starting at or before it, else the
// first): a band cut where it turns is several pieces of one segment.
const ColonPiece* piece_at(const std::multimap<int, const ColonPiece*>& by_segment, int seg, double c);

// Of the bins of a placed piece with an offset (common s - own mm, flipped: + own mm; NaN: none), keeps
// the largest set whose common s runs forward along the piece (longest monotone subsequence); the
// others lose their offset (NaN). Post: the kept offsets' common s is monotone along the piece.
void keep_forward_run(std::vector<double>& offset, bool flipped, double bin_mm);

// A placed piece lying along one side branch b of the reference from its neck to its tip (every projection,
// `ref_piece`, on b; its end nearer the neck within `reach_mm` of b's neck end and its other end within
// `reach_mm` of b's tip, after `shift`) is the same blind stretch of colon: it is laid proportionally from
// b's neck s to its tip s (s_bin, start_mm). Nearest-point projection is biased there: where two centre
// lines bend differently into the tip's cap it held the real mask's 182 mm supine branch on 176 mm of the
// prone's 208, its tip 32 mm short. True when laid.
bool lay_along_branch(ColonPiece& piece, const std::vector<int>& ref_piece, const std::vector<ColonPiece>& ref,
                      const Eigen::Vector3d& shift, double reach_mm);

}  // namespace cf
