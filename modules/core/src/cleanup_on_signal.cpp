// Removing temporaries when the process is interrupted. A signal handler may only call
// async-signal-safe functions, so the paths live in a fixed table of C strings and the handler
// calls unlink()/rmdir() on them, then re-raises the signal with its default action.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <mutex>

#include "colonflat/core/atomic_file.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr std::size_t kSlots = 512;
constexpr std::size_t kPathMax = 4096;

struct Slot {
  std::atomic<bool> used{false};
  char path[kPathMax];
};
Slot g_slots[kSlots];
std::mutex g_mutex;

void cleanup_handler(int sig) {
  // Files first (in any order), then folders deepest-last registration first (rmdir of a
  // non-empty folder just fails).
  for (std::size_t i = 0; i < kSlots; ++i)
    if (g_slots[i].used.load()) ::unlink(g_slots[i].path);
  for (std::size_t i = kSlots; i-- > 0;)
    if (g_slots[i].used.load()) ::rmdir(g_slots[i].path);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void install_handlers_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      ::sigaction(sig, nullptr, &old);
      if (old.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
      struct sigaction sa {};
      sa.sa_handler = cleanup_handler;
      sigemptyset(&sa.sa_mask);
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

}  // namespace

void register_for_cleanup(const fs::path& path) {
  install_handlers_once();
  const std::string s = fs::absolute(path).string();
  if (s.size() + 1 > kPathMax) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  for (auto& slot : g_slots) {
    if (slot.used.load()) continue;
    std::memcpy(slot.path, s.c_str(), s.size() + 1);
    slot.used.store(true);
    return;
  }
}

void unregister_for_cleanup(const fs::path& path) {
  const std::string s = fs::absolute(path).string();
  std::lock_guard<std::mutex> lock(g_mutex);
  for (auto& slot : g_slots)
    if (slot.used.load() && s == slot.path) {
      slot.used.store(false);
      return;
    }
}

}  // namespace cf
