// compact_ct / expand_ct (volume_io.h): a CT whose HU are 16-bit integers held in 16 bits while
// no stage reads it, and the float image back, voxel for voxel; compact_mask / expand_mask: a
// binary mask held in one bit per voxel.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>

#include "colonflat/core/threads.h"
#include "colonflat/volume/volume_io.h"

namespace cf {
namespace {

// An image of type Out on the grid of `in` (origin, spacing, direction, region), its header
// dictionary copied, no pixels allocated.
template <class Out, class In>
typename Out::Pointer grid_like(const In& in) {
  auto out = Out::New();
  out->CopyInformation(&in);
  out->SetRegions(in.GetLargestPossibleRegion());
  out->SetMetaDataDictionary(in.GetMetaDataDictionary());
  return out;
}

// The same with its pixels allocated.
template <class Out, class In>
typename Out::Pointer image_like(const In& in) {
  auto out = grid_like<Out>(in);
  out->Allocate();
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

std::shared_ptr<const CompactMask> compact_mask(const MaskImage& mask) {
  const std::size_t n = mask.GetLargestPossibleRegion().GetNumberOfPixels();
  const unsigned char* src = mask.GetBufferPointer();
  auto out = std::make_shared<CompactMask>();
  out->bits.resize((n + 63) / 64);
  std::atomic<bool> binary{true};
  parallel_for(out->bits.size(), [&](std::size_t b, std::size_t e) {
    bool ok = true;
    for (std::size_t w = b; w < e; ++w) {
      std::uint64_t word = 0;
      for (std::size_t i = w * 64, end = std::min(n, i + 64); i < end; ++i) {
        ok = ok && src[i] <= 1;
        word |= std::uint64_t(src[i] & 1) << (i % 64);
      }
      out->bits[w] = word;
    }
    if (!ok) binary = false;
  });
  if (!binary) return nullptr;
  out->grid = grid_like<MaskImage>(mask);
  return out;
}

MaskImage::Pointer expand_mask(const CompactMask& compact) {
  const std::size_t n = compact.grid->GetLargestPossibleRegion().GetNumberOfPixels();
  auto out = image_like<MaskImage>(*compact.grid);
  unsigned char* dst = out->GetBufferPointer();
  parallel_for(n, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) dst[i] = static_cast<unsigned char>((compact.bits[i / 64] >> (i % 64)) & 1);
  });
  return out;
}

}  // namespace cf
