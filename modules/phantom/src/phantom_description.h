#pragma once
// phantom.json: the case (options, geometry, colon, pools, stretches, extra anatomy, HU table).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "phantom_model.h"

namespace cf::phantom_detail {

struct VolumeCounts {
  std::size_t lumen = 0, fluid = 0;
  std::array<std::size_t, 9> by_label{};  // voxels per TruthLabel
};

// The sharp HU volume and the truth images (out.lumen, out.labels) of a label volume on grid md.g
// (identity direction); `mat` is released.
CtImage::Pointer materials_to_images(const Model& md, std::vector<unsigned char>& mat, Phantom& out, VolumeCounts& counts);
// Partial-volume blur (Gaussian, sigma blur_mm; 0 = 0.6 x in-plane spacing, >= 0.45 mm) and Gaussian
// noise (per-slice deterministic streams from `seed`), rounded to integers and clamped to [-1024, 3071].
CtImage::Pointer blur_and_noise(CtImage::Pointer sharp, double noise_hu, double blur_mm, std::uint64_t seed, const Grid& g);

nlohmann::json describe_phantom(const PhantomOptions& o, const Model& md, const VolumeCounts& counts);

}  // namespace cf::phantom_detail
