#pragma once
// Gaussian smoothing of a large-scale field on a fine pixel grid, done on a coarser grid.
#include "colonflat/render/artifacts.h"

namespace cf {

// A 2D image (any number of double components, z extent 1) smoothed with a Gaussian of standard
// deviation `sigma_px` pixels, truncated at 2.5 sigma (vtkImageGaussianSmooth's kernel).
// Where sigma_px >= 2 * kCoarseSigmaPx the image is first averaged over f x f blocks
// (f = floor(sigma_px / kCoarseSigmaPx)), smoothed there with sigma_px / f, and interpolated back
// bilinearly between the block centres (constant beyond the outermost centres): a Gaussian of
// sigma s on a grid of spacing f costs f^3 times less, and a field smooth at scale s varies by
// O((f / s)^2) between block centres. Else the Gaussian runs on the image itself (same output as
// vtkImageGaussianSmooth). Every output pixel depends only on the input, never on the thread count.
// Pre: image has scalars of type double, dimensions w x h x 1 with w, h >= 1; sigma_px > 0.
// Post: the output has the input's dimensions, origin, spacing and component count.
ImagePtr smooth_large_scale(vtkImageData* image, double sigma_px);

// The coarse grid holds sigma / f >= this many pixels (4: the Gaussian still spans 20 coarse
// pixels, and bilinear interpolation between centres 1/4 sigma apart is within 1 % of the field).
inline constexpr double kCoarseSigmaPx = 4.0;

}  // namespace cf
