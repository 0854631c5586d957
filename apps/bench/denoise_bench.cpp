// Denoising benchmark: for every closed shared mesh of genus >= 1 and for large generated
// surfaces (spheres with hundreds of handles, >= 1M faces), faces, genus, loops, total loop
// vertices, total loop length and time for the paper's method and the default (exact), and
// the triangle pairs its caps still intersect (cap_x; 0 = surgery introduced no intersection).
// Run in Release: ./build/apps/denoise_bench [--quick]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "bench_meshes.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/denoise/denoise.h"

namespace fs = std::filesystem;
using namespace cf;

namespace {

void row(const std::string& name, const Mesh& m, const std::string& method, int max_loops = -1) {
  DenoiseOptions o;
  o.method = method;
  const int genus = *analyze_topology(m).genus;
  if (max_loops >= 0) o.target_genus = std::max(0, genus - max_loops);
  Stopwatch sw;
  DenoiseResult r = denoise(m, o);
  const double t = sw.seconds();
  std::printf("%-22s %9zu %6d  %-6s %6zu %9zu %12.2f %9.2f %9.0f %6s %6zu  %s\n", name.c_str(), m.n_faces(), genus,
              method.c_str(), r.loops.size(), r.report["totals"]["loop_vertices"].get<std::size_t>(),
              r.report["totals"]["loop_length_mm"].get<double>(), t, peak_memory_mib(),
              r.report["genus_after"].is_null() ? "-" : r.report["genus_after"].dump().c_str(),
              r.report["totals"]["cap_intersections"].get<std::size_t>(),
              max_loops >= 0 ? ("first " + std::to_string(max_loops) + " loops only").c_str() : "");
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::strcmp(argv[1], "--sphere") == 0) {  // --sphere RADIUS HANDLES VOXEL: one case, phases
    Mesh m = bench::sphere_with_handles(std::atof(argv[2]), std::atoi(argv[3]), std::atof(argv[4]));
    DenoiseResult r = denoise(m, DenoiseOptions{});
    std::printf("faces %zu genus %s -> %s\ntime %s\nsearch %s\n", m.n_faces(), r.report["genus_before"].dump().c_str(),
                r.report["genus_after"].dump().c_str(), r.report["time_s"].dump().c_str(),
                r.report["search"].dump().c_str());
    return 0;
  }
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("%-22s %9s %6s  %-6s %6s %9s %12s %9s %9s %6s %6s\n", "mesh", "faces", "genus", "method", "loops",
              "loop_vtx", "loop_len_mm", "time_s", "peak_MiB", "g_after", "cap_x");
  const fs::path dir = fs::path(COLONFLAT_SHARED_DIR) / "meshes";
  std::ifstream in(dir / "MANIFEST.tsv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string name, faces, verts, genus, comps, closed;
    std::getline(ss, name, '\t');
    std::getline(ss, faces, '\t');
    std::getline(ss, verts, '\t');
    std::getline(ss, genus, '\t');
    std::getline(ss, comps, '\t');
    std::getline(ss, closed, '\t');
    if (genus == "NA" || closed != "True" || std::stoi(genus) < 1) continue;
    const Mesh m = load_mesh(dir / (name + ".off")).mesh;
    row(name, m, "paper");
    row(name, m, "exact");
  }
  // Large generated surfaces. Scaling: fixed voxel (0.6 mm) and handle density, area and handle
  // count growing together (time vs faces at the same local structure); then the >= 1.5M-face,
  // genus >= 300 target case, and a finer one.
  struct Big {
    double radius;
    int handles;
    double voxel;
  };
  std::vector<Big> bigs = quick ? std::vector<Big>{{50, 75, 0.6}}
                                : std::vector<Big>{{50, 75, 0.6},   {71, 150, 0.6},  {100, 300, 0.6},
                                                   {141, 600, 0.6}, {100, 300, 0.52}, {100, 400, 0.52}};
  for (const auto& b : bigs) {
    Stopwatch sw;
    Mesh m = bench::sphere_with_handles(b.radius, b.handles, b.voxel);
    std::fprintf(stderr, "generated %zu faces in %.1f s\n", m.n_faces(), sw.seconds());
    char name[64];
    std::snprintf(name, sizeof name, "sphere%.0f+%dh@%.2f", b.radius, b.handles, b.voxel);
    row(name, m, "exact");
    row(name, m, "paper", 3);
  }
  return 0;
}
