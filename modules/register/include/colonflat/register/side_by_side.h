#pragma once
// The two flat colons on one length axis (the supine one's): supine band on top, the prone wall
// resampled through the registration below it (so the same anatomy sits in the same column),
// matched candidates joined by lines, single candidates marked, a length axis in mm.
#include <vector>

#include <vtkSmartPointer.h>

#include "colonflat/register/register.h"

class vtkImageData;

namespace cf {

struct SideBySideOptions {
  double pixel_mm = 1.0;  // mm per pixel along the colon and around it (at the mean radius)
  int max_width = 4000;   // pixels; the pixel size grows when the colon would be wider
};

// Where a candidate sits in that image (pixels; row counted from the top), for clickable marks.
struct SideBySideMark {
  int id = 0;          // candidate id
  bool supine = true;  // band (supine on top, prone below)
  int x = 0, row = 0, radius = 0;
};
struct SideBySideMarks {
  int width = 0, height = 0;  // of the image
  std::vector<SideBySideMark> marks;
};
// Every candidate of both scans, as drawn. Precondition: reg.run() has completed.
SideBySideMarks side_by_side_marks(const ColonRegistration& reg, const SideBySideOptions& opts);

// RGB unsigned char image. Precondition: reg.run() has completed.
vtkSmartPointer<vtkImageData> render_side_by_side(const ColonRegistration& reg, const SideBySideOptions& opts);

}  // namespace cf
