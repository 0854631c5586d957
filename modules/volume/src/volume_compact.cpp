// compact_ct / expand_ct (volume_io.h): a CT whose HU are 16-bit integers held in 16 bits while
// no stage reads it, and the float image back, voxel for voxel.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "colonflat/core/threads.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

// An image of type Out on the grid of `in` (origin, spacing, direction, region), its header
// dictionary copied.
template <class Out, class In>
typename Out::Pointer image_like(const In& in) {
  auto out = Out::New();
  out->CopyInformation(&in);
  out->SetRegions(in.GetLargestPossibleRegion());
  out->Allocate();
  out->SetMetaDataDictionary(in.GetMetaDataDictionary());
  return out;
}

bool is_short(float v) {
  return v >= -32768.0f && v <= 32767.0f && std::nearbyint(v) == v;  // false for NaN too
}

}  // namespace

CompactCtImage::Pointer compact_ct(const CtImage& ct) {
  const std::size_t n = ct.GetLargestPossibleRegion().GetNumberOfPixels();
  const float* src = ct.GetBufferPointer();
  std::atomic<bool> exact{true};
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    if (!std::all_of(src + b, src + e, is_short)) exact = false;
  });
  if (!exact) return nullptr;
  auto out = image_like<CompactCtImage>(ct);
  short* dst = out->GetBufferPointer();
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) dst[i] = static_cast<short>(src[i]);
  });
  return out;
}

CtImage::Pointer expand_ct(const CompactCtImage& compact) {
  const std::size_t n = compact.GetLargestPossibleRegion().GetNumberOfPixels();
  auto out = image_like<CtImage>(compact);
  const short* src = compact.GetBufferPointer();
  float* dst = out->GetBufferPointer();
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) dst[i] = static_cast<float>(src[i]);
  });
  return out;
}

}  // namespace cf
