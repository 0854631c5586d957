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
//                            *.nrrd CT volumes: segmented with segment's defaults, then as a mask
//                            (the surface a mask-only tool would give; `colonflat run` reconstructs
//                            with the CT instead); *.vtk / *.vtp surfaces: denoise; cached in DIR2,
//                            default /tmp/flatten_bench_cache), flattened with map M: faces,
//                            coverage, area ratio p05/p95, qc mean/p95, flipped, time, peak memory;
//                            DIR3 gets colon.png per case. --raw-masks: each mask also as its raw
//                            staircase; --grown-masks: each mask also grown and shrunk by one voxel
//                            (mask_variants.h: the same anatomy with thinner / thicker walls);
//                            --sliced-masks: each mask with thinner slices also at 1.25 mm slices
//                            (a thick-slice scan: walls between touching loops drop out).
#include <benchmark/benchmark.h>

#include "bench_cli.h"
#include "bench_meshes.h"
#include "mask_variants.h"
#include "colonflat/core/orientation.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <functional>
#include <ctime>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include <filesystem>
#include <fstream>

#include "colonflat/core/orientation.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage.h"
#include "colonflat/denoise/denoise_stage.h"
#include "colonflat/reconstruct/reconstruct_stage.h"
#include "colonflat/segment/segment_stage.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/phantom/mask_phantom.h"
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

// The denoised surface of a real case, computed once and cached; `raw`: a lumen mask reconstructed
// as its binary staircase (no sub-voxel surface, smoothing or fairing: far more handles).
// A real case denoised (cached in `cache`): a surface as it is, a mask reconstructed first (`raw`:
// as its binary staircase; `grow` != 0: the mask grown (> 0) or shrunk (< 0) by that many voxels;
// `sliced`: the mask at kThickSliceMm slices).
std::filesystem::path denoised_real(const std::filesystem::path& in, const std::filesystem::path& cache, bool raw,
                                    int grow = 0, bool sliced = false) {
  std::filesystem::create_directories(cache);
  std::string stem = in.filename().string();
  stem = stem.substr(0, stem.find('.')) + (raw ? "_raw" : "") +
         (grow > 0 ? "_grown" + std::to_string(grow) : grow < 0 ? "_shrunk" + std::to_string(-grow) : "") +
         (sliced ? "_sliced" : "");
  const auto den = cache / (stem + "_denoised.vtp");
  if (std::filesystem::exists(den)) return den;
  std::filesystem::path source = in;
  if (grow != 0 || sliced) {
    source = cache / (stem + "_mask.nii.gz");
    const cf::MaskImage::Pointer mask = cf::read_mask(in);
    cf::write_mask(sliced ? cf::resample_mask_slices(mask, cf::bench::kThickSliceMm).GetPointer()
                          : cf::bench::grown_mask(mask, grow).GetPointer(),
                   source);
  }
  auto run = [](std::unique_ptr<cf::Stage> (*make)(), const std::vector<std::string>& args) {
    std::ostringstream o, e;
    if (cf::make_stage_tool(make)->run(args, o, e) != 0) throw std::runtime_error(e.str());
  };
  std::filesystem::path surface = source;
  if (in.string().size() > 7 && in.string().substr(in.string().size() - 7) == ".nii.gz") {
    surface = cache / (stem + "_surface.vtp");
    std::vector<std::string> args{source.string(), "-o", surface.string(), "-q"};
    if (raw)
      for (const char* a : {"--subvoxel", "off", "--smoothing-iterations", "0", "--fairing-iterations", "0"})
        args.push_back(a);
    run(cf::make_reconstruct_stage, args);
  }
  run(cf::make_denoise_stage, {surface.string(), "-o", den.string(), "-q"});
  return den;
}

// The lumen mask of a real CT volume `ct` (segment's defaults), computed once and cached as
// cache/<stem>_segmented.nii.gz: from there on a mask case like any other.
std::filesystem::path segmented_mask(const std::filesystem::path& ct, const std::filesystem::path& cache) {
  std::filesystem::create_directories(cache);
  const std::string name = ct.filename().string();
  const auto mask = cache / (name.substr(0, name.find('.')) + "_segmented.nii.gz");
  if (std::filesystem::exists(mask)) return mask;
  std::ostringstream o, e;
  if (cf::make_stage_tool(cf::make_segment_stage)->run({ct.string(), "-o", mask.string(), "-q"}, o, e) != 0)
    throw std::runtime_error(e.str());
  return mask;
}

// One surface of the stress set: its name and how to get it (genus 0, ready to flatten).
struct StressCase {
  std::string name;
  std::function<cf::Mesh()> load;
};

// The generated colon-like surfaces: the 1.07 M-face synthetic colon (folds, polyps) and the
// U-shaped colon-like mask surface (bridges, strands, hooks) with its limbs touching over 60, 120
// and 180 mm and not at all, as denoise_bench has them (each denoised once, cached).
std::vector<StressCase> generated_cases(const std::filesystem::path& cache) {
  std::vector<StressCase> cases;
  cases.push_back({"synthetic colon 1.5 m", [] { return cf::synthetic::to_mesh(cf::synthetic::colon(million_face_colon()).mesh); }});
  for (const int contact : {60, 120, 180, 0}) {
    const std::string tag = contact > 0 ? "contact" + std::to_string(contact) : "nocontact";
    const std::string name = contact > 0 ? "colon-like U, contact " + std::to_string(contact) + " mm" : "colon-like U, no contact";
    cases.push_back({name, [cache, contact, tag] {
                       const auto den = cache / ("colonlike_" + tag + "_denoised.vtp");
                       if (!std::filesystem::exists(den)) {
                         std::filesystem::create_directories(cache);
                         cf::write_mesh(cf::denoise(cf::bench::colon_like_surface({0.42, double(contact), true, true, true}),
                                                    cf::DenoiseOptions{}).mesh, den);
                       }
                       return cf::load_mesh(den).mesh;
                     }});
  }
  return cases;
}

// Peak memory from here on (Linux: writing 5 to clear_refs resets the process' VmHWM).
void reset_peak_memory() { std::ofstream("/proc/self/clear_refs") << "5"; }

// One row per surface and thread count: wall and CPU time of flatten_colon, CPU use, peak memory
// from the call on (the loaded surface included), coverage and distortion, whether the map equals
// the first thread count's (largest coordinate difference), then the stage's phases.
void stress_row(const std::string& name, const cf::Mesh& mesh, int threads, const cf::FlattenOptions& fo,
                std::vector<std::array<double, 2>>& first_uv, const std::string& out) {
  cf::set_thread_count(threads);
  reset_peak_memory();
  const double load = load_average(), cpu0 = cf::process_cpu_seconds();
  cf::ProgressScope scope(nullptr, "flatten");
  cf::Stopwatch sw;
  const cf::FlatMap flat = cf::flatten_colon(mesh, fo);
  const double t = sw.seconds(), cpu = cf::process_cpu_seconds() - cpu0;
  std::size_t left_out = 0;
  for (const auto& sg : flat.segments) left_out += sg.crowded_faces;
  std::string same = "-";
  if (first_uv.empty()) {
    first_uv = flat.uv;
  } else if (first_uv.size() != flat.uv.size()) {
    same = "no (size)";
  } else {
    double d = 0;
    for (std::size_t i = 0; i < flat.uv.size(); ++i)
      d = std::max({d, std::abs(flat.uv[i][0] - first_uv[i][0]), std::abs(flat.uv[i][1] - first_uv[i][1])});
    same = d == 0 ? "bitwise" : std::to_string(d);
  }
  const auto& st = flat.stats;
  std::printf("%-30s %8zu %3d %4zu %8.3f %9.0f %7.3f %7.3f %7.3f %7.3f %7zu %7zu %8.2f %8.2f %5.0f %8.0f %5.2f %s\n",
              name.c_str(), mesh.n_faces(), threads, flat.segments.size(), 100 * flat.coverage.fraction,
              flat.coverage.wall_area_mm2 - flat.coverage.shown_area_mm2, st.area_p05, st.area_p95, st.qc_mean,
              st.qc_p95, st.flipped, left_out, t, cpu, 100 * cpu / std::max(t, 1e-9), cf::peak_memory_mib(), load,
              same.c_str());
  std::string phases;
  for (const auto& ph : scope.phases())
    phases += " " + ph["phase"].get<std::string>() + " " + std::to_string(ph["time_s"].get<double>()).substr(0, 5) + ";";
  std::printf("    phases:%s\n", phases.c_str());
  for (const auto& sg : flat.segments)
    std::printf("    segment %d (%s, %zu faces): area p05 %.3f p95 %.3f, qc %.3f, shown %.2f %%, correction steps %d, "
                "left out %zu (%zu inverted)\n",
                sg.id, sg.kind.c_str(), sg.faces, sg.stats.area_p05, sg.stats.area_p95, sg.stats.qc_mean,
                100 * sg.coverage.fraction, sg.corrected_iterations, sg.crowded_faces, sg.inverted_faces);
  std::fflush(stdout);
  if (!out.empty() && same == "-") {
    std::filesystem::create_directories(out);
    cf::RenderOptions ro;
    ro.snapshots = false;
    std::string stem = name;
    std::replace(stem.begin(), stem.end(), ' ', '_');
    cf::write_png(cf::render_flat(flat, ro).colon.image, out + "/" + stem + "_colon.png");
  }
}

struct StressOptions {
  std::string real, cache, map, out;
  std::vector<std::string> surfaces;
  bool generated = false, raw_masks = false, grown_masks = false, sliced_masks = false;
  std::vector<int> thread_counts{1, 2};
};

void stress_table(const StressOptions& so) {
  std::vector<StressCase> cases;
  if (!so.real.empty()) {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(so.real)) {
      const std::string n = e.path().filename().string();
      if (n.find(".nii.gz") != std::string::npos || e.path().extension() == ".vtk" || e.path().extension() == ".vtp" ||
          e.path().extension() == ".nrrd")
        files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (auto in : files) {
      if (in.extension() == ".nrrd") in = segmented_mask(in, so.cache);
      const bool mask = in.string().find(".nii.gz") != std::string::npos;
      for (bool raw : {false, true})
        if (!raw || (mask && so.raw_masks))
          cases.push_back({in.filename().string() + (raw ? " raw" : ""),
                           [in, raw, &so] { return cf::load_mesh(denoised_real(in, so.cache, raw)).mesh; }});
      for (int grow : {1, -1})
        if (mask && so.grown_masks)
          cases.push_back({in.filename().string() + (grow > 0 ? " grown 1 vx" : " shrunk 1 vx"),
                           [in, grow, &so] { return cf::load_mesh(denoised_real(in, so.cache, false, grow)).mesh; }});
      if (mask && so.sliced_masks && cf::read_mask(in)->GetSpacing()[2] < cf::bench::kThickSliceMm)
        cases.push_back({in.filename().string() + " " + cf::bench::thick_slice_text() + " mm slices",
                         [in, &so] { return cf::load_mesh(denoised_real(in, so.cache, false, 0, true)).mesh; }});
    }
  }
  for (const std::string& f : so.surfaces)
    cases.push_back({std::filesystem::path(f).filename().string(), [f] { return cf::load_mesh(f).mesh; }});
  if (so.generated)
    for (auto& c : generated_cases(so.cache)) cases.push_back(std::move(c));
  std::printf("load average %.2f; map %s; %d cores\n", load_average(), so.map.c_str(), cf::default_thread_count());
  std::printf("time_s/cpu_s = wall/CPU time of flatten_colon, cpu%% = CPU/wall, peak_MiB = peak RSS from the call on "
              "(surface included), same = map vs the first thread count (largest |d uv| mm)\n");
  std::printf("%-30s %8s %3s %4s %8s %9s %7s %7s %7s %7s %7s %7s %8s %8s %5s %8s %5s %s\n", "case", "faces", "thr",
              "segs", "cover%", "notshown", "area05", "area95", "qc_mean", "qc_p95", "flipped", "leftout", "time_s",
              "cpu_s", "cpu%", "peak_MiB", "load", "same");
  cf::FlattenOptions fo;
  fo.map = so.map;
  for (const StressCase& c : cases) {
    cf::Mesh mesh = c.load();
    cf::orient_outward(mesh);  // as the flatten stage does (iso_surface's normals point into the lumen)
    std::vector<std::array<double, 2>> first_uv;
    for (int t : so.thread_counts) stress_row(c.name, mesh, t, fo, first_uv, so.out);
  }
  cf::set_thread_count(0);
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
  std::string phantoms, size = "full", threads = "1,2";
  StressOptions so{"", "/tmp/flatten_bench_cache", "area-balanced", ""};
  CLI::App& app = cli.app();
  app.add_flag("--table-only", table_only, "the table without Google Benchmark");
  app.add_option("--phantom", phantoms, "acceptance on phantom seeds N or N-M");
  app.add_option("--size", size, "phantom size")->check(CLI::IsMember({"full", "small"}));
  app.add_option("--out", so.out, "folder for the colon images (and the phantoms' candidate JSON)");
  app.add_option("--real", so.real, "stress set: folder of real cases (*.nii.gz masks, *.vtk / *.vtp surfaces)");
  app.add_option("--surface", so.surfaces, "stress set: a denoised (genus 0) surface, flattened as it is (repeatable)");
  app.add_flag("--generated", so.generated, "stress set: the generated colon-like surfaces");
  app.add_flag("--raw-masks", so.raw_masks, "stress set: also each --real mask reconstructed as its raw staircase");
  app.add_flag("--grown-masks", so.grown_masks, "stress set: also each --real mask grown and shrunk by one voxel");
  app.add_flag("--sliced-masks", so.sliced_masks,
               "stress set: also each --real mask with thinner slices at 1.25 mm slices (each the nearest of its own)");
  app.add_option("--thread-counts", threads, "stress set: thread counts, one row each (e.g. 1,2)");
  app.add_option("--cache", so.cache, "cache of denoised real and generated surfaces");
  app.add_option("--map", so.map, "flatten map")->check(CLI::IsMember({"area-balanced", "conformal"}));
  return cli.run(argc, argv, [&] {
    if (!so.real.empty() || !so.surfaces.empty() || so.generated) {
      so.thread_counts.clear();
      std::stringstream ss(threads);
      for (std::string t; std::getline(ss, t, ',');) so.thread_counts.push_back(std::stoi(t));
      stress_table(so);
      return 0;
    }
    if (!phantoms.empty()) {
      const auto [first, last] = cf::bench::parse_range(phantoms);
      phantom_table(first, last, size, so.out);
      return 0;
    }
    table();
    return table_only ? 0 : cli.run_google_benchmarks();
  });
}
