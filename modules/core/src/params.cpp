#include "colonflat/core/params.h"

#include <cstdio>

namespace cf {

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string ParamInfo::describe() const {
  std::ostringstream s;
  s << help;
  if (!unit.empty()) s << " [" << unit << "]";
  s << " (default " << (default_text.empty() ? "''" : default_text);
  const bool has_min = min && std::isfinite(*min) && *min > -2147483648.0;
  const bool has_max = max && std::isfinite(*max) && *max < 2147483647.0;
  if (has_min || has_max)
    s << "; range [" << (has_min ? format_number(*min) : "-inf") << ", " << (has_max ? format_number(*max) : "inf")
      << "]";
  s << ")";
  return s.str();
}

}  // namespace cf
