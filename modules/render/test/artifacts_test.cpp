// The render stage's PNG artifact: written at kPngCompressionLevel, read back pixel for pixel.
#include <gtest/gtest.h>

#include <vtkImageData.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "colonflat/render/artifacts.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

// A w x h RGB image of smooth gradients and a sharp-edged square, like the shaded colon image.
ImagePtr test_image(int w, int h) {
  ImagePtr img = ImagePtr::New();
  img->SetExtent(0, w - 1, 0, h - 1, 0, 0);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* p = static_cast<unsigned char*>(img->GetScalarPointer());
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      unsigned char* d = p + (std::size_t(j) * w + i) * 3;
      const bool square = i > w / 4 && i < w / 2 && j > h / 4 && j < h / 2;
      d[0] = square ? 255 : static_cast<unsigned char>(i * 255 / w);
      d[1] = static_cast<unsigned char>(j * 255 / h);
      d[2] = static_cast<unsigned char>((i + j) % 7 * 30);
    }
  return img;
}

// The FLEVEL bits of the zlib header that starts the first IDAT chunk (RFC 1950: 0 = fastest).
int zlib_level_flags(const std::string& png) {
  const std::size_t idat = png.find("IDAT");
  if (idat == std::string::npos || idat + 6 > png.size()) return -1;
  return static_cast<unsigned char>(png[idat + 5]) >> 6;
}

// write_png deflates at zlib's fastest level (the zlib header says so: vtkPNGWriter's default 5
// writes FLEVEL 1) and read_png gives back every pixel unchanged.
TEST(RenderArtifacts, PngIsWrittenFastAndReadsBackTheSamePixels) {
  testing::TempDir tmp;
  const ImagePtr img = test_image(301, 157);
  write_png(img, tmp / "image.png");
  std::ifstream in(tmp / "image.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(zlib_level_flags(bytes), 0);
  const ImagePtr back = read_png(tmp / "image.png");
  int dims[3];
  back->GetDimensions(dims);
  ASSERT_EQ(dims[0], 301);
  ASSERT_EQ(dims[1], 157);
  ASSERT_EQ(back->GetNumberOfScalarComponents(), 3);
  const auto* a = static_cast<const unsigned char*>(img->GetScalarPointer());
  const auto* b = static_cast<const unsigned char*>(back->GetScalarPointer());
  EXPECT_TRUE(std::equal(a, a + 301 * 157 * 3, b));
}

}  // namespace
}  // namespace cf
