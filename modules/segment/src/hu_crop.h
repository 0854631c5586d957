#pragma once
// The CT in the segmenter's crop (HU, in the crop's voxel order): 16 bits per voxel when every
// voxel of the crop is an integer in [-32768, 32767], as scanners store HU (the same values in half
// the memory of float: on a 0.5 mm scan 271 MiB less at segment's peak), else float. Every read
// gives the float value, so the segmentation is the same either way.
#include <cstddef>
#include <cstdint>
#include <functional>

#include "segment_buffers.h"

namespace cf::segment_detail {

class HuCrop {
 public:
  // Copies the crop out of the full volume `hu`: `rows` rows of `row_length` voxels, the crop's row
  // r (its voxels r * row_length ..) from hu + row_start(r). 16 bits when every value is an integer
  // in range, else float (a second copy, then). Rows are copied over the workers.
  void copy(const float* hu, std::size_t rows, std::size_t row_length,
            const std::function<std::size_t(std::size_t)>& row_start);
  float operator[](std::size_t q) const { return wide_.empty() ? float(narrow_[q]) : wide_[q]; }
  std::size_t size() const { return wide_.empty() ? narrow_.size() : wide_.size(); }
  bool narrow() const { return wide_.empty(); }
  const std::int16_t* narrow_data() const { return narrow_.data(); }  // when narrow()
  const float* wide_data() const { return wide_.data(); }             // when !narrow()

 private:
  RawBuffer<std::int16_t> narrow_;
  RawBuffer<float> wide_;
};

}  // namespace cf::segment_detail
