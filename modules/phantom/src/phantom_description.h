#pragma once
// phantom.json: the case (options, geometry, colon, pools, stretches, extra anatomy, HU table).
#include <array>
#include <cstddef>

#include <nlohmann/json.hpp>

#include "phantom_model.h"

namespace cf::phantom_detail {

struct VolumeCounts {
  std::size_t lumen = 0, fluid = 0;
  std::array<std::size_t, 9> by_label{};  // voxels per TruthLabel
};

nlohmann::json describe_phantom(const PhantomOptions& o, const Model& md, const VolumeCounts& counts);

}  // namespace cf::phantom_detail
