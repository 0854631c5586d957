// The fallback's crossing loop search (crossing_search.h): the loop equals the one searching every
// picked source on its own returns, on tori whose crossing loops differ from source to source and
// tie between sources, for one and two lanes, with fewer settled vertices.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "colonflat/core/synthetic.h"
#include "colonflat/denoise/crossing_search.h"

namespace cf {
namespace {

using namespace synthetic;
using VH = Mesh::VertexHandle;

struct Reference {
  std::vector<VH> loop;
  long long settled = 0;
};

// The old search: every picked source on its own in order, to the best value before it, a
// strictly shorter loop replacing the best.
Reference every_source(FundamentalCycleSearch& search, const CrossingLoopInput& in) {
  Reference ref;
  double best = in.limit;
  search.set_cochain(in.cochain);
  const std::size_t stride = std::max<std::size_t>(1, in.loop->size() / in.max_sources);
  for (std::size_t i = 0; i < in.loop->size(); i += stride) {
    const CycleCandidate c = search.run((*in.loop)[i], best);
    ref.settled += static_cast<long long>(search.last_settled());
    if (c.found && c.value < best) {
      best = c.value;
      ref.loop = search.extract(c);
    }
  }
  search.set_cochain(nullptr);
  return ref;
}

// Runs the lanes' jobs on threads of their own (job 0 on the caller), as the search worker does.
void run_on_threads(int n, const std::function<void(int)>& job) {
  std::vector<std::thread> helpers;
  for (int t = 1; t < n; ++t) helpers.emplace_back(job, t);
  job(0);
  for (std::thread& h : helpers) h.join();
}

// A torus, bumpy or not, and the loops whose crossing loops are searched: meridians (their
// crossing loops run round the hole, shortest at the inner equator) and parallels.
struct Case {
  Mesh mesh;
  std::vector<std::vector<VH>> loops;
};

Case torus_case(double bump) {
  const int nu = 48, nv = 24;
  Case c{to_mesh(torus(3, 1, nu, nv)), {}};
  for (auto v : c.mesh.vertices()) c.mesh.point(v) *= 1.0 + bump * std::sin(3.0 * v.idx());
  for (int i : {0, 7}) {
    std::vector<VH> meridian;
    for (int j = 0; j < nv; ++j) meridian.push_back(VH(i * nv + j));
    c.loops.push_back(meridian);
  }
  for (int j : {0, nv / 2, 5}) {
    std::vector<VH> parallel;
    for (int i = 0; i < nu; ++i) parallel.push_back(VH(i * nv + j));
    c.loops.push_back(parallel);
  }
  return c;
}

// Certified search = every source on its own (same loop, vertex for vertex) on a plain torus
// (symmetric sources tie: the first must win) and a bumpy one, for 1 and 2 lanes, with several
// source counts and with a limit below the shortest (no loop); and it settles fewer vertices.
TEST(DenoiseCrossingSearch, SameLoopAsEverySourceOnItsOwnForOneAndTwoLanes) {
  long long mine_settled = 0, ref_settled = 0;
  for (double bump : {0.0, 0.03}) {
    const Case c = torus_case(bump);
    HomologyBasis hb;
    hb.build(c.mesh);
    Z2Span span(hb.words());
    FundamentalCycleSearch s0(c.mesh, hb, span), s1(c.mesh, hb, span), ref_search(c.mesh, hb, span);
    for (const std::vector<VH>& loop : c.loops) {
      const std::vector<std::uint8_t> cochain = crossing_cochain(c.mesh, loop);
      for (std::size_t sources : {std::size_t(4), std::size_t(24), loop.size()}) {
        for (double limit : {100.0, 1.0}) {
          CrossingLoopInput in;
          in.mesh = &c.mesh;
          in.loop = &loop;
          in.cochain = &cochain;
          in.limit = limit;
          in.max_sources = sources;
          in.lane_search = [&](int t) -> FundamentalCycleSearch& { return t == 0 ? s0 : s1; };
          const Reference ref = every_source(ref_search, in);
          CrossingSearchCount one, two;
          const std::vector<VH> alone = shortest_crossing_loop(in, &one);
          in.lanes = 2;
          in.run_lanes = run_on_threads;
          const std::vector<VH> paired = shortest_crossing_loop(in, &two);
          EXPECT_EQ(alone, ref.loop) << "bump " << bump << " sources " << sources << " limit " << limit;
          EXPECT_EQ(paired, ref.loop) << "bump " << bump << " sources " << sources << " limit " << limit;
          EXPECT_EQ(one.settled, two.settled);
          EXPECT_EQ(limit < 2.0, ref.loop.empty());
          if (limit > 2.0) mine_settled += one.settled, ref_settled += ref.settled;
        }
      }
    }
  }
  EXPECT_LT(mine_settled, ref_settled);
}

}  // namespace
}  // namespace cf
