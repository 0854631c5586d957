#include "colonflat/report/endoluminal.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
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
  vtkNew<vtkPolyData> surface;
  vtkNew<vtkStaticCellLocator> locator;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;
};

namespace {

vtkSmartPointer<vtkPolyData> to_polydata(const TriangleList& s, const std::vector<std::array<double, 3>>& normals) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const auto& p : s.points) pts->InsertNextPoint(p.data());
  vtkNew<vtkCellArray> polys;
  for (const auto& t : s.triangles) {
    const vtkIdType c[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, c);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  if (normals.size() == s.points.size()) {
    vtkNew<vtkDoubleArray> n;
    n->SetNumberOfComponents(3);
    n->SetName("Normals");
    // the lumen side is what the camera sees: shade with normals pointing into the lumen
    for (const auto& v : normals) n->InsertNextTuple3(-v[0], -v[1], -v[2]);
    pd->GetPointData()->SetNormals(n);
  }
  return pd;
}

}  // namespace

EndoluminalRenderer::EndoluminalRenderer(const TriangleList& surface,
                                         const std::vector<std::array<double, 3>>& normals,
                                         const EndoluminalOptions& opts)
    : impl_(std::make_unique<Impl>()) {
  ensure_display();
  impl_->opts = opts;
  impl_->surface->ShallowCopy(to_polydata(surface, normals));
  impl_->locator->SetDataSet(impl_->surface);
  impl_->locator->BuildLocator();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(impl_->surface);
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.93, 0.64, 0.56);
  actor->GetProperty()->SetSpecular(0.25);
  actor->GetProperty()->SetSpecularPower(25);
  actor->GetProperty()->BackfaceCullingOff();
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
  // free distance into the lumen: first wall hit along -normal
  double start[3], end[3], hit[3], pcoords[3], t = 0;
  int sub = 0;
  for (int k = 0; k < 3; ++k) start[k] = target[k] - 1.0 * normal_out[k], end[k] = target[k] - 250.0 * normal_out[k];
  double free_mm = 250;
  if (impl_->locator->IntersectWithLine(start, end, 1e-6, t, hit, pcoords, sub))
    free_mm = 1.0 + t * 249.0;
  const double d = std::max(o.min_distance_mm, std::min(o.distance_mm, 0.6 * free_mm));
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
  cam->SetClippingRange(0.3, 400);  // inside a closed tube: near walls must not be clipped
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
