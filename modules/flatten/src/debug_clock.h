#pragma once
// The flatten stage's debug timeline (COLONFLAT_FLATTEN_DEBUG=1).
#include <cstddef>
#include <vector>

namespace cf::flat_detail {

// COLONFLAT_FLATTEN_DEBUG=1: a timeline line on stderr: wall and process CPU seconds (all threads,
// getrusage) since the first call, and since the previous call (`what`: the stretch just ended),
// with the cores that stretch kept busy on average (CPU / wall) and the core-seconds left idle of
// thread_count() cores. Only on a thread inside a DebugClockScope(true) (a colon segment's, not its
// side branches' on their side thread). Thread-safe; no effect without the variable.
void debug_clock(const char* what);
// The calling thread prints debug_clock lines while this lives (`on`; "segment start" first); a
// pool worker that ran a segment prints none afterwards.
struct DebugClockScope {
  explicit DebugClockScope(bool on);
  ~DebugClockScope();
  DebugClockScope(const DebugClockScope&) = delete;
  DebugClockScope& operator=(const DebugClockScope&) = delete;
  bool was;
};

// COLONFLAT_FLATTEN_DEBUG=1: one line per band flattened (a colon segment, a side branch or a patch),
// when it is done: its depth, faces, and the calling thread's CPU seconds (wall in brackets) of each
// stretch marked (`mark(what)`: the stretch since the previous mark, or since the timer's start).
class BandTimer {
 public:
  BandTimer();
  void mark(const char* what);
  void report(int depth, std::size_t faces_in, std::size_t band_faces, std::size_t patches, std::size_t branches) const;

 private:
  struct Stretch {
    const char* what;
    double wall, cpu;
  };
  double wall0_ = 0, cpu0_ = 0;
  std::vector<Stretch> stretches_;
};

}  // namespace cf::flat_detail
