#pragma once
// Wall-clock timing and peak resident memory, for stage reports and benchmarks.
#include <chrono>
#include <cstddef>

namespace cf {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void restart() { start_ = std::chrono::steady_clock::now(); }
  // Seconds since the start (or the last restart/lap), and the start moved to now: consecutive
  // laps split one interval without a gap.
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Peak resident set size of this process so far, in MiB (VmHWM); 0 where unknown.
double peak_memory_mib();
// Current resident set size in MiB (VmRSS); 0 where unknown.
double current_memory_mib();

}  // namespace cf
