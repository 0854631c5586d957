#include "debug_clock.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"

namespace cf::flat_detail {

namespace {
thread_local bool clock_thread = false;
}

DebugClockScope::DebugClockScope(bool on) : was(clock_thread) {
  if (!on) return;
  clock_thread = true;
  debug_clock("segment start");
}
DebugClockScope::~DebugClockScope() { clock_thread = was; }

void debug_clock(const char* what) {
  if (!clock_thread || !std::getenv("COLONFLAT_FLATTEN_DEBUG")) return;
  static std::mutex m;
  static const Stopwatch since_start;
  static const double cpu_start = process_cpu_seconds();
  static double last_wall = 0, last_cpu = 0;
  const std::lock_guard<std::mutex> lock(m);
  const double wall = since_start.seconds(), cpu = process_cpu_seconds() - cpu_start;
  const double dw = wall - last_wall, dc = cpu - last_cpu;
  std::fprintf(stderr, "flatten debug clock %s: wall %.2f s (+%.2f), process CPU %.2f s (+%.2f), cores busy %.2f, "
               "idle core-s %.2f of %d\n", what, wall, dw, cpu, dc, dw > 0 ? dc / dw : 0.0,
               std::max(0.0, thread_count() * dw - dc), thread_count());
  last_wall = wall, last_cpu = cpu;
}

}  // namespace cf::flat_detail
