// HuCrop (hu_crop.h).
#include "hu_crop.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "colonflat/core/threads.h"

namespace cf::segment_detail {
namespace {

// Whether every one of v[0 .. n) is an integer in [-32768, 32767]; copies them to out (as int16)
// up to the first that is not.
bool copy_as_int16(const float* v, std::size_t n, std::int16_t* out) {
  for (std::size_t i = 0; i < n; ++i) {
    const float x = v[i];
    if (!(x >= -32768.0f && x <= 32767.0f) || x != std::nearbyint(x)) return false;  // NaN fails too
    out[i] = static_cast<std::int16_t>(x);
  }
  return true;
}

}  // namespace

void HuCrop::copy(const float* hu, std::size_t rows, std::size_t row_length,
                  const std::function<std::size_t(std::size_t)>& row_start) {
  RawBuffer<float>().swap(wide_);
  narrow_.resize(rows * row_length);  // not initialised: every row is written below
  std::atomic<bool> integers{true};
  parallel_for(rows, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1 && integers.load(std::memory_order_relaxed); ++r)
      if (!copy_as_int16(hu + row_start(r), row_length, narrow_.data() + r * row_length)) integers = false;
  });
  if (integers) return;
  RawBuffer<std::int16_t>().swap(narrow_);
  wide_.resize(rows * row_length);
  parallel_for(rows, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1; ++r) std::copy_n(hu + row_start(r), row_length, wide_.data() + r * row_length);
  });
}

}  // namespace cf::segment_detail
