// Denoising benchmark: faces, genus, loops, total loop vertices (the seed paper's Table 3
// column), total and longest loop length, triangle pairs the caps still intersect (cap_x), time
// per phase (homology + cut graph, loop search, surgery) and total, peak memory, for
//   - the real colon mask ../shared/real/ctc_lumen_mask_a.nii.gz (reconstructed here with the
//     default reconstruct options) and the real GCA large-intestine surfaces;
//   - colon-like generated surfaces (long contact handles, air bridges, wide strands, hooks);
//   - every closed shared mesh of genus >= 1 (not with --quick);
//   - large generated spheres with hundreds of handles (>= 1M faces).
// Each with the default (exact) method and the paper's method (real and colon-like cases).
// Times are wall-clock per phase (report's time_s) and in total; cpu_s is the process CPU time
// of the row (both threads), the figure to compare when the machine is shared.
// Run in Release: ./build/apps/denoise_bench [--quick] [--exact-only] [--only real|colon|shared|spheres]
//   or one case: --sphere RADIUS HANDLES VOXEL, --colon VOXEL CONTACT_MM [OUT.vtp]
// Environment: DENOISE_BENCH_THREADS=2 runs the exact method's search on two threads (default 1).
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/resource.h>

#include "bench_meshes.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/denoise.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/volume/volume_io.h"

namespace fs = std::filesystem;
using namespace cf;

namespace {

// Minor page faults of the process so far (fresh memory touched: costly on this virtual machine).
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

void header() {
  std::printf("%-24s %8s %5s %-6s %5s %7s %9s %7s %5s %6s %7s %6s %7s %6s %8s %5s  %s\n", "mesh", "faces", "genus",
              "method", "loops", "loopvtx", "looplen", "longest", "cap_x", "hom_s", "search_s", "surg_s", "total_s",
              "cpu_s", "peak_MiB", "g_aft", "note");
}

bool g_exact_only = false;  // --exact-only: skip the paper method's rows

// One row: the result is built in place (DenoiseResult r = denoise(...)): assigning it to a
// declared result would copy the mesh (OpenMesh meshes have no move operations) inside the timing.
void print_row(const std::string& name, const Mesh& m, int genus, const std::string& method, int max_loops,
               const DenoiseOptions& o) {
  Stopwatch sw;
  const std::clock_t cpu0 = std::clock();  // process CPU time (all threads): meaningful on a loaded machine
  const DenoiseResult r = denoise(m, o);
  const double t = sw.seconds();
  const double cpu = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  const auto& tot = r.report["totals"];
  const auto& ts = r.report["time_s"];
  std::printf("%-24s %8zu %5d %-6s %5zu %7zu %9.1f %7.1f %5zu %6.2f %8.2f %6.2f %7.2f %6.2f %8.0f %5s  %s\n", name.c_str(),
              m.n_faces(), genus, method.c_str(), r.loops.size(), tot["loop_vertices"].get<std::size_t>(),
              tot["loop_length_mm"].get<double>(), tot["longest_loop_mm"].get<double>(),
              tot["cap_intersections"].get<std::size_t>(), ts["homology_and_cut_graph"].get<double>(),
              ts["loop_search"].get<double>(), ts["surgery"].get<double>(), t, cpu, peak_memory_mib(),
              r.report["genus_after"].is_null() ? "-" : r.report["genus_after"].dump().c_str(),
              max_loops >= 0 ? ("first " + std::to_string(max_loops) + " loops only").c_str() : "");
  if (std::getenv("DENOISE_BENCH_SEARCH")) std::printf("    search %s\n", r.report["search"].dump().c_str());
}

void row(const std::string& name, const Mesh& m, const std::string& method, int max_loops = -1) {
  if (g_exact_only && method != "exact") return;
  DenoiseOptions o;
  o.method = method;
  if (const char* t = std::getenv("DENOISE_BENCH_THREADS")) o.threads = std::atoi(t);
  const int genus = *analyze_topology(m).genus;
  if (max_loops >= 0) o.target_genus = std::max(0, genus - max_loops);
  try {
    print_row(name, m, genus, method, max_loops, o);
  } catch (const std::exception& e) {
    std::printf("%-24s %8zu %5d %-6s failed: %s\n", name.c_str(), m.n_faces(), genus, method.c_str(), e.what());
  }
  std::fflush(stdout);
}

void real_cases() {
  const fs::path real = fs::path(COLONFLAT_SHARED_DIR) / "real";
  const fs::path mask_file = real / "ctc_lumen_mask_a.nii.gz";
  if (fs::exists(mask_file)) {
    Stopwatch sw;
    const MaskImage::Pointer mask = read_mask(mask_file);
    const Mesh m = reconstruct_surface(mask.GetPointer(), ReconstructOptions{});
    std::fprintf(stderr, "reconstructed %s: %zu faces in %.1f s\n", mask_file.filename().c_str(), m.n_faces(), sw.seconds());
    row("real ctc_lumen_mask_a", m, "exact");
    row("real ctc_lumen_mask_a", m, "paper");
  }
  for (const char* f : {"gca_large_intestine_100k.vtk", "gca_large_intestine_20k.vtk"}) {
    if (!fs::exists(real / f)) continue;
    const Mesh m = load_mesh(real / f).mesh;
    row(std::string("real ") + std::string(f).substr(4, std::strlen(f) - 8), m, "exact");
    row(std::string("real ") + std::string(f).substr(4, std::strlen(f) - 8), m, "paper");
  }
}

void colon_like_cases(bool quick) {
  struct Case {
    const char* name;
    bench::ColonLikeOptions o;
  };
  std::vector<Case> cases{{"colonlike contact60", {0.42, 60, true, true, true}},
                          {"colonlike contact120", {0.42, 120, true, true, true}},
                          {"colonlike nocontact", {0.42, 0, true, true, true}}};
  if (quick) cases = {{"colonlike contact60 @0.8", {0.8, 60, true, true, true}}};
  for (const auto& c : cases) {
    Stopwatch sw;
    const Mesh m = bench::colon_like_surface(c.o);
    std::fprintf(stderr, "generated %s: %zu faces in %.1f s\n", c.name, m.n_faces(), sw.seconds());
    row(c.name, m, "exact");
    row(c.name, m, "paper");
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
    const Mesh m = load_mesh(dir / (name + ".off")).mesh;
    row(name, m, "paper");
    row(name, m, "exact");
  }
}

// Scaling: fixed voxel (0.6 mm) and handle density, area and handle count growing together;
// then the >= 1.5M-face, genus >= 300 target case, and a finer one.
void sphere_cases(bool quick) {
  struct Big {
    double radius;
    int handles;
    double voxel;
  };
  const std::vector<Big> bigs = quick ? std::vector<Big>{{100, 300, 0.52}}
                                      : std::vector<Big>{{50, 75, 0.6},   {71, 150, 0.6},  {100, 300, 0.6},
                                                         {141, 600, 0.6}, {100, 300, 0.52}, {100, 400, 0.52}};
  for (const auto& b : bigs) {
    Stopwatch sw;
    const Mesh m = bench::sphere_with_handles(b.radius, b.handles, b.voxel);
    std::fprintf(stderr, "generated %zu faces in %.1f s\n", m.n_faces(), sw.seconds());
    char name[64];
    std::snprintf(name, sizeof name, "sphere%.0f+%dh@%.2f", b.radius, b.handles, b.voxel);
    row(name, m, "exact");
    row(name, m, "paper", 3);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::strcmp(argv[1], "--sphere") == 0) {  // --sphere RADIUS HANDLES VOXEL: one case, phases
    Mesh m = bench::sphere_with_handles(std::atof(argv[2]), std::atoi(argv[3]), std::atof(argv[4]));
    Stopwatch sw;
    const std::clock_t cpu0 = std::clock();
    const long faults0 = minor_faults();
    DenoiseOptions o;
    if (const char* t = std::getenv("DENOISE_BENCH_THREADS")) o.threads = std::atoi(t);
    DenoiseResult r = denoise(m, o);
    std::printf("wall %.2f s, cpu %.2f s, peak %.0f MiB, %ld page faults\n", sw.seconds(),
                double(std::clock() - cpu0) / CLOCKS_PER_SEC, peak_memory_mib(), minor_faults() - faults0);
    std::printf("faces %zu genus %s -> %s\ntotals %s\ntime %s\nsearch %s\n", m.n_faces(),
                r.report["genus_before"].dump().c_str(), r.report["genus_after"].dump().c_str(),
                r.report["totals"].dump().c_str(), r.report["time_s"].dump().c_str(), r.report["search"].dump().c_str());
    return 0;
  }
  if (argc >= 4 && std::strcmp(argv[1], "--colon") == 0) {  // --colon VOXEL CONTACT [OUT.vtp]: one colon-like case
    const Mesh m = bench::colon_like_surface({std::atof(argv[2]), std::atof(argv[3]), true, true, true});
    if (argc >= 5) write_mesh(m, argv[4]);
    header();
    row("colonlike", m, "exact");
    return 0;
  }
  bool quick = false;
  std::string only;
  const char* usage =
      "usage: denoise_bench [--quick] [--exact-only] [--only real|colon|shared|spheres]\n"
      "       denoise_bench --sphere RADIUS HANDLES VOXEL | --colon VOXEL CONTACT_MM [OUT.vtp]\n";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    else if (std::strcmp(argv[i], "--exact-only") == 0) g_exact_only = true;
    else if (std::strcmp(argv[i], "--only") == 0 && i + 1 < argc) only = argv[++i];
    else {
      const bool help = std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0;
      if (!help) std::fprintf(stderr, "denoise_bench: error: unknown argument '%s'\n", argv[i]);
      std::fputs(usage, help ? stdout : stderr);
      return help ? 0 : 2;
    }
  }
  header();
  if (only.empty() || only == "real") real_cases();
  if (only.empty() || only == "colon") colon_like_cases(quick);
  if ((only.empty() && !quick) || only == "shared") shared_cases();
  if (only.empty() || only == "spheres") sphere_cases(quick);
  return 0;
}
