// Reconstruction benchmark and acceptance table (Release):
//   reconstruct_bench               table on the small and full-size phantoms (seed 1): time per
//                                   step, faces, peak memory of the reconstruction alone, distance
//                                   to the ground-truth lumen boundary; then the Google Benchmark cases.
//   reconstruct_bench --table-only  the table without Google Benchmark.
// Peak memory: the process's peak resident set is reset (/proc/self/clear_refs) after generating
// the phantom, so "peak" is the high-water mark while reconstructing, the mask included.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>

#include "colonflat/core/run_stats.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/reconstruct/reconstruct.h"

namespace {

const cf::Phantom& phantom(const std::string& size) {
  static std::map<std::string, cf::Phantom> cache;
  auto it = cache.find(size);
  if (it == cache.end()) {
    cf::PhantomOptions o;
    o.size = size;
    o.seed = 1;
    cf::Phantom p = cf::generate_phantom(o);
    p.ct = nullptr;  // only the ground-truth lumen mask is needed
    it = cache.emplace(size, std::move(p)).first;
  }
  return it->second;
}

bool reset_peak_memory() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  return bool(f);
}

void row(const char* name, const cf::MaskImage* mask, const cf::ReconstructOptions& o) {
  const bool reset = reset_peak_memory();
  const double base = cf::current_memory_mib();
  cf::ReconstructStats st;
  cf::Stopwatch sw;
  const cf::Mesh m = cf::reconstruct_surface(mask, o, &st);
  const double t = sw.seconds();
  const double peak = cf::peak_memory_mib();
  const cf::BoundaryDistance d = cf::distance_to_mask_boundary(m, mask);
  std::printf("%-34s %8.2f %7.2f %7.2f %7.2f %7.2f %9zu %9zu %5zu %5d %8.0f%s %8.0f %7.3f %7.3f\n", name, t,
              st.time_extract_s, st.time_check_s, st.time_smooth_s, st.time_decimate_s, st.extracted_faces, st.faces,
              st.kept.size(), st.genus, peak, reset ? "" : "*", peak - base, d.max_mm, d.mean_mm);
}

void table() {
  std::printf("%-34s %8s %7s %7s %7s %7s %9s %9s %5s %5s %9s %8s %7s %7s\n", "case", "time_s", "extract", "check",
              "smooth", "decim", "mc_faces", "faces", "comps", "genus", "peak_MiB", "+MiB", "dmax_mm", "dmean_mm");
  for (const std::string size : {"small", "full"}) {
    const cf::MaskImage* mask = phantom(size).lumen.GetPointer();
    cf::ReconstructOptions o;
    row((size + " phantom, defaults").c_str(), mask, o);
    row((size + " phantom, defaults (again)").c_str(), mask, o);
    o.smoothing_iterations = 0;
    row((size + " phantom, no smoothing").c_str(), mask, o);
    o = cf::ReconstructOptions{};
    o.target_faces = size == "full" ? 200000 : 20000;
    row((size + " phantom, decimate to " + std::to_string(o.target_faces)).c_str(), mask, o);
  }
  std::printf("(peak_MiB: high-water mark during the call, mask included; +MiB: above the RSS before it)\n");
}

void BM_ReconstructPhantom(benchmark::State& state, const std::string& size, int target_faces) {
  const cf::MaskImage* mask = phantom(size).lumen.GetPointer();
  cf::ReconstructOptions o;
  o.target_faces = target_faces;
  std::size_t faces = 0;
  for (auto _ : state) {
    cf::Mesh m = cf::reconstruct_surface(mask, o);
    faces = m.n_faces();
    benchmark::DoNotOptimize(m);
  }
  state.counters["faces"] = double(faces);
}
BENCHMARK_CAPTURE(BM_ReconstructPhantom, small, std::string("small"), 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReconstructPhantom, full, std::string("full"), 0)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_ReconstructPhantom, full_decimated_200k, std::string("full"), 200000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

}  // namespace

int main(int argc, char** argv) {
  bool table_only = false;
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--table-only") == 0) table_only = true;
  table();
  if (table_only) return 0;
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
