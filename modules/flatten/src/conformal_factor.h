#pragma once
// The factorisation of a conformal solve (harmonic.cpp), kept so that the map of what remains of
// the surface after its side branches are cut off is solved by a low-rank update of it
// (conformal_update.cpp) instead of a new factorisation (docs/flatten.md, "Speed").
#include <array>
#include <vector>

#include "flatten_internal.h"
#include "spd_solver.h"

namespace cf::flat_detail {

struct ConformalFactor {
  SpdSolver solver;                       // LDL^T of v's system, the loops' vertices ordered last
  std::vector<int> unknown_of;            // per vertex: its unknown in v's system (-1: the pinned vertex)
  std::vector<char> mark;                 // per vertex: 1 on loop A, 2 on loop B, else 0
  int leading = 0;                        // u's unknowns (the vertices off the loops): the order's leading block
  bool clamp = false;                     // clamped weights
  std::vector<std::array<int, 2>> edges;  // the surface's edges (lo, hi), sorted
  std::vector<double> weights;            // their weights
};

// Turns `f` into the factorisation of v's system on the part of its surface that remains
// (`new_of_old`: each of f's vertices' id there, -1 when cut off; `E`, `w`, `mark`: the remaining
// surface's edges, weights and loops), in f's numbering: a rank-one update or downdate
// w (e_a - e_b)(e_a - e_b)^T per edge whose weight changed (the cut-off faces' cotangent terms
// leave), so that the cut-off vertices form blocks of their own, each grounded at one vertex (a
// rank-one update) to stay positive definite. A right-hand side that is 0 on them then gives 0
// there and, on the rest, the remaining surface's solution. False when the loops are not the
// same or CHOLMOD refuses (then f is unusable).
bool restrict_factor(ConformalFactor& f, const Edges& E, const std::vector<double>& w, const std::vector<char>& mark,
                     const std::vector<int>& new_of_old);

// Whether restrict_factor updates a factorisation of `factorisation_flops` (CHOLMOD's count) with
// terms whose modify_flops() estimate is `estimated_update_flops`, rather than leaving it to a new
// factorisation: the update is the cheaper in wall time on two threads, with a margin.
bool update_is_cheaper(double estimated_update_flops, double factorisation_flops);

}  // namespace cf::flat_detail
