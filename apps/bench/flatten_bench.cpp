// Flattening benchmark and acceptance table (Release):
//   flatten_bench            timing of cf::flatten_colon on a >= 1M-face synthetic colon (3 runs),
//                            distortion and flipped triangles, then the Google Benchmark cases.
//   flatten_bench --table-only   the table without Google Benchmark.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "colonflat/core/run_stats.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"

namespace {

cf::synthetic::ColonOptions million_face_colon() {
  cf::synthetic::ColonOptions o;
  o.length = 1500;
  o.radius = 25;
  o.spacing = 1.5;
  o.around = 512;
  for (int i = 0; i < 10; ++i) o.polyps.push_back({100.0 + 130 * i, 0.7 * i, 5.0 + i});
  return o;
}

void print_row(const char* name, std::size_t faces, double secs, const cf::FlatMap& f) {
  const auto& s = f.stats;
  std::printf("%-28s %9zu %7.2f %7zu %8.4f %8.4f %8.3f %7.3f %7.3f %7.3f\n", name, faces, secs, s.flipped,
              s.qc_mean, s.qc_p95, s.qc_max, s.area_p05, s.area_median, s.area_p95);
}

void table() {
  std::printf("%-28s %9s %7s %7s %8s %8s %8s %7s %7s %7s\n", "surface", "faces", "time_s", "flipped", "qc_mean",
              "qc_p95", "qc_max", "area05", "area50", "area95");
  const auto colon = cf::synthetic::colon(million_face_colon());
  for (int run = 0; run < 3; ++run) {
    cf::Stopwatch sw;
    const cf::FlatMap f = cf::flatten_colon(colon.mesh);
    const double t = sw.seconds();
    print_row("synthetic colon 1.5 m", colon.mesh.triangles.size(), t, f);
  }
  std::printf("peak memory %.0f MiB\n", cf::peak_memory_mib());
}

void BM_FlattenColon(benchmark::State& state) {
  cf::synthetic::ColonOptions o;
  o.length = 600;
  o.spacing = 1.0 * 256.0 / double(state.range(0));
  o.around = int(state.range(0));
  const auto colon = cf::synthetic::colon(o);
  for (auto _ : state) benchmark::DoNotOptimize(cf::flatten_colon(colon.mesh));
  state.counters["faces"] = double(colon.mesh.triangles.size());
}
BENCHMARK(BM_FlattenColon)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  bool table_only = false;
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--table-only")) table_only = true;
  table();
  if (table_only) return 0;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
