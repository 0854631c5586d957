#pragma once
// Synthetic masks for the reconstruct tests: an image of any size, spacing, origin, direction and
// region start, filled by rasterising a predicate at the voxel centres (LPS mm, ITK's own map).
#include <itkImageRegionIteratorWithIndex.h>

#include <array>
#include <functional>

#include "colonflat/reconstruct/reconstruct.h"

namespace cf::testing::masks {

using Geometry = std::function<bool(const std::array<double, 3>&)>;

struct MaskSpec {
  std::array<std::size_t, 3> size{32, 32, 32};
  std::array<double, 3> spacing{1, 1, 1};
  std::array<double, 3> origin{0, 0, 0};
  std::array<double, 9> direction{1, 0, 0, 0, 1, 0, 0, 0, 1};  // row major
  std::array<long, 3> start{0, 0, 0};
};

// An image with the geometry of `s`, zero-filled.
template <class Image = MaskImage>
typename Image::Pointer make_image(const MaskSpec& s) {
  auto m = Image::New();
  typename Image::RegionType r;
  for (int a = 0; a < 3; ++a) {
    r.SetIndex(a, s.start[a]);
    r.SetSize(a, s.size[a]);
  }
  m->SetRegions(r);
  typename Image::SpacingType sp;
  typename Image::PointType o;
  typename Image::DirectionType d;
  for (int a = 0; a < 3; ++a) {
    sp[a] = s.spacing[a];
    o[a] = s.origin[a];
    for (int c = 0; c < 3; ++c) d(a, c) = s.direction[3 * a + c];
  }
  m->SetSpacing(sp);
  m->SetOrigin(o);
  m->SetDirection(d);
  m->Allocate(true);
  return m;
}

inline MaskImage::Pointer make_mask(const MaskSpec& s) { return make_image<MaskImage>(s); }

// Sets every voxel whose centre (LPS mm, through ITK's own index->point map) satisfies `inside`.
inline MaskImage::Pointer rasterize(const MaskSpec& s, const Geometry& inside) {
  auto m = make_mask(s);
  itk::ImageRegionIteratorWithIndex<MaskImage> it(m, m->GetBufferedRegion());
  for (; !it.IsAtEnd(); ++it) {
    MaskImage::PointType p;
    m->TransformIndexToPhysicalPoint(it.GetIndex(), p);
    if (inside({p[0], p[1], p[2]})) it.Set(1);
  }
  return m;
}

}  // namespace cf::testing::masks
