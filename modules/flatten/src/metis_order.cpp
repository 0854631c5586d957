// METIS_NodeND called directly on the graph of a symmetric system, then CHOLMOD's etree postorder
// (see metis_order.h).
#include "metis_order.h"

#if defined(COLONFLAT_HAVE_METIS) && defined(COLONFLAT_HAVE_CHOLMOD)
#include <cholmod.h>
#include <metis.h>
#endif

namespace cf::flat_detail {

std::mutex& metis_mutex() {
  static std::mutex m;
  return m;
}

#if defined(COLONFLAT_HAVE_METIS) && defined(COLONFLAT_HAVE_CHOLMOD)

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// The adjacency graph of A (both triangles, no diagonal) in METIS's CSR form; each list ascending,
// as cholmod_copy builds it for cholmod_metis.
struct Graph {
  std::vector<idx_t> xadj, adjncy;
};

Graph graph_of(const SpMat& A) {
  const Eigen::Index n = A.cols();
  Graph g;
  g.xadj.assign(std::size_t(n) + 1, 0);
  for (Eigen::Index j = 0; j < n; ++j)
    for (SpMat::InnerIterator it(A, j); it; ++it)
      if (it.row() > j) ++g.xadj[std::size_t(j) + 1], ++g.xadj[std::size_t(it.row()) + 1];
  for (Eigen::Index j = 0; j < n; ++j) g.xadj[std::size_t(j) + 1] += g.xadj[std::size_t(j)];
  g.adjncy.resize(std::size_t(g.xadj[std::size_t(n)]));
  std::vector<idx_t> next(g.xadj.begin(), g.xadj.end() - 1);
  for (Eigen::Index j = 0; j < n; ++j)
    for (SpMat::InnerIterator it(A, j); it; ++it)
      if (it.row() > j) {
        g.adjncy[std::size_t(next[std::size_t(j)]++)] = idx_t(it.row());
        g.adjncy[std::size_t(next[std::size_t(it.row())]++)] = idx_t(j);
      }
  return g;
}

// METIS_NodeND's permutation (place -> unknown); empty when it fails or the graph has no edge.
std::vector<int> node_nd(Graph& g, int refinement_passes) {
  idx_t n = idx_t(g.xadj.size()) - 1;
  if (g.adjncy.empty()) return {};
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  if (refinement_passes != kMetisDefaultPasses) options[METIS_OPTION_NITER] = refinement_passes;
  std::vector<idx_t> perm(static_cast<std::size_t>(n)), iperm(static_cast<std::size_t>(n));
  const std::lock_guard<std::mutex> one_metis_at_a_time(metis_mutex());
  if (METIS_NodeND(&n, g.xadj.data(), g.adjncy.data(), nullptr, options, perm.data(), iperm.data()) != METIS_OK)
    return {};
  return std::vector<int>(perm.begin(), perm.end());
}

// order followed by the postorder of the elimination tree of A permuted by it, as cholmod_metis
// does with `postorder` true: the same fill, each subtree's columns contiguous.
bool postorder(const SpMat& A, std::vector<int>& order) {
  const std::size_t n = order.size();
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  cholmod_sparse view{};
  view.nrow = view.ncol = n;
  view.nzmax = std::size_t(A.nonZeros());
  view.p = const_cast<int*>(A.outerIndexPtr());
  view.i = const_cast<int*>(A.innerIndexPtr());
  view.x = const_cast<double*>(A.valuePtr());
  view.stype = -1;  // lower triangle
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  std::vector<int> parent(n), post(n);
  const bool ok = cholmod_analyze_ordering(&view, CHOLMOD_GIVEN, order.data(), nullptr, 0, parent.data(), post.data(),
                                           nullptr, nullptr, nullptr, &common) &&
                  common.status == CHOLMOD_OK;
  cholmod_finish(&common);
  if (!ok) return false;
  std::vector<int> combined(n);
  for (std::size_t k = 0; k < n; ++k) combined[k] = order[std::size_t(post[k])];
  order.swap(combined);
  return true;
}

}  // namespace

bool metis_direct_available() { return true; }

std::vector<int> metis_dissection_order(const SpMat& A, int refinement_passes) {
  if (A.rows() != A.cols() || A.rows() == 0 || !A.isCompressed()) return {};
  Graph g = graph_of(A);
  std::vector<int> order = node_nd(g, refinement_passes);
  if (order.empty() || !postorder(A, order)) return {};
  return order;
}

#else  // no libmetis-dev (or no CHOLMOD): SpdSolver orders through CHOLMOD's METIS wrapper or AMD

bool metis_direct_available() { return false; }

std::vector<int> metis_dissection_order(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>&, int) { return {}; }

#endif

}  // namespace cf::flat_detail
