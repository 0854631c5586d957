#pragma once
// The message of the cf::Error a call throws ("" when it throws none).
#include <functional>
#include <string>

#include "colonflat/core/error.h"

namespace cf::testing {

inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace cf::testing
