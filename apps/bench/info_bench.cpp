// `colonflat info` on a >= 1.5M-face mesh: reading (binary PLY, VTP, OFF), diagnosis and the
// topology report, as Google Benchmark cases (target: <= 3 s on 2 cores in Release).
// Run: ./build/apps/bench/info_bench --benchmark_time_unit=ms
#include <benchmark/benchmark.h>

#include <filesystem>
#include <sstream>

#include "bench_meshes.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/topology.h"
#include "colonflat/pipeline/dispatch.h"

namespace fs = std::filesystem;

namespace {

const fs::path& big_mesh_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / "colonflat_info_bench";
    fs::create_directories(d);
    if (!fs::exists(d / "big.ply")) {
      cf::Mesh m = cf::bench::sphere_with_handles(100.0, 300, 0.42);
      cf::WriteOptions bin;
      cf::write_mesh(m, d / "big.ply", bin);
      cf::write_mesh(m, d / "big.vtp", bin);
      cf::write_mesh(m, d / "big.off", bin);
    }
    return d;
  }();
  return dir;
}

// The whole command, in-process: read, diagnose, topology, print.
void BM_InfoCommand(benchmark::State& state, const char* file) {
  const std::string path = (big_mesh_dir() / file).string();
  for (auto _ : state) {
    std::ostringstream out, err;
    const int rc = cf::colonflat_main({"info", path}, out, err);
    if (rc != 0) state.SkipWithError(err.str().c_str());
  }
  state.counters["faces"] = static_cast<double>(cf::read_polygon_soup(path).num_faces());
}
BENCHMARK_CAPTURE(BM_InfoCommand, ply_binary, "big.ply")->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_InfoCommand, vtp, "big.vtp")->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_InfoCommand, off_ascii, "big.off")->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

// Topology report alone (in memory).
void BM_TopologyOnly(benchmark::State& state) {
  const cf::PolygonSoup soup = cf::read_polygon_soup(big_mesh_dir() / "big.ply");
  const cf::TriangleList t = cf::soup_to_triangles(soup, cf::LoadPolicy{}, cf::diagnose_soup(soup));
  for (auto _ : state) benchmark::DoNotOptimize(cf::analyze_topology(t));
  state.counters["faces"] = static_cast<double>(t.triangles.size());
}
BENCHMARK(BM_TopologyOnly)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
