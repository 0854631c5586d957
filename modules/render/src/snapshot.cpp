#include "colonflat/render/snapshot.h"

#include "colonflat/render/colon_image.h"
#include "colonflat/core/vtk_convert.h"

#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkRenderingOpenGL2);
VTK_MODULE_INIT(vtkRenderingFreeType);

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkPointData.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkIdList.h>
#include <vtkTubeFilter.h>
#include <vtkWindowToImageFilter.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <vector>

#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/vertex_corners.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {
namespace {

pid_t g_xvfb = -1;

void stop_xvfb() {
  if (g_xvfb > 0) {
    kill(g_xvfb, SIGTERM);
    waitpid(g_xvfb, nullptr, 0);
    g_xvfb = -1;
  }
}

std::string start_xvfb() {
  int fds[2];
  if (pipe(fds) != 0) throw Error("cannot start Xvfb: pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw Error("cannot start Xvfb: fork failed");
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    close(fds[0]);
    const int devnull = open("/dev/null", O_RDWR);
    if (devnull >= 0) dup2(devnull, 1), dup2(devnull, 2);
    const std::string fd = std::to_string(fds[1]);
    execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1600x1200x24", "-nolisten", "tcp",
           "-noreset", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  std::string num;
  pollfd p{fds[0], POLLIN, 0};
  for (int waited = 0; waited < 15000;) {
    if (poll(&p, 1, 250) > 0) {
      char buf[32];
      const ssize_t n = read(fds[0], buf, sizeof buf);
      if (n <= 0) break;
      num.append(buf, buf + n);
      if (num.find('\n') != std::string::npos) break;
    } else {
      waited += 250;
      int st;
      if (waitpid(pid, &st, WNOHANG) == pid) break;
    }
  }
  close(fds[0]);
  while (!num.empty() && (num.back() == '\n' || num.back() == ' ')) num.pop_back();
  if (num.empty()) {
    kill(pid, SIGTERM);
    waitpid(pid, nullptr, 0);
    throw Error("3D snapshots need an X display: DISPLAY is not set and Xvfb could not be started "
                "(install xvfb or run under xvfb-run)");
  }
  g_xvfb = pid;
  std::atexit(stop_xvfb);
  return ":" + num;
}

}  // namespace

std::string ensure_display() {
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  const char* d = std::getenv("DISPLAY");
  if (d && *d) return d;
  const std::string disp = start_xvfb();
  setenv("DISPLAY", disp.c_str(), 1);
  return disp;
}

namespace {

// #P points as a double array (#P x 3); at(i) gives point i's 3 coordinates. Rows split over the threads.
template <class PointAt>
vtkSmartPointer<vtkDoubleArray> point_array(std::size_t P, const PointAt& at) {
  auto xyz = vtkSmartPointer<vtkDoubleArray>::New();
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(vtkIdType(P));
  double* x = xyz->GetPointer(0);
  parallel_for(P, [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) std::copy(at(i), at(i) + 3, x + 3 * i);
  });
  return xyz;
}

// Points and triangles as a vtkPolyData (one triangle = 3 ids, fixed-size cell storage), the ids
// copied in bulk, rows split over the threads.
vtkSmartPointer<vtkPolyData> polydata_of(vtkDoubleArray* xyz, const std::vector<std::array<int, 3>>& triangles) {
  const std::size_t T = triangles.size();
  vtkNew<vtkIdTypeArray> ids;
  ids->SetNumberOfValues(vtkIdType(3 * T));
  vtkIdType* c = ids->GetPointer(0);
  parallel_for(T, [&](std::size_t t0, std::size_t t1) {
    for (std::size_t t = t0; t < t1; ++t) std::copy(triangles[t].begin(), triangles[t].end(), c + 3 * t);
  });
  vtkNew<vtkPoints> pts;
  pts->SetData(xyz);
  vtkNew<vtkCellArray> polys;
  polys->SetData(3, ids);
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

// Unit normal of triangle t over the points xyz (#P x 3; zero when degenerate).
std::array<double, 3> face_normal(const double* xyz, const std::array<int, 3>& t) {
  const double* p0 = xyz + 3 * std::size_t(t[0]);
  const double* p1 = xyz + 3 * std::size_t(t[1]);
  const double* p2 = xyz + 3 * std::size_t(t[2]);
  const double a[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, b[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  std::array<double, 3> n{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (l > 0) n[0] /= l, n[1] /= l, n[2] /= l;
  return n;
}

// smooth_point_normals over the points xyz (#P x 3) and the triangles.
vtkSmartPointer<vtkFloatArray> point_normals(const double* xyz, std::size_t P, const std::vector<std::array<int, 3>>& tris) {
  std::vector<std::array<double, 3>> fn(tris.size());
  parallel_for(tris.size(), [&](std::size_t t0, std::size_t t1) {
    for (std::size_t t = t0; t < t1; ++t) fn[t] = face_normal(xyz, tris[t]);
  });
  const VertexCorners corners = vertex_corners(tris, P);
  auto normals = vtkSmartPointer<vtkFloatArray>::New();
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(vtkIdType(P));
  float* out = normals->GetPointer(0);
  parallel_for(P, [&](std::size_t v0, std::size_t v1) {
    for (std::size_t v = v0; v < v1; ++v) {
      double n[3] = {0, 0, 0};
      for (const std::uint32_t* c = corners.begin(v); c != corners.begin(v) + corners.degree(v); ++c)
        for (int k = 0; k < 3; ++k) n[k] += fn[*c / 3][k];
      const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int k = 0; k < 3; ++k) out[3 * v + k] = float(l > 0 ? n[k] / l : 0.0);
    }
  });
  return normals;
}

}  // namespace

vtkSmartPointer<vtkPolyData> surface_polydata(const TriangleList& surface) {
  return triangles_to_polydata(surface);
}

vtkSmartPointer<vtkFloatArray> smooth_point_normals(const TriangleList& surface) {
  static_assert(sizeof(std::array<double, 3>) == 3 * sizeof(double), "points are packed");
  return point_normals(surface.points.empty() ? nullptr : surface.points.front().data(), surface.points.size(),
                       surface.triangles);
}

vtkSmartPointer<vtkPolyData> lit_surface_polydata(const TriangleList& surface) {
  vtkSmartPointer<vtkPolyData> pd = surface_polydata(surface);
  pd->GetPointData()->SetNormals(smooth_point_normals(surface));
  return pd;
}

vtkSmartPointer<vtkPolyData> lit_surface_polydata(const Mesh& mesh) {
  if (has_deleted_elements(mesh)) return lit_surface_polydata(to_triangle_list(mesh));
  const std::vector<std::array<int, 3>> tris = mesh_triangles(mesh);
  vtkSmartPointer<vtkDoubleArray> xyz =
      point_array(mesh.n_vertices(), [&](std::size_t i) { return mesh.point(Mesh::VertexHandle(int(i))).data(); });
  vtkSmartPointer<vtkPolyData> pd = polydata_of(xyz, tris);
  pd->GetPointData()->SetNormals(point_normals(xyz->GetPointer(0), mesh.n_vertices(), tris));
  return pd;
}

vtkSmartPointer<vtkActor> surface_actor(vtkPolyData* surface, const SurfaceLook& look) {
  vtkNew<vtkPolyDataMapper> mapper;
  if (surface->GetPointData()->GetNormals()) {
    mapper->SetInputData(surface);
  } else {
    vtkNew<vtkPolyDataNormals> normals;
    normals->SetInputData(surface);
    normals->SplittingOff();
    normals->ConsistencyOff();
    mapper->SetInputConnection(normals->GetOutputPort());
  }
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(look.color[0], look.color[1], look.color[2]);
  actor->GetProperty()->SetSpecular(look.specular);
  actor->GetProperty()->SetSpecularPower(look.specular_power);
  return actor;
}

namespace {

// render_snapshot() as named steps: the scene (surface, loops as tubes with a ball around each),
// the camera, and the off-screen grab.
class SnapshotScene {
 public:
  SnapshotScene(vtkSmartPointer<vtkPolyData> lit_surface, vtkPolyData* loops, const SnapshotOptions& opts)
      : surface_(std::move(lit_surface)), loops_(loops), opts_(opts) {}
  ImagePtr run();

 private:
  void add_surface();
  void add_loop_tubes();
  void add_loop_balls();
  void place_camera();
  ImagePtr grab();

  VtkMessageCapture messages_;
  vtkSmartPointer<vtkPolyData> surface_;
  vtkPolyData* loops_;  // may be null
  const SnapshotOptions& opts_;
  vtkNew<vtkRenderer> renderer_;
  vtkNew<vtkRenderWindow> window_;
  vtkSmartPointer<vtkActor> surface_actor_;
  double bounds_[6] = {0, 0, 0, 0, 0, 0};
  double diagonal_ = 0;  // of the surface's bounding box (mm)
};

ImagePtr SnapshotScene::run() {
  add_surface();
  if (loops_ && loops_->GetNumberOfPoints() > 0) {
    surface_actor_->GetProperty()->SetOpacity(0.55);
    add_loop_tubes();
    add_loop_balls();
  }
  window_->SetOffScreenRendering(1);
  window_->SetMultiSamples(0);
  window_->AddRenderer(renderer_);
  window_->SetSize(opts_.width, opts_.height);
  place_camera();
  return grab();
}

// The surface in skin colour over a dark gradient; its bounding box sizes the rest.
void SnapshotScene::add_surface() {
  surface_actor_ = surface_actor(surface_, SurfaceLook{});
  renderer_->AddActor(surface_actor_);
  renderer_->SetBackground(0.12, 0.13, 0.16);
  renderer_->SetBackground2(0.3, 0.32, 0.38);
  renderer_->GradientBackgroundOn();
  surface_->GetBounds(bounds_);
  const double* b = bounds_;
  diagonal_ = std::sqrt((b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
}

// The loops as tubes: handles red, tunnels blue (cell data "type"), else orange.
void SnapshotScene::add_loop_tubes() {
  vtkNew<vtkTubeFilter> tubes;
  tubes->SetInputData(loops_);
  tubes->SetRadius(std::max(0.8, diagonal_ / 250));
  tubes->SetNumberOfSides(10);
  vtkNew<vtkPolyDataMapper> lm;
  lm->SetInputConnection(tubes->GetOutputPort());
  vtkNew<vtkLookupTable> lut;
  lut->SetNumberOfTableValues(2);
  lut->SetTableValue(0, 0.95, 0.15, 0.1, 1);  // handle
  lut->SetTableValue(1, 0.15, 0.45, 1.0, 1);  // tunnel
  lut->SetTableRange(0, 1);
  lut->Build();
  if (loops_->GetCellData()->GetArray("type")) {
    lm->SetScalarModeToUseCellFieldData();
    lm->SelectColorArray("type");
    lm->SetLookupTable(lut);
    lm->SetScalarRange(0, 1);
    lm->ScalarVisibilityOn();
  } else {
    lm->ScalarVisibilityOff();
  }
  vtkNew<vtkActor> la;
  la->SetMapper(lm);
  la->GetProperty()->SetColor(1.0, 0.55, 0.0);
  renderer_->AddActor(la);
}

// Loops are often a few mm long: a translucent ball around each makes it findable.
void SnapshotScene::add_loop_balls() {
  vtkDataArray* type = loops_->GetCellData()->GetArray("type");
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < loops_->GetNumberOfCells(); ++c) {
    loops_->GetCellPoints(c, ids);
    if (ids->GetNumberOfIds() == 0) continue;
    double m[3] = {0, 0, 0};
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
      double q[3];
      loops_->GetPoint(ids->GetId(k), q);
      for (int d = 0; d < 3; ++d) m[d] += q[d] / double(ids->GetNumberOfIds());
    }
    vtkNew<vtkSphereSource> ball;
    ball->SetCenter(m);
    ball->SetRadius(std::max(4.0, diagonal_ / 70));
    ball->SetThetaResolution(24);
    ball->SetPhiResolution(16);
    vtkNew<vtkPolyDataMapper> bm;
    bm->SetInputConnection(ball->GetOutputPort());
    vtkNew<vtkActor> ba;
    ba->SetMapper(bm);
    const bool tunnel = type && type->GetTuple1(c) > 0.5;
    if (tunnel) ba->GetProperty()->SetColor(0.2, 0.5, 1.0);
    else ba->GetProperty()->SetColor(1.0, 0.2, 0.1);
    ba->GetProperty()->SetOpacity(0.45);
    renderer_->AddActor(ba);
  }
}

// Looking at the box centre from the front (anterior, LPS -y) or the patient's left (+x),
// superior up, the whole surface in view.
void SnapshotScene::place_camera() {
  const double* b = bounds_;
  vtkCamera* cam = renderer_->GetActiveCamera();
  const double c[3] = {0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])};
  cam->SetFocalPoint(c);
  if (opts_.view == "left") cam->SetPosition(c[0] + diagonal_, c[1], c[2]);
  else cam->SetPosition(c[0], c[1] - diagonal_, c[2]);  // anterior: LPS -y
  cam->SetViewUp(0, 0, 1);                                 // superior: LPS +z
  renderer_->ResetCamera();
  cam->Zoom(1.15);
}

ImagePtr SnapshotScene::grab() {
  window_->Render();
  vtkNew<vtkWindowToImageFilter> grabber;
  grabber->SetInput(window_);
  grabber->SetInputBufferTypeToRGB();
  grabber->ReadFrontBufferOff();
  grabber->Update();
  if (!messages_.errors().empty()) throw Error("off-screen rendering failed: " + messages_.errors().front());
  ImagePtr img = ImagePtr::New();
  img->DeepCopy(grabber->GetOutput());
  return img;
}

}  // namespace

namespace {
ImagePtr render_lit_snapshot(vtkSmartPointer<vtkPolyData> lit_surface, vtkPolyData* loops, const SnapshotOptions& o) {
  ensure_display();
  ImagePtr img = SnapshotScene(std::move(lit_surface), loops, o).run();
  caption_snapshot(img, o.caption);
  return img;
}
}  // namespace

ImagePtr render_snapshot(const TriangleList& surface, vtkPolyData* loops, const SnapshotOptions& o) {
  return render_lit_snapshot(lit_surface_polydata(surface), loops, o);
}

ImagePtr render_snapshot(const Mesh& surface, vtkPolyData* loops, const SnapshotOptions& o) {
  return render_lit_snapshot(lit_surface_polydata(surface), loops, o);
}

void caption_snapshot(vtkImageData* snapshot, const std::string& caption) {
  static const double white[3] = {1, 1, 1};
  if (!caption.empty()) draw_text(snapshot, caption, 12, 12, 20, white);
}

}  // namespace cf
