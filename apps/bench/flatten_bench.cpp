// Flattening benchmark and acceptance table (Release):
//   flatten_bench            timing of cf::flatten_colon on a >= 1M-face synthetic colon (3 runs),
//                            distortion and flipped triangles, then the Google Benchmark cases.
//   flatten_bench --table-only   the table without Google Benchmark.
//   flatten_bench --phantom 1-5 [--size full|small] [--out DIR]
//                            acceptance on phantoms: ground-truth lumen -> reconstruct -> denoise ->
//                            flatten -> polyp candidates, scored against the phantom's polyps
//                            (sensitivity for polyps >= 6 mm, false positives per scan); DIR gets
//                            the colon images (with the known polyps) and the candidate JSON.
//   flatten_bench --real DIR [--cache DIR2] [--map M] [--out DIR3]
//                            the real cases in DIR (*.nii.gz lumen masks: reconstruct + denoise;
//                            *.vtk / *.vtp surfaces: denoise; denoised surfaces cached in DIR2,
//                            default /tmp/flatten_bench_cache), flattened with map M: faces,
//                            coverage, area ratio p05/p95, qc mean/p95, flipped, time, peak memory;
//                            DIR3 gets colon.png per case.
#include <benchmark/benchmark.h>

#include "bench_cli.h"

#include <cstdio>
#include <ctime>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include <filesystem>
#include <fstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage.h"
#include "colonflat/denoise/denoise_stage.h"
#include "colonflat/reconstruct/reconstruct_stage.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/reconstruct/reconstruct.h"
#include <vtkImageData.h>

#include "colonflat/render/artifacts.h"
#include "colonflat/render/render_stage.h"

namespace {

using cf::bench::load_average;

cf::synthetic::ColonOptions million_face_colon() {
  cf::synthetic::ColonOptions o;
  o.length = 1500;
  o.radius = 25;
  o.spacing = 0.68;  // isotropic triangles (231 around, 2206 rings): 1.07 M faces
  for (int i = 0; i < 10; ++i) o.polyps.push_back({100.0 + 130 * i, 0.7 * i, 5.0 + i});
  return o;
}

void print_row(const char* name, std::size_t faces, double secs, double cpu, const cf::FlatMap& f) {
  const auto& s = f.stats;
  std::printf("%-28s %9zu %7.2f %7.2f %7zu %8.4f %8.4f %8.3f %7.3f %7.3f %7.3f\n", name, faces, secs, cpu, s.flipped,
              s.qc_mean, s.qc_p95, s.qc_max, s.area_p05, s.area_median, s.area_p95);
}

void table() {
  std::printf("load average %.2f; time_s = wall clock, cpu_s = CPU time of all threads\n", load_average());
  std::printf("%-28s %9s %7s %7s %7s %8s %8s %8s %7s %7s %7s\n", "surface", "faces", "time_s", "cpu_s", "flipped", "qc_mean",
              "qc_p95", "qc_max", "area05", "area50", "area95");
  const auto colon = cf::synthetic::colon(million_face_colon());
  for (int run = 0; run < 3; ++run) {
    cf::Stopwatch sw;
    const std::clock_t c0 = std::clock();
    const cf::FlatMap f = cf::flatten_colon(colon.mesh);
    const double t = sw.seconds(), cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    print_row("synthetic colon 1.5 m", colon.mesh.triangles.size(), t, cpu, f);
  }
  std::printf("peak memory %.0f MiB\n", cf::peak_memory_mib());
}

void phantom_table(int first, int last, const std::string& size, const std::string& out) {
  std::printf("%-5s %8s %5s %7s %7s %8s %8s %8s %8s %7s %7s %6s %6s %6s %4s %s\n", "seed", "faces", "genus", "flat_s",
              "flipped", "cover%", "qc_mean", "qc_p95", "qc_max", "area05", "area95", "polyps", "found", "sens", "FP",
              "missed (id:diameter)");
  int tot_p = 0, tot_f = 0, tot_fp = 0;
  for (int seed = first; seed <= last; ++seed) {
    cf::PhantomOptions po;
    po.seed = std::uint64_t(seed);
    po.size = size;
    cf::Phantom ph = cf::generate_phantom(po);
    ph.ct = nullptr;
    const cf::Mesh surface = cf::reconstruct_surface(ph.lumen.GetPointer(), cf::ReconstructOptions{});
    ph.lumen = nullptr;
    const cf::DenoiseResult dn = cf::denoise(surface, cf::DenoiseOptions{});
    cf::Stopwatch sw;
    const cf::FlatMap flat = cf::flatten_colon(dn.mesh);
    const double t = sw.seconds();
    nlohmann::json known = nlohmann::json::array();
    std::vector<cf::KnownPolyp> truth;
    for (const auto& p : ph.polyps) {
      known.push_back({{"id", p.id}, {"center_lps_mm", p.center_lps_mm}, {"diameter_mm", p.diameter_mm}, {"type", p.type}});
      truth.push_back({p.id, p.center_lps_mm, p.diameter_mm, p.type});
    }
    const std::string dir = out.empty() ? std::string() : out + "/seed" + std::to_string(seed);
    cf::RenderOptions ro;
    if (!dir.empty()) {
      std::filesystem::create_directories(dir);
      std::ofstream(dir + "/known_polyps.json") << known.dump(2);
      ro.known_polyps = dir + "/known_polyps.json";
    }
    const cf::RenderResult rr = cf::render_flat(flat, ro);
    const cf::DetectionScore sc = cf::score_detections(rr.candidates, truth, 6.0, 5.0);
    std::string missed;
    for (int id : sc.missed_ids)
      for (const auto& p : ph.polyps)
        if (p.id == id) missed += std::to_string(id) + ":" + std::to_string(int(std::lround(p.diameter_mm))) + " ";
    const auto& st = flat.stats;
    std::printf("%-5d %8zu %5d %7.2f %7zu %8.3f %8.4f %8.4f %8.2f %7.3f %7.3f %6d %6d %6.2f %4d %s\n", seed,
                dn.mesh.n_faces(), dn.before.genus ? *dn.before.genus : -1, t, st.flipped, 100 * flat.coverage.fraction, st.qc_mean, st.qc_p95,
                st.qc_max, st.area_p05, st.area_p95, sc.polyps, sc.polyps_detected, sc.sensitivity,
                sc.false_positives, missed.c_str());
    std::fflush(stdout);
    tot_p += sc.polyps, tot_f += sc.polyps_detected, tot_fp += sc.false_positives;
    if (!dir.empty()) {
      cf::write_png(rr.colon.image, dir + "/colon.png");
      std::ofstream(dir + "/polyps.json") << rr.candidates_json.dump(2);
    }
  }
  std::printf("total: %d/%d polyps >= 6 mm found (sensitivity %.3f), %.2f false positives per scan\n", tot_f, tot_p,
              tot_p ? double(tot_f) / tot_p : 1.0, double(tot_fp) / (last - first + 1));
}

// The denoised surface of a real case, computed once and cached.
std::filesystem::path denoised_real(const std::filesystem::path& in, const std::filesystem::path& cache) {
  std::filesystem::create_directories(cache);
  std::string stem = in.filename().string();
  stem = stem.substr(0, stem.find('.'));
  const auto den = cache / (stem + "_denoised.vtp");
  if (std::filesystem::exists(den)) return den;
  auto run = [](std::unique_ptr<cf::Stage> (*make)(), const std::vector<std::string>& args) {
    std::ostringstream o, e;
    if (cf::make_stage_tool(make)->run(args, o, e) != 0) throw std::runtime_error(e.str());
  };
  std::filesystem::path surface = in;
  if (in.string().size() > 7 && in.string().substr(in.string().size() - 7) == ".nii.gz") {
    surface = cache / (stem + "_surface.vtp");
    run(cf::make_reconstruct_stage, {in.string(), "-o", surface.string(), "-q"});
  }
  run(cf::make_denoise_stage, {surface.string(), "-o", den.string(), "-q"});
  return den;
}

void real_table(const std::string& dir, const std::string& cache, const std::string& map, const std::string& out) {
  std::printf("load average %.2f; map %s\n", load_average(), map.c_str());
  std::printf("time_s = wall clock of flatten_colon, cpu_s = its CPU time (all threads), load = load average before\n");
  std::printf("%-30s %8s %4s %8s %9s %7s %7s %7s %7s %7s %7s %8s %8s %8s %5s\n", "case", "faces", "segs", "cover%",
              "notshown", "area05", "area95", "qc_mean", "qc_p95", "flipped", "leftout", "time_s", "cpu_s", "peak_MiB",
              "load");
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.find(".nii.gz") != std::string::npos || e.path().extension() == ".vtk" || e.path().extension() == ".vtp")
      files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& in : files) {
    const auto den = denoised_real(in, cache);
    const cf::Mesh mesh = cf::load_mesh(den).mesh;
    cf::FlattenOptions fo;
    fo.map = map;
    const double load = load_average();
    cf::Stopwatch sw;
    const std::clock_t c0 = std::clock();
    const cf::FlatMap flat = cf::flatten_colon(mesh, fo);
    const double t = sw.seconds(), cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    std::size_t left_out = 0;
    for (const auto& sg : flat.segments) left_out += sg.crowded_faces;
    const auto& st = flat.stats;
    std::printf("%-30s %8zu %4zu %8.3f %9.0f %7.3f %7.3f %7.3f %7.3f %7zu %7zu %8.2f %8.2f %8.0f %5.2f\n",
                in.filename().string().c_str(), mesh.n_faces(), flat.segments.size(), 100 * flat.coverage.fraction,
                flat.coverage.wall_area_mm2 - flat.coverage.shown_area_mm2, st.area_p05, st.area_p95, st.qc_mean,
                st.qc_p95, st.flipped, left_out, t, cpu, cf::peak_memory_mib(), load);
    for (const auto& sg : flat.segments)
      std::printf("    segment %d: %s -> %s, centreline %.0f mm, band %.0f x %.0f mm, balanced %zu vertices\n", sg.id,
                  sg.x0_end.c_str(), sg.x1_end.c_str(), sg.centreline_length, sg.length, sg.period,
                  sg.balanced_vertices);
    std::fflush(stdout);
    if (!out.empty()) {
      std::filesystem::create_directories(out);
      cf::RenderOptions ro;
      ro.snapshots = false;
      const cf::RenderResult rr = cf::render_flat(flat, ro);
      std::string stem = in.filename().string();
      cf::write_png(rr.colon.image, out + "/" + stem.substr(0, stem.find('.')) + "_colon.png");
    }
  }
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
  cf::bench::BenchCli cli("flatten_bench", "Flattening benchmark and acceptance table (see the file's header)");
  bool table_only = false;
  std::string phantoms, size = "full", out, real, cache = "/tmp/flatten_bench_cache", map = "area-balanced";
  CLI::App& app = cli.app();
  app.add_flag("--table-only", table_only, "the table without Google Benchmark");
  app.add_option("--phantom", phantoms, "acceptance on phantom seeds N or N-M");
  app.add_option("--size", size, "phantom size")->check(CLI::IsMember({"full", "small"}));
  app.add_option("--out", out, "folder for the colon images and candidate JSON");
  app.add_option("--real", real, "folder of real cases (*.nii.gz masks, *.vtk / *.vtp surfaces)");
  app.add_option("--cache", cache, "cache of denoised real surfaces");
  app.add_option("--map", map, "flatten map")->check(CLI::IsMember({"area-balanced", "conformal"}));
  return cli.run(argc, argv, [&] {
    if (!real.empty()) {
      real_table(real, cache, map, out);
      return 0;
    }
    if (!phantoms.empty()) {
      const auto [first, last] = cf::bench::parse_range(phantoms);
      phantom_table(first, last, size, out);
      return 0;
    }
    table();
    return table_only ? 0 : cli.run_google_benchmarks();
  });
}
