#pragma once
// Internal to the denoise module: whether the environment variable COLONFLAT_DENOISE_DEBUG is
// set (docs/denoise.md: one stderr line per cut, per costly surgery, per restricted
// triangulation of >= 48 vertices, per failed collar / front step, per homology build and per
// part of the set-up). The one place that reads
// it; read once per process (setting it after the first denoise call has no effect).
#include <cstdlib>

namespace cf::detail {

inline bool denoise_debug() {
  static const bool on = std::getenv("COLONFLAT_DENOISE_DEBUG") != nullptr;
  return on;
}

}  // namespace cf::detail
