// The band graph cut (docs/segment.md step 8): partial-volume data terms, contrast-sensitive
// smoothness, Boost.Graph's boykov_kolmogorov_max_flow on a compressed-sparse-row graph, in slabs of
// 32 slices with 6 slices of overlap, one slab per worker at a time (cf::thread_count() workers,
// slabs taken in order; each slab's result is the same whoever solves it). Each worker keeps one
// SlabCut whose arrays (node map, edges, capacities, flow state) are reused from slab to slab, and
// the energy terms are plain inline functions (no per-edge callbacks).
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <numeric>

#include "segment_internal.h"

namespace cf::segment_detail {
namespace {

using Csr = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                               boost::no_property, std::uint32_t, std::uint32_t>;
using CsrEdge = boost::graph_traits<Csr>::edge_descriptor;
constexpr double kScale = 1000.0;  // capacities are integers: costs x 1000

// The energy: data terms from the partial-volume lumen fraction (the cut passes where it is one
// half) and the contrast-sensitive pair weight, tabulated per 1/4 HU up to 8 sigma (0 beyond).
class Energy {
 public:
  explicit Energy(const GraphCutInput& in) : in_(in), hu_(*in.hu), near_fluid_(in.near_fluid->data()) {
    const Dims& d = *in.d;
    const double hmin = std::min({d.sp[0], d.sp[1], d.sp[2]});
    for (int a = 0; a < 3; ++a) wax_[a] = kScale * in.smoothness * hmin / d.sp[a];
    const double inv2s2 = 1.0 / (2.0 * in.edge_sigma * in.edge_sigma);
    gauss_.resize(std::size_t(8 * in.edge_sigma / kStep) + 2);
    for (std::size_t t = 0; t < gauss_.size(); ++t) gauss_[t] = std::exp(-(t * kStep) * (t * kStep) * inv2s2);
    gauss_.back() = 0;
  }
  // src: paid when q becomes wall; snk: paid when q becomes lumen.
  void data(std::size_t q, long& src, long& snk) const {
    const double v = hu_[q], tis = in_.tissue;
    double a = 0;
    if (v < tis) a = std::clamp((tis - v) / (tis - in_.air), 0.0, 1.0);
    else if (near_fluid_[q]) a = std::clamp((v - tis) / (in_.fluid - tis), 0.0, 1.0);
    src = std::lround(kScale * a);
    snk = std::lround(kScale * (1.0 - a));
  }
  long pair(std::size_t p, std::size_t q, int axis) const {
    const std::size_t t = std::min(gauss_.size() - 1, std::size_t(std::abs(double(hu_[p]) - double(hu_[q])) / kStep + 0.5));
    return std::lround(wax_[axis] * gauss_[t]);
  }

 private:
  static constexpr double kStep = 0.25;
  const GraphCutInput& in_;
  const HuCrop& hu_;
  const unsigned char* near_fluid_;
  double wax_[3] = {0, 0, 0};
  std::vector<double> gauss_;
};

// The largest slab: its band voxels (free state 2) and its voxels.
struct SlabSize {
  std::size_t band = 0, voxels = 0;
};

// Min cut of the band voxels of slices [k0, k1); results written for the core slices [c0, c1).
// One SlabCut per worker: solve() may be called for many slabs. Its arrays are reserved once for
// the largest slab (grown from slab to slab they were re-allocated and their fresh pages faulted in
// again: about 1 GB in 32 steps on the real CT).
class SlabCut {
 public:
  SlabCut(const Dims& d, const unsigned char* state, const Energy& energy, const SlabSize& largest)
      : d_(d), state_(state), energy_(energy) {
    const std::size_t n = largest.band, m = 10 * largest.band;  // at most 10 edges per band voxel (add_edges)
    vox_.reserve(n), src_.reserve(n), first_.reserve(n + 3);
    color_.reserve(n + 2), pred_.reserve(n + 2), dist_.reserve(n + 2);
    edges_.reserve(m), cap_.reserve(m), res_.reserve(m), rev_.reserve(m);
    node_.reserve(largest.voxels);
  }
  GraphCutOutput solve(std::size_t k0, std::size_t k1, std::size_t c0, std::size_t c1, Bytes& result) {
    GraphCutOutput out;
    k0_ = k0, k1_ = k1;
    collect_voxels();
    if (vox_.empty()) return out;
    Stopwatch sw;
    add_edges();
    reverse_edges();
    out.build_cpu_s = sw.seconds();
    sw.restart();
    max_flow(out);
    out.flow_cpu_s = sw.seconds();
    const std::size_t slice = d_.n[0] * d_.n[1];
    const auto black = boost::color_traits<boost::default_color_type>::black();
    for (std::uint32_t i = 0; i < n_; ++i) {
      const std::size_t k = vox_[i] / slice;
      if (k >= c0 && k < c1) result[vox_[i]] = color_[i] == black ? 1 : 0;
      node_[vox_[i] - base_] = UINT32_MAX;  // the node map is clean for the next slab
    }
    return out;
  }

 private:
  void collect_voxels() {
    const std::size_t slice = d_.n[0] * d_.n[1];
    vox_.clear();
    for (std::size_t q = k0_ * slice; q < k1_ * slice; ++q)
      if (state_[q] == 2) vox_.push_back(q);
    n_ = std::uint32_t(vox_.size());
    base_ = k0_ * slice;
    if (node_.size() < k1_ * slice - base_) node_.resize(k1_ * slice - base_, UINT32_MAX);  // dense map: faster than searching vox_
    for (std::uint32_t i = 0; i < n_; ++i) node_[vox_[i] - base_] = i;
  }
  // Out-edges per node, sorted by target: band neighbours (ascending), then S, then T.
  void add_edges() {
    const std::uint32_t S = n_, T = n_ + 1;
    edges_.clear();
    cap_.clear();
    edges_.reserve(std::size_t(n_) * 10);
    cap_.reserve(edges_.capacity());
    src_.resize(n_);
    first_.assign(n_ + 3, 0);
    for (std::uint32_t i = 0; i < n_; ++i) {
      first_[i] = std::uint32_t(edges_.size());
      long s_cap = 0, t_cap = 0;
      neighbour_edges(i, s_cap, t_cap);
      const long m = std::min(s_cap, t_cap);
      src_[i] = s_cap - m;
      edges_.emplace_back(i, S);
      cap_.push_back(0);
      edges_.emplace_back(i, T);
      cap_.push_back(t_cap - m);
    }
    first_[S] = std::uint32_t(edges_.size());
    for (std::uint32_t i = 0; i < n_; ++i) {
      edges_.emplace_back(S, i);
      cap_.push_back(src_[i]);
    }
    first_[T] = std::uint32_t(edges_.size());
    for (std::uint32_t i = 0; i < n_; ++i) {
      edges_.emplace_back(T, i);
      cap_.push_back(0);
    }
    first_[T + 1] = std::uint32_t(edges_.size());
  }
  // Edges to band neighbours in ascending voxel order (-z, -y, -x, +x, +y, +z); fixed neighbours
  // add to the terminal capacities.
  void neighbour_edges(std::uint32_t i, long& s_cap, long& t_cap) {
    const std::size_t q = vox_[i];
    energy_.data(q, s_cap, t_cap);
    std::size_t c[3];
    d_.coords(q, c[0], c[1], c[2]);
    static const int order[6][2] = {{2, -1}, {1, -1}, {0, -1}, {0, 1}, {1, 1}, {2, 1}};
    for (const auto& od : order) {
      const int ax = od[0], dir = od[1];
      if ((dir < 0 && c[ax] == 0) || (dir > 0 && c[ax] + 1 == d_.n[ax])) continue;
      if (ax == 2 && (std::int64_t(c[2]) + dir < std::int64_t(k0_) || std::int64_t(c[2]) + dir >= std::int64_t(k1_))) continue;
      const std::size_t r = dir < 0 ? q - d_.stride[ax] : q + d_.stride[ax];
      const long w = energy_.pair(q, r, ax);
      if (state_[r] == 1) s_cap += w;
      else if (state_[r] == 0) t_cap += w;
      else if (node_[r - base_] != UINT32_MAX) {
        edges_.emplace_back(i, node_[r - base_]);
        cap_.push_back(w);
      }
    }
  }
  void reverse_edges() {
    const std::uint32_t S = n_, T = n_ + 1;
    rev_.resize(edges_.size());
    for (std::uint32_t e = 0; e < edges_.size(); ++e) {
      const auto [u, v] = edges_[e];
      std::uint32_t r;
      if (u == S) r = first_[v + 1] - 2;       // v -> S
      else if (u == T) r = first_[v + 1] - 1;  // v -> T
      else if (v == S) r = first_[S] + u;
      else if (v == T) r = first_[T] + u;
      else {
        auto b = edges_.begin() + first_[v], en = edges_.begin() + first_[v + 1] - 2;
        r = std::uint32_t(std::lower_bound(b, en, std::make_pair(v, u)) - edges_.begin());
      }
      rev_[e] = CsrEdge(v, r);
    }
  }
  void max_flow(GraphCutOutput& out) {
    Csr g(boost::edges_are_sorted, edges_.begin(), edges_.end(), n_ + 2);
    res_.assign(cap_.size(), 0);
    color_.assign(n_ + 2, boost::default_color_type());
    pred_.assign(n_ + 2, CsrEdge());
    dist_.assign(n_ + 2, 0);
    auto eim = boost::get(boost::edge_index, g);
    auto vim = boost::get(boost::vertex_index, g);
    out.flow = double(boost::boykov_kolmogorov_max_flow(
        g, boost::make_iterator_property_map(cap_.begin(), eim), boost::make_iterator_property_map(res_.begin(), eim),
        boost::make_iterator_property_map(rev_.begin(), eim), boost::make_iterator_property_map(pred_.begin(), vim),
        boost::make_iterator_property_map(color_.begin(), vim), boost::make_iterator_property_map(dist_.begin(), vim),
        vim, n_, n_ + 1));
    out.edges = cap_.size();
  }

  const Dims& d_;
  const unsigned char* state_;
  const Energy& energy_;
  std::size_t k0_ = 0, k1_ = 0, base_ = 0;
  std::uint32_t n_ = 0;
  Buffer<std::size_t> vox_;
  Buffer<std::uint32_t> node_, first_;
  Buffer<std::pair<std::uint32_t, std::uint32_t>> edges_;
  Buffer<long> cap_, res_, src_, dist_;
  Buffer<CsrEdge> rev_, pred_;
  Buffer<boost::default_color_type> color_;
};

constexpr std::size_t kCore = 32, kMargin = 6;  // slab: 32 slices solved, 6 more on each side

// Slab s: slices [k0, k1) cut, results kept for [c0, c1).
void slab_range(std::size_t s, std::size_t nz, std::size_t& k0, std::size_t& k1, std::size_t& c0, std::size_t& c1) {
  c0 = s * kCore, c1 = std::min(nz, c0 + kCore);
  k0 = c0 > kMargin ? c0 - kMargin : 0, k1 = std::min(nz, c1 + kMargin);
}

SlabSize largest_slab(const Dims& d, const Bytes& state, std::size_t nslabs) {
  const std::size_t slice = d.n[0] * d.n[1];
  std::vector<std::size_t> band(d.n[2], 0);  // per slice
  cf::parallel_for(d.n[2], [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k)
      band[k] = std::size_t(std::count(state.begin() + std::ptrdiff_t(k * slice), state.begin() + std::ptrdiff_t((k + 1) * slice), 2));
  });
  SlabSize out;
  for (std::size_t s = 0, k0, k1, c0, c1; s < nslabs; ++s) {
    slab_range(s, d.n[2], k0, k1, c0, c1);
    out.band = std::max(out.band, std::accumulate(band.begin() + std::ptrdiff_t(k0), band.begin() + std::ptrdiff_t(k1), std::size_t(0)));
    out.voxels = std::max(out.voxels, (k1 - k0) * slice);
  }
  return out;
}

}  // namespace

GraphCutOutput graph_cut_band(const GraphCutInput& in, Bytes& state) {
  const Dims& d = *in.d;
  const Energy energy(in);
  const std::size_t nz = d.n[2];
  const std::size_t nslabs = (nz + kCore - 1) / kCore;
  const SlabSize largest = largest_slab(d, state, nslabs);
  std::atomic<std::size_t> next{0};
  std::mutex mu;
  Bytes result(d.total, 0);
  std::exception_ptr failure;
  std::vector<GraphCutOutput> slab(nslabs);  // summed in slab order: the same totals for any thread count
  const auto workers = std::size_t(std::max(1, std::min(cf::thread_count(), int(nslabs))));
  cf::parallel_for(workers, [&](std::size_t, std::size_t) {
    try {
      SlabCut cut(d, state.data(), energy, largest);
      for (std::size_t s, k0, k1, c0, c1; (s = next.fetch_add(1)) < nslabs;) {
        slab_range(s, nz, k0, k1, c0, c1);
        slab[s] = cut.solve(k0, k1, c0, c1, result);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mu);
      failure = std::current_exception();
    }
  });
  if (failure) std::rethrow_exception(failure);
  GraphCutOutput total;
  for (const GraphCutOutput& so : slab) {
    total.flow += so.flow / kScale;
    total.edges += so.edges;
    total.build_cpu_s += so.build_cpu_s;
    total.flow_cpu_s += so.flow_cpu_s;
  }
  for (std::size_t q = 0; q < d.total; ++q)
    if (state[q] == 2) state[q] = result[q];
  return total;
}

}  // namespace cf::segment_detail
