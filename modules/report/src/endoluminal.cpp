#include "colonflat/report/endoluminal.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkStaticCellLocator.h>
#include <vtkWindowToImageFilter.h>

#include <cmath>

#include "colonflat/core/error.h"
#include "colonflat/core/vtk_messages.h"
#include "colonflat/render/snapshot.h"

namespace cf {

struct EndoluminalRenderer::Impl {
  EndoluminalOptions opts;
  TriangleList surface;
  std::vector<std::array<double, 3>> normals;
  vtkNew<vtkPolyDataMapper> mapper;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;  // one off-screen window (GL context) for every view

  // The triangles with a corner within radius_mm of `c`, compacted, with their normals.
  vtkSmartPointer<vtkPolyData> local_wall(const std::array<double, 3>& c) const;
  // Distance from `target` into the lumen (along -normal) to the first wall, at most `limit`.
  double free_distance(vtkPolyData* wall, const std::array<double, 3>& target, const std::array<double, 3>& n,
                       double limit) const;
};

vtkSmartPointer<vtkPolyData> EndoluminalRenderer::Impl::local_wall(const std::array<double, 3>& c) const {
  const double r2 = opts.radius_mm * opts.radius_mm;
  std::vector<vtkIdType> new_id(surface.points.size(), -1);
  vtkNew<vtkPoints> pts;
  vtkNew<vtkFloatArray> nrm;
  nrm->SetNumberOfComponents(3);
  nrm->SetName("Normals");
  vtkNew<vtkCellArray> polys;
  auto near = [&](int v) {
    const auto& p = surface.points[v];
    return (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]) <= r2;
  };
  auto id_of = [&](int v) {
    if (new_id[v] < 0) {
      new_id[v] = pts->InsertNextPoint(surface.points[v].data());
      const auto& n = normals.empty() ? std::array<double, 3>{0, 0, 0} : normals[v];
      // as given (consistent with the winding): two-sided lighting flips them for the back faces
      // the camera sees from inside the lumen
      nrm->InsertNextTuple3(n[0], n[1], n[2]);
    }
    return new_id[v];
  };
  for (const auto& t : surface.triangles) {
    if (!near(t[0]) && !near(t[1]) && !near(t[2])) continue;
    const vtkIdType ids[3] = {id_of(t[0]), id_of(t[1]), id_of(t[2])};
    polys->InsertNextCell(3, ids);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  if (!normals.empty()) pd->GetPointData()->SetNormals(nrm);
  return pd;
}

double EndoluminalRenderer::Impl::free_distance(vtkPolyData* wall, const std::array<double, 3>& target,
                                                const std::array<double, 3>& n, double limit) const {
  if (wall->GetNumberOfCells() == 0) return limit;
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(wall);
  locator->BuildLocator();
  double start[3], end[3], hit[3], pcoords[3], t = 0;
  int sub = 0;
  for (int k = 0; k < 3; ++k) start[k] = target[k] - n[k], end[k] = target[k] - (limit + 1) * n[k];
  if (!locator->IntersectWithLine(start, end, 1e-6, t, hit, pcoords, sub)) return limit;
  return 1.0 + t * limit;
}

EndoluminalRenderer::EndoluminalRenderer(const TriangleList& surface,
                                         const std::vector<std::array<double, 3>>& normals,
                                         const EndoluminalOptions& opts)
    : impl_((ensure_display(), std::make_unique<Impl>())) {  // a display before the window exists
  impl_->opts = opts;
  impl_->surface = surface;
  if (normals.size() == surface.points.size()) impl_->normals = normals;
  impl_->mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(impl_->mapper);
  actor->GetProperty()->SetColor(0.93, 0.64, 0.56);
  actor->GetProperty()->SetSpecular(0.25);
  actor->GetProperty()->SetSpecularPower(25);
  impl_->renderer->AddActor(actor);
  impl_->renderer->SetBackground(0.02, 0.02, 0.03);
  impl_->renderer->SetTwoSidedLighting(true);
  impl_->window->SetOffScreenRendering(1);
  impl_->window->SetMultiSamples(0);
  impl_->window->AddRenderer(impl_->renderer);
  impl_->window->SetSize(opts.size, opts.size);
}

EndoluminalRenderer::~EndoluminalRenderer() = default;

ImagePtr EndoluminalRenderer::render(const std::array<double, 3>& target, const std::array<double, 3>& normal_out,
                                     double* camera_distance_mm) {
  VtkMessageCapture msgs;
  const EndoluminalOptions& o = impl_->opts;
  vtkSmartPointer<vtkPolyData> wall = impl_->local_wall(target);
  const double free_mm = impl_->free_distance(wall, target, normal_out, o.radius_mm);
  const double d = std::max(o.min_distance_mm, std::min(o.distance_mm, 0.6 * free_mm));
  impl_->mapper->SetInputData(wall);
  double eye[3];
  for (int k = 0; k < 3; ++k) eye[k] = target[k] - d * normal_out[k];
  vtkCamera* cam = impl_->renderer->GetActiveCamera();
  cam->SetPosition(eye);
  cam->SetFocalPoint(target.data());
  // superior up unless the view is nearly vertical, then anterior up
  const bool vertical = std::abs(normal_out[2]) > 0.9;
  cam->SetViewUp(0, vertical ? -1 : 0, vertical ? 0 : 1);
  cam->OrthogonalizeViewUp();
  cam->SetViewAngle(o.view_angle_deg);
  cam->SetClippingRange(0.3, 2 * o.radius_mm + d);  // inside a tube: near walls must not be clipped
  impl_->window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(impl_->window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  if (!msgs.errors().empty()) throw Error("endoluminal rendering failed: " + msgs.errors().front());
  if (camera_distance_mm) *camera_distance_mm = d;
  ImagePtr img = ImagePtr::New();
  img->DeepCopy(grab->GetOutput());
  return img;
}

}  // namespace cf
