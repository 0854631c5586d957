// Nested dissection order of a symmetric system by METIS_NodeND called directly (libmetis 5.1),
// with fewer refinement passes than METIS's default (docs/flatten.md, "METIS called directly").
#pragma once

#include <Eigen/SparseCore>

#include <mutex>
#include <vector>

namespace cf::flat_detail {

// FM refinement passes per uncoarsening level of each bisection (METIS_OPTION_NITER; METIS's
// default 10). 1 pass: 16-30 % less METIS CPU on a CT colon band for +2.7 % factorisation flops
// (docs/flatten.md, session 20).
constexpr int kMetisRefinementPasses = 1;
// Passing this as `refinement_passes` leaves METIS's own default (what cholmod_metis uses).
constexpr int kMetisDefaultPasses = -1;

// libmetis 5.1 draws its random numbers from the C library's rand(): one state for the process,
// re-seeded at each call. Every METIS call (direct or through CHOLMOD) holds this mutex, so that
// each order is the order it is alone whatever runs beside it.
std::mutex& metis_mutex();

// Whether this build calls METIS directly (libmetis-dev and CHOLMOD found by CMake).
bool metis_direct_available();

// METIS_NodeND's order of A (n x n, symmetric, lower triangle stored, int indices; the diagonal is
// ignored), followed by the postorder of its elimination tree (as cholmod_metis postorders).
// Returns place -> unknown (a permutation of 0..n-1); empty when METIS or CHOLMOD is missing or
// fails. refinement_passes >= 1, or kMetisDefaultPasses. Deterministic (fixed seed, under
// metis_mutex) and independent of the number of threads.
std::vector<int> metis_dissection_order(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& A,
                                        int refinement_passes);

}  // namespace cf::flat_detail
