#include "debug_clock.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

#include <time.h>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/threads.h"

namespace cf::flat_detail {

namespace {
thread_local bool clock_thread = false;

// Wall seconds (steady clock) and CPU seconds of the calling thread.
double wall_now() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double thread_cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
}  // namespace

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

BandTimer::BandTimer() : wall0_(wall_now()), cpu0_(thread_cpu_now()) {}

void BandTimer::mark(const char* what) {
  const double wall = wall_now(), cpu = thread_cpu_now();
  stretches_.push_back({what, wall - wall0_, cpu - cpu0_});
  wall0_ = wall, cpu0_ = cpu;
}

void BandTimer::report(int depth, std::size_t faces_in, std::size_t band_faces, std::size_t patches,
                       std::size_t branches) const {
  if (!std::getenv("COLONFLAT_FLATTEN_DEBUG")) return;
  std::string line = "flatten debug band time: depth " + std::to_string(depth) + ", " + std::to_string(faces_in) +
                     " faces in, " + std::to_string(band_faces) + " in the band, " + std::to_string(patches) +
                     " patches, " + std::to_string(branches) + " branches; thread CPU s (wall):";
  char buf[160];
  for (const Stretch& s : stretches_) {
    std::snprintf(buf, sizeof buf, " %s %.3f (%.3f);", s.what, s.cpu, s.wall);
    line += buf;
  }
  std::fprintf(stderr, "%s\n", line.c_str());
}

}  // namespace cf::flat_detail
