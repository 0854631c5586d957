// Denoising benchmark: one row per surface and per thread count (default 1 and 2) with faces,
// genus, loops, total loop vertices (the seed paper's Table 3 column), total and longest loop
// length, triangle pairs the caps still intersect (cap_x), time per phase (topology analysis,
// homology + cut graph, loop search, surgery, verification), total wall time, process CPU time of
// the row (cpu_s / total_s = the cores kept busy) and the row's peak memory (VmHWM reset before
// each row; the input surface, resident during the row, is included).
//
// Sets (--only, default "stress"):
//   stress  every surface below that is built from ../shared (nothing is read from elsewhere):
//           - the real mask ../shared/real/ctc_lumen_mask_a.nii.gz reconstructed raw: the binary
//             staircase (--subvoxel off, no smoothing, no fairing): far more handles;
//           - the same mask reconstructed with the defaults;
//           - the same mask grown and shrunk by one voxel (mask_variants.h: thinner walls between
//             touching loops fuse into more and longer handles; thin necks open), then the defaults;
//           - the real prone CT ../shared/real/ctc_prone_a.nrrd, segmented and reconstructed with
//             the defaults (as `colonflat run` does: reconstruct also gets the CT);
//           - its lumen mask reconstructed from the mask alone, raw, with the defaults, grown
//             and shrunk by one voxel (the rows of the real mask, for a second real colon), and at
//             1.25 mm slices (a mask with thinner slices only: a thick-slice scan of the same colon,
//             where walls between touching loops that lay in a dropped slice are gone);
//           - the real GCA large-intestine surfaces (../shared/real/*.vtk);
//           - generated colon-like surfaces at 0.42 mm voxels (bench_meshes.h): limbs touching
//             over 60, 120 and 180 mm, no contact;
//   real / colon    the real or the generated surfaces of the stress set alone;
//   shared          every closed shared mesh of genus >= 1 (../shared/meshes);
//   spheres         large generated spheres with hundreds of handles (>= 1 M faces).
// Also: --surface FILE (repeatable) adds a row per file (with --only none: only those); --threads LIST (default 1,2) the thread
// counts (cf::set_thread_count, as `--threads N` of colonflat); --save DIR writes each surface of
// the set to DIR/<name>.vtp before denoising it; --paper adds the paper method's rows (one thread).
//   ./build/apps/bench/denoise_bench [--only SET] [--threads 1,2] [--surface F.vtp] [--save DIR]
//   one case: --sphere RADIUS HANDLES VOXEL, --colon VOXEL CONTACT_MM
// COLONFLAT_DENOISE_DEBUG=1 prints one line per cut (docs/denoise.md).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench_cli.h"
#include "bench_meshes.h"
#include "mask_variants.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/segment/segment.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;
using namespace cf;

namespace {

struct Settings {
  std::vector<int> threads{1, 2};
  bool paper = false;
  std::string save_dir;
};
Settings g;

// Resets the process's peak resident set (VmHWM) to its current size, so that the next
// peak_memory_mib() is the peak since this call (Linux >= 4.0; ignored elsewhere).
void reset_peak_memory() {
  std::ofstream clear("/proc/self/clear_refs");
  if (clear) clear << "5";
}

void header() {
  std::printf("%-26s %8s %5s %3s %-6s %5s %7s %8s %7s %5s %6s %6s %8s %6s %6s %7s %7s %8s %5s\n", "mesh", "faces",
              "genus", "thr", "method", "loops", "loopvtx", "looplen", "longest", "cap_x", "ana_s", "hom_s", "search_s",
              "surg_s", "ver_s", "total_s", "cpu_s", "peak_MiB", "g_aft");
}

// One row. The result is built in place (DenoiseResult r = denoise(...)): assigning it to a
// declared result would copy the mesh (OpenMesh meshes have no move operations) inside the timing.
void print_row(const std::string& name, const Mesh& m, int genus, int threads, const DenoiseOptions& o) {
  set_thread_count(threads);
  reset_peak_memory();
  Stopwatch sw;
  const double cpu0 = process_cpu_seconds();
  const DenoiseResult r = denoise(m, o);
  const double t = sw.seconds(), cpu = process_cpu_seconds() - cpu0;
  const auto& tot = r.report["totals"];
  const auto& ts = r.report["time_s"];
  std::printf("%-26s %8zu %5d %3d %-6s %5zu %7zu %8.1f %7.1f %5zu %6.2f %6.2f %8.2f %6.2f %6.2f %7.2f %7.2f %8.0f %5s\n",
              name.c_str(), m.n_faces(), genus, threads, o.method.c_str(), r.loops.size(),
              tot["loop_vertices"].get<std::size_t>(), tot["loop_length_mm"].get<double>(),
              tot["longest_loop_mm"].get<double>(), tot["cap_intersections"].get<std::size_t>(),
              ts["analysis"].get<double>(), ts["homology_and_cut_graph"].get<double>(), ts["loop_search"].get<double>(),
              ts["surgery"].get<double>(), ts["verification"].get<double>(), t, cpu, peak_memory_mib(),
              r.report["genus_after"].is_null() ? "-" : r.report["genus_after"].dump().c_str());
  if (std::getenv("DENOISE_BENCH_SEARCH")) std::printf("    search %s\n", r.report["search"].dump().c_str());
}

// The rows of one surface: the exact method for every thread count (and the paper's, on request).
void rows(const std::string& name, const Mesh& m) {
  if (!g.save_dir.empty()) {
    fs::create_directories(g.save_dir);
    write_mesh(m, fs::path(g.save_dir) / (name + ".vtp"));
  }
  const int genus = *analyze_topology(m).genus;
  std::vector<std::pair<std::string, int>> runs;
  for (int t : g.threads) runs.push_back({"exact", t});
  if (g.paper) runs.push_back({"paper", 1});
  for (const auto& [method, threads] : runs) {
    DenoiseOptions o;
    o.method = method;
    try {
      print_row(name, m, genus, threads, o);
    } catch (const std::exception& e) {
      std::printf("%-26s %8zu %5d %3d %-6s failed: %s\n", name.c_str(), m.n_faces(), genus, threads, method.c_str(),
                  e.what());
    }
    std::fflush(stdout);
  }
  set_thread_count(0);
}

// A surface built (timed on stderr) and its rows.
void built(const std::string& name, const std::function<Mesh()>& build) {
  Stopwatch sw;
  const Mesh m = build();
  std::fprintf(stderr, "%s: %zu faces built in %.1f s\n", name.c_str(), m.n_faces(), sw.seconds());
  rows(name, m);
}

// The rows of one real lumen mask: its raw staircase (no sub-voxel surface, no smoothing or
// fairing: far more handles), reconstruct's defaults, and the defaults on the mask grown and shrunk
// by one voxel and, when its slices are thinner, at kThickSliceMm slices (mask_variants.h).
void mask_cases(const std::string& name, const MaskImage* mask) {
  built(name + " raw", [&] {
    ReconstructOptions raw;
    raw.subvoxel = "off";
    raw.smoothing_iterations = 0;
    raw.fairing_iterations = 0;
    return reconstruct_surface(mask, raw);
  });
  built(name, [&] { return reconstruct_surface(mask, ReconstructOptions{}); });
  for (int grow : {1, -1})
    built(name + (grow > 0 ? " grown 1 vx" : " shrunk 1 vx"),
          [&] { return reconstruct_surface(bench::grown_mask(mask, grow).GetPointer(), ReconstructOptions{}); });
  if (mask->GetSpacing()[2] < bench::kThickSliceMm)
    built(name + " " + bench::thick_slice_text() + " mm slices", [&] {
      return reconstruct_surface(resample_mask_slices(mask, bench::kThickSliceMm).GetPointer(), ReconstructOptions{});
    });
}

void real_cases() {
  const fs::path real = fs::path(COLONFLAT_SHARED_DIR) / "real";
  const fs::path mask_file = real / "ctc_lumen_mask_a.nii.gz", ct_file = real / "ctc_prone_a.nrrd";
  if (fs::exists(mask_file)) mask_cases("real mask", read_mask(mask_file).GetPointer());
  if (fs::exists(ct_file)) {
    const CtImage::Pointer ct = read_ct_volume(ct_file);
    const MaskImage::Pointer mask = segment_colon(ct.GetPointer());
    built("real CT prone", [&] { return reconstruct_surface(mask.GetPointer(), ct.GetPointer(), ReconstructOptions{}); });
    mask_cases("real CT mask", mask.GetPointer());  // the CT's lumen as a mask-only tool reconstructs it
  }
  for (const char* f : {"gca_large_intestine_100k.vtk", "gca_large_intestine_20k.vtk"})
    if (fs::exists(real / f)) rows(std::string("real GCA ") + (std::strstr(f, "100k") ? "100k" : "20k"), load_mesh(real / f).mesh);
}

void colon_like_cases() {
  for (double contact : {60.0, 120.0, 180.0, 0.0}) {
    const std::string name = contact > 0 ? "colonlike contact" + std::to_string(int(contact)) : "colonlike nocontact";
    built(name, [&] { return bench::colon_like_surface({0.42, contact, true, true, true}); });
  }
}

void shared_cases() {
  const fs::path dir = fs::path(COLONFLAT_SHARED_DIR) / "meshes";
  std::ifstream in(dir / "MANIFEST.tsv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string name, faces, verts, genus, comps, closed;
    for (std::string* f : {&name, &faces, &verts, &genus, &comps, &closed}) std::getline(ss, *f, '\t');
    if (genus == "NA" || closed != "True" || std::stoi(genus) < 1) continue;
    rows(name, load_mesh(dir / (name + ".off")).mesh);
  }
}

// Scaling: fixed voxel (0.6 mm) and handle density, area and handle count growing together;
// then the >= 1.5M-face, genus >= 300 case, and a finer one.
void sphere_cases() {
  struct Big {
    double radius;
    int handles;
    double voxel;
  };
  for (const Big& b : std::vector<Big>{{50, 75, 0.6}, {71, 150, 0.6}, {100, 300, 0.6}, {141, 600, 0.6},
                                       {100, 300, 0.52}, {100, 400, 0.52}}) {
    char name[64];
    std::snprintf(name, sizeof name, "sphere%.0f+%dh@%.2f", b.radius, b.handles, b.voxel);
    built(name, [&] { return bench::sphere_with_handles(b.radius, b.handles, b.voxel); });
  }
}

std::vector<int> parse_threads(const std::string& list) {
  std::vector<int> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) {
    const auto [first, last] = bench::parse_range(item);
    for (int t = first; t <= last; ++t) out.push_back(t);
  }
  if (out.empty() || out.front() < 1) throw std::invalid_argument("--threads: give counts >= 1, e.g. 1,2");
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bench::BenchCli cli("denoise_bench", "Denoising benchmark: one row per surface and thread count (see the source's head)");
  std::string only = "stress", threads = "1,2";
  std::vector<std::string> surfaces;
  std::vector<double> sphere, colon;
  CLI::App& app = cli.app();
  app.add_option("--only", only, "set: stress, real, colon, shared, spheres, none")
      ->check(CLI::IsMember({"stress", "real", "colon", "shared", "spheres", "none"}));
  app.add_option("--threads", threads, "thread counts, e.g. 1,2 or 1-4");
  app.add_option("--surface", surfaces, "a surface file to add as a row (repeatable)")->check(CLI::ExistingFile);
  app.add_option("--save", g.save_dir, "write each surface of the set to DIR/<name>.vtp");
  app.add_flag("--paper", g.paper, "also the paper method's rows (one thread; minutes on the real surfaces)");
  app.add_option("--sphere", sphere, "one case: RADIUS HANDLES VOXEL")->expected(3);
  app.add_option("--colon", colon, "one case: VOXEL CONTACT_MM")->expected(2);
  return cli.run(argc, argv, [&] {
    g.threads = parse_threads(threads);
    std::printf("load average %.2f, %d cores\n", bench::load_average(), default_thread_count());
    header();
    for (const std::string& f : surfaces) rows(fs::path(f).filename().string(), load_mesh(f).mesh);
    if (sphere.size() == 3) {
      built("sphere", [&] { return bench::sphere_with_handles(sphere[0], int(sphere[1]), sphere[2]); });
      return 0;
    }
    if (colon.size() == 2) {
      built("colonlike", [&] { return bench::colon_like_surface({colon[0], colon[1], true, true, true}); });
      return 0;
    }
    if (only == "stress" || only == "real") real_cases();
    if (only == "stress" || only == "colon") colon_like_cases();
    if (only == "shared") shared_cases();
    if (only == "spheres") sphere_cases();
    return 0;
  });
}
