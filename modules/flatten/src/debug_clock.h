#pragma once
// The flatten stage's debug timeline (COLONFLAT_FLATTEN_DEBUG=1).

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

}  // namespace cf::flat_detail
