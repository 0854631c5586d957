// Reconstruction benchmark and acceptance table (Release):
//   reconstruct_bench               table on the small and full-size phantoms (seed 1) and on the real
//                                   mask ../shared/real/ctc_lumen_mask_a.nii.gz (when present), with
//                                   each sub-voxel mode: time per step, faces, genus, peak memory of
//                                   the reconstruction alone, distance to the mask's voxel boundary
//                                   (mm and voxels); then the Google Benchmark cases.
//   reconstruct_bench --table-only  the table without Google Benchmark.
//   reconstruct_bench --real-only   only the real mask's rows of the table.
//   reconstruct_bench --closeup DIR the real mask's flattest wall patch: ripple measures (RMS dihedral
//                                   angle, RMS residual of a quadric fit) for each surface mode, and
//                                   a shaded close-up PNG of each into DIR (VTK off-screen; needs X,
//                                   e.g. xvfb-run). For docs/reconstruct.md.
// Peak memory: the process's peak resident set is reset (/proc/self/clear_refs) after generating
// the phantom, so "peak" is the high-water mark while reconstructing, the mask included.
#include <benchmark/benchmark.h>

#include "bench_cli.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/render/snapshot.h"
#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkRenderingOpenGL2);

#include <Eigen/Dense>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkLight.h>
#include <vtkNew.h>
#include <vtkImageData.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkWindowToImageFilter.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <queue>
#include <string>
#include <vector>

#include "colonflat/core/run_stats.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/reconstruct/reconstruct.h"
#include "colonflat/volume/volume_io.h"

namespace {

const cf::Phantom& phantom(const std::string& size) {
  static std::map<std::string, cf::Phantom> cache;
  auto it = cache.find(size);
  if (it == cache.end()) {
    cf::PhantomOptions o;
    o.size = size;
    o.seed = 1;
    cf::Phantom p = cf::generate_phantom(o);
    it = cache.emplace(size, std::move(p)).first;
  }
  return it->second;
}

bool reset_peak_memory() {
  std::ofstream f("/proc/self/clear_refs");
  f << "5";
  return bool(f);
}

// One table row: the call's time and steps, faces, genus, memory, distance to the mask's voxel
// boundary (the staircase surface) in mm and voxels.
void row(const std::string& name, const cf::MaskImage* mask, const cf::CtImage* ct, const cf::ReconstructOptions& o) {
  const bool reset = reset_peak_memory();
  const double base = cf::current_memory_mib();
  cf::ReconstructStats st;
  cf::Stopwatch sw;
  const cf::Mesh m = cf::reconstruct_surface(mask, ct, o, &st);
  const double t = sw.seconds();
  const double peak = cf::peak_memory_mib();
  const cf::BoundaryDistance d = cf::distance_to_mask_boundary(m, mask);
  std::printf("%-38s %7.2f %6.2f %6.2f %6.2f %6.2f %6.2f %9zu %5zu %5d %8.0f%s %7.0f %6.3f %6.3f %6.3f\n", name.c_str(),
              t, st.time_field_s, st.time_extract_s, st.time_check_s, st.time_smooth_s, st.time_decimate_s, st.faces,
              st.kept.size(), st.genus, peak, reset ? "" : "*", peak - base, d.max_mm, d.mean_mm, d.max_voxels);
}

cf::ReconstructOptions mode(const std::string& subvoxel, int sinc_iterations,
                            int fairing = cf::ReconstructOptions{}.fairing_iterations,
                            const std::string& smoothing = cf::ReconstructOptions{}.mask_smoothing) {
  cf::ReconstructOptions o;
  o.subvoxel = subvoxel;
  o.smoothing_iterations = sinc_iterations;
  o.fairing_iterations = fairing;
  o.mask_smoothing = smoothing;
  return o;
}

void rows_for(const std::string& name, const cf::MaskImage* mask, const cf::CtImage* ct) {
  row(name + ", defaults", mask, ct, cf::ReconstructOptions{});
  row(name + ", staircase (subvoxel off)", mask, ct, mode("off", 0));
  row(name + ", staircase + sinc 20 (old)", mask, ct, mode("off", 20));
  row(name + ", mask sinc 20 clamped, no fairing (previous default)", mask, ct, mode("mask", 20, 0));
  row(name + ", mask antialias + sinc 20 + fairing", mask, ct, mode("mask", 20, 100, "antialias"));
  if (ct) row(name + ", ct", mask, ct, mode("ct", 0));
  if (ct) row(name + ", ct + sinc 20", mask, ct, mode("ct", 20));
}

void table(bool real_only) {
  std::printf("%-38s %7s %6s %6s %6s %6s %6s %9s %5s %5s %9s %7s %6s %6s %6s\n", "case", "time_s", "field", "extr",
              "check", "smooth", "decim", "faces", "comps", "genus", "peak_MiB", "+MiB", "dmax", "dmean", "dmax_vx");
  for (const std::string size : {"small", "full"}) {
    if (real_only) break;
    const cf::Phantom& p = phantom(size);
    rows_for(size + " phantom", p.lumen.GetPointer(), p.ct.GetPointer());
    cf::ReconstructOptions o;
    o.target_faces = size == "full" ? 200000 : 20000;
    row(size + " phantom, decimate to " + std::to_string(o.target_faces), p.lumen.GetPointer(), nullptr, o);
  }
  const std::filesystem::path real = std::filesystem::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
  if (std::filesystem::exists(real)) rows_for("real mask a", cf::read_mask(real).GetPointer(), nullptr);
  std::printf("(peak_MiB: high-water mark during the call, mask and CT included; +MiB: above the RSS before it;\n"
              " dmax/dmean: mm to the mask's voxel boundary, dmax_vx the same in voxels)\n");
}

// ---- Close-up of a flat wall (--closeup DIR) ----

// The vertices within `radius` mm of vertex `centre`, reached through edges.
std::vector<cf::Mesh::VertexHandle> patch(const cf::Mesh& m, cf::Mesh::VertexHandle centre, double radius) {
  std::vector<cf::Mesh::VertexHandle> out;
  std::vector<char> seen(m.n_vertices(), 0);
  std::queue<cf::Mesh::VertexHandle> todo;
  todo.push(centre);
  seen[std::size_t(centre.idx())] = 1;
  const cf::Vec3 c = m.point(centre);
  while (!todo.empty()) {
    const auto v = todo.front();
    todo.pop();
    out.push_back(v);
    for (auto w : m.vv_range(v))
      if (!seen[std::size_t(w.idx())] && (m.point(w) - c).norm() <= radius) {
        seen[std::size_t(w.idx())] = 1;
        todo.push(w);
      }
  }
  return out;
}

cf::Vec3 face_normal(const cf::Mesh& m, cf::Mesh::FaceHandle f) {
  auto it = m.cfv_begin(f);
  const cf::Vec3 a = m.point(*it), b = m.point(*++it), c = m.point(*++it);
  cf::Vec3 n = OpenMesh::cross(b - a, c - a);
  const double l = n.norm();
  return l > 0 ? n / l : n;
}

// Ripple measures of a patch: RMS angle between the normals of adjacent faces (degrees), and the
// RMS height residual (mm) of a least-squares quadric z = f(x, y) in the patch's mean-normal frame.
struct Ripple {
  double dihedral_rms_deg = 0, quadric_rms_mm = 0, curvature_max_per_mm = 0;
  cf::Vec3 normal{0, 0, 0};
};
Ripple ripple(const cf::Mesh& m, const std::vector<cf::Mesh::VertexHandle>& vs, bool fit_quadric = true) {
  std::vector<char> in(m.n_vertices(), 0);
  for (auto v : vs) in[std::size_t(v.idx())] = 1;
  Ripple r;
  double sum = 0;
  std::size_t edges = 0;
  for (auto v : vs)
    for (auto h : m.voh_range(v)) {
      if (!in[std::size_t(m.to_vertex_handle(h).idx())] || m.to_vertex_handle(h).idx() < v.idx()) continue;
      const cf::Vec3 a = face_normal(m, m.face_handle(h)), b = face_normal(m, m.opposite_face_handle(h));
      const double ang = std::acos(std::clamp(double(OpenMesh::dot(a, b)), -1.0, 1.0)) * 180.0 / M_PI;
      sum += ang * ang;
      ++edges;
      r.normal += a;
    }
  r.dihedral_rms_deg = std::sqrt(sum / double(std::max<std::size_t>(edges, 1)));
  r.normal.normalize();
  if (!fit_quadric) return r;
  cf::Vec3 c(0, 0, 0);
  for (auto v : vs) c += m.point(v);
  c /= double(vs.size());
  const cf::Vec3 e1 = (std::abs(r.normal[0]) < 0.9 ? OpenMesh::cross(r.normal, cf::Vec3(1, 0, 0))
                                                     : OpenMesh::cross(r.normal, cf::Vec3(0, 1, 0))).normalized();
  const cf::Vec3 e2 = OpenMesh::cross(r.normal, e1);
  Eigen::MatrixXd A(vs.size(), 6);
  Eigen::VectorXd z(vs.size());
  for (std::size_t i = 0; i < vs.size(); ++i) {
    const cf::Vec3 d = m.point(vs[i]) - c;
    const double x = OpenMesh::dot(d, e1), y = OpenMesh::dot(d, e2);
    A.row(Eigen::Index(i)) << 1, x, y, x * x, x * y, y * y;
    z[Eigen::Index(i)] = OpenMesh::dot(d, r.normal);
  }
  const Eigen::VectorXd q = A.colPivHouseholderQr().solve(z);
  r.quadric_rms_mm = std::sqrt((A * q - z).squaredNorm() / double(vs.size()));
  r.curvature_max_per_mm = 2 * std::max({std::abs(q[3]), std::abs(q[5]), std::abs(q[4])});
  return r;
}

// Whether the straight segment a -> b stays in the lumen (sampled every 0.5 mm).
bool in_lumen(const cf::MaskImage* mask, const cf::Vec3& a, const cf::Vec3& b) {
  const int steps = int((b - a).norm() / 0.5) + 1;
  for (int i = 0; i <= steps; ++i) {
    const cf::Vec3 p = a + (b - a) * (double(i) / steps);
    cf::MaskImage::IndexType idx;
    if (!mask->TransformPhysicalPointToIndex(cf::MaskImage::PointType(p.data()), idx) || !mask->GetPixel(idx))
      return false;
  }
  return true;
}

// The flattest wall vertex (smallest quadric curvature on the smoothed surface, 12 mm patch) that
// can be seen from 20 mm inside the lumen along its normal.
cf::Mesh::VertexHandle flattest_visible(const cf::Mesh& m, const cf::MaskImage* mask) {
  cf::Mesh::VertexHandle best;
  double best_score = 1e300;
  const std::size_t stride = std::max<std::size_t>(1, m.n_vertices() / 1500);
  for (std::size_t i = 0; i < m.n_vertices(); i += stride) {
    const cf::Mesh::VertexHandle v{int(i)};
    const auto vs = patch(m, v, 12.0);
    if (vs.size() < 100) continue;
    const Ripple r = ripple(m, vs);
    const cf::Vec3 eye = m.point(v) - r.normal * 20.0;
    if (r.curvature_max_per_mm >= best_score || !in_lumen(mask, eye, m.point(v) - r.normal * 1.5)) continue;
    best_score = r.curvature_max_per_mm;
    best = v;
  }
  return best;
}

void render_closeup(const cf::Mesh& m, const cf::Vec3& centre, const cf::Vec3& normal, const std::string& png) {
  cf::TriangleList near;  // every vertex, the faces within 45 mm of the centre
  for (auto v : m.vertices()) near.points.push_back({m.point(v)[0], m.point(v)[1], m.point(v)[2]});
  for (auto f : m.faces()) {
    if ((m.point(*m.cfv_begin(f)) - centre).norm() > 45) continue;
    std::array<int, 3> ids;
    int k = 0;
    for (auto v : m.fv_range(f)) ids[k++] = v.idx();
    near.triangles.push_back(ids);
  }
  cf::SurfaceLook look;
  look.color[0] = 0.93, look.color[1] = 0.72, look.color[2] = 0.62;
  look.specular = 0.25;
  const vtkSmartPointer<vtkActor> actor = cf::surface_actor(cf::surface_polydata(near), look);
  vtkNew<vtkRenderer> ren;
  ren->AddActor(actor);
  ren->SetBackground(0, 0, 0);
  vtkNew<vtkRenderWindow> win;
  win->SetOffScreenRendering(1);
  win->AddRenderer(ren);
  win->SetSize(420, 420);
  vtkCamera* cam = ren->GetActiveCamera();
  const cf::Vec3 eye = centre - normal * 20.0;
  cam->SetPosition(eye.data());
  cam->SetFocalPoint(centre.data());
  const cf::Vec3 up = std::abs(normal[2]) < 0.9 ? cf::Vec3(0, 0, 1) : cf::Vec3(0, 1, 0);
  cam->SetViewUp(up.data());
  cam->SetViewAngle(50);
  cam->SetClippingRange(1.0, 200.0);
  ren->ResetCameraClippingRange();
  vtkNew<vtkLight> light;  // a light from the side, grazing, as an endoscope's shows relief
  light->SetLightTypeToCameraLight();
  light->SetPosition(0.6, 0.6, 1.0);
  ren->AddLight(light);
  win->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(win);
  grab->ReadFrontBufferOff();
  grab->Update();
  cf::write_png(grab->GetOutput(), png);
}

int closeup(const std::string& dir) {
  const std::filesystem::path real = std::filesystem::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";
  if (!std::filesystem::exists(real)) {
    std::fprintf(stderr, "reconstruct_bench: error: %s: missing\n", real.c_str());
    return 1;
  }
  std::filesystem::create_directories(dir);
  const cf::MaskImage::Pointer mask = cf::read_mask(real);
  const cf::Mesh smooth = cf::reconstruct_surface(mask.GetPointer(), mode("mask", 20, 0));
  const cf::Mesh::VertexHandle v = flattest_visible(smooth, mask.GetPointer());
  if (!v.is_valid()) return 1;
  const Ripple ref = ripple(smooth, patch(smooth, v, 12.0));
  const cf::Vec3 centre = smooth.point(v);
  std::printf("flat patch at LPS (%.1f, %.1f, %.1f) mm, normal (%.2f, %.2f, %.2f), 12 mm radius\n", centre[0],
              centre[1], centre[2], ref.normal[0], ref.normal[1], ref.normal[2]);
  std::printf("%-28s %12s %14s %12s %12s\n", "surface", "dihedral_deg", "quadric_rms_mm", "patch_verts",
              "whole_dihedral");
  const std::vector<std::pair<std::string, cf::ReconstructOptions>> modes = {
      {"staircase", mode("off", 0)},
      {"sinc_clamped", mode("mask", 20, 0)},
      {"default_fairing", mode("mask", 20)},
      {"fairing_300", mode("mask", 20, 300)}};
  for (const auto& [name, o] : modes) {
    cf::ReconstructStats st;
    const cf::Mesh m = cf::reconstruct_surface(mask.GetPointer(), o, &st);
    std::printf("  %s: field %.2f s total %.2f s\n", name.c_str(), st.time_field_s, st.time_total_s);
    // The same vertex: every mode but windowed sinc keeps the staircase's vertices; windowed sinc
    // keeps their order too (it moves points only).
    const auto vs = patch(m, v, 12.0);
    const Ripple r = ripple(m, vs);
    std::vector<cf::Mesh::VertexHandle> all(m.vertices_begin(), m.vertices_end());
    const Ripple whole = ripple(m, all, false);
    std::printf("%-28s %12.2f %14.3f %12zu %12.2f\n", name.c_str(), r.dihedral_rms_deg, r.quadric_rms_mm, vs.size(),
                whole.dihedral_rms_deg);
    render_closeup(m, centre, ref.normal, (std::filesystem::path(dir) / ("closeup_" + name + ".png")).string());
  }
  return 0;
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
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // rows appear as they are measured
  cf::bench::BenchCli cli("reconstruct_bench", "Reconstruction benchmark and acceptance table (see the file's header)");
  bool table_only = false, real_only = false;
  std::string closeup_dir;
  CLI::App& app = cli.app();
  app.add_flag("--table-only", table_only, "the table without Google Benchmark");
  app.add_flag("--real-only", real_only, "only the real mask's rows of the table");
  app.add_option("--closeup", closeup_dir, "write close-ups of the real mask's flattest wall patch here");
  return cli.run(argc, argv, [&] {
    if (!closeup_dir.empty()) return closeup(closeup_dir);
    table(real_only);
    return table_only || real_only ? 0 : cli.run_google_benchmarks();
  });
}
