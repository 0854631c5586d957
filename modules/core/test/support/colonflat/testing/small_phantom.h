#pragma once
// The small phantom of a seed, generated once per test process (for tests linking the phantom
// module).
#include <cstdint>
#include <map>
#include <utility>

#include "colonflat/phantom/phantom.h"

namespace cf::testing {

inline const Phantom& small_phantom(std::uint64_t seed = 1, bool collapsed = false) {
  static std::map<std::pair<std::uint64_t, bool>, Phantom> cache;
  const auto key = std::make_pair(seed, collapsed);
  auto it = cache.find(key);
  if (it == cache.end()) {
    PhantomOptions o;
    o.size = "small";
    o.seed = seed;
    o.collapsed_segment = collapsed;
    it = cache.emplace(key, generate_phantom(o)).first;
  }
  return it->second;
}

}  // namespace cf::testing
