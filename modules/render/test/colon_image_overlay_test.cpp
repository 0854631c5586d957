// The colon image's overlay canvas (colon_image_overlay.cpp): VTK's canvas drawing in place.
#include <gtest/gtest.h>

#include <vtkImageCanvasSource2D.h>
#include <vtkImageData.h>
#include <vtkNew.h>

#include <cstddef>

#include "colonflat/core/error.h"
#include "../src/colon_image_steps.h"

namespace cf::detail {
namespace {

ImagePtr grey_image(int w, int h, int type, int components) {
  ImagePtr img = ImagePtr::New();
  img->SetExtent(0, w - 1, 0, h - 1, 0, 0);
  img->AllocateScalars(type, components);
  auto* p = static_cast<unsigned char*>(img->GetScalarPointer());
  const std::size_t bytes = std::size_t(w) * h * components * img->GetScalarSize();
  for (std::size_t i = 0; i < bytes; ++i) p[i] = 28;
  return img;
}

// A box filled on the canvas lands in the image the canvas was given, on exactly the box's pixels
// (columns 10-20, rows 5-8 from the bottom, in the draw colour) and nowhere else: the shaded bands
// need no copy into the canvas and none back out of it.
TEST(RenderOverlayCanvas, DrawsIntoTheGivenImageInPlace) {
  const int w = 64, h = 32;
  ImagePtr img = grey_image(w, h, VTK_UNSIGNED_CHAR, 3);
  vtkNew<OverlayCanvas> canvas;
  canvas->draw_on(img);
  canvas->SetDrawColor(255, 230, 0);
  canvas->FillBox(10, 20, 5, 8);
  const auto* p = static_cast<const unsigned char*>(img->GetScalarPointer());
  int in_box = 0, wrong = 0;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const unsigned char* d = p + (std::size_t(j) * w + i) * 3;
      const bool box = i >= 10 && i <= 20 && j >= 5 && j <= 8;
      const bool yellow = d[0] == 255 && d[1] == 230 && d[2] == 0;
      const bool grey = d[0] == 28 && d[1] == 28 && d[2] == 28;
      in_box += box && yellow;
      wrong += box ? !yellow : !grey;
    }
  EXPECT_EQ(in_box, 11 * 4);
  EXPECT_EQ(wrong, 0);
}

// fill_tube changes the same pixels as VTK's FillTube on a canvas over the whole image, for tubes
// along the axes, diagonal, across the image border, one pixel long and of zero length.
TEST(RenderOverlayCanvas, TubeIsVtksFillTubePixelForPixel) {
  const int w = 90, h = 50;
  const int tubes[][4] = {{10, 10, 40, 10}, {5, 40, 5, 12}, {20, 5, 70, 44}, {80, 30, 95, 48},
                          {-6, 20, 12, -3}, {33, 33, 34, 33}, {60, 25, 60, 25}};
  for (const auto& t : tubes) {
    ImagePtr mine = grey_image(w, h, VTK_UNSIGNED_CHAR, 3);
    vtkNew<OverlayCanvas> canvas;
    canvas->draw_on(mine);
    canvas->SetDrawColor(255, 230, 0);
    canvas->fill_tube(t[0], t[1], t[2], t[3], 1.3);
    vtkNew<vtkImageCanvasSource2D> vtk;
    vtk->SetScalarTypeToUnsignedChar();
    vtk->SetNumberOfScalarComponents(3);
    vtk->SetExtent(0, w - 1, 0, h - 1, 0, 0);
    vtk->SetDrawColor(28, 28, 28);
    vtk->FillBox(0, w - 1, 0, h - 1);
    vtk->SetDrawColor(255, 230, 0);
    vtk->FillTube(t[0], t[1], t[2], t[3], 1.3);
    vtk->Update();
    const auto* a = static_cast<const unsigned char*>(mine->GetScalarPointer());
    const auto* b = static_cast<const unsigned char*>(vtk->GetOutput()->GetScalarPointer());
    int drawn = 0, differ = 0;
    for (std::size_t i = 0; i < std::size_t(w) * h * 3; i += 3) drawn += b[i] == 255, differ += a[i] != b[i] || a[i + 1] != b[i + 1];
    EXPECT_EQ(differ, 0) << t[0] << "," << t[1] << " - " << t[2] << "," << t[3];
    if (t[0] != t[2] || t[1] != t[3]) EXPECT_GT(drawn, 0) << t[0] << "," << t[1] << " - " << t[2] << "," << t[3];
  }
}

// Only RGB unsigned char images are drawn on; a float image is refused with an error.
TEST(RenderOverlayCanvas, RefusesANonRgbByteImage) {
  ImagePtr img = grey_image(8, 8, VTK_FLOAT, 3);
  vtkNew<OverlayCanvas> canvas;
  EXPECT_THROW(canvas->draw_on(img), Error);
}

}  // namespace
}  // namespace cf::detail
