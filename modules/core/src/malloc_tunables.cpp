#include "colonflat/core/malloc_tunables.h"

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <thread>

namespace cf {

namespace {
constexpr const char* kMallocPrefix = "glibc.malloc.";
// Larger than any block a stage allocates (a float CT of 512 x 512 x 1024 voxels is 1 GiB).
constexpr const char* kNoUnmapBelow = "4294967296";
}  // namespace

std::string tunables_for_colonflat(const char* current, unsigned cores) {
  const std::string now = current ? current : "";
  if (now.find(kMallocPrefix) != std::string::npos) return "";
  const std::string ours = std::string("glibc.malloc.hugetlb=1") + ":glibc.malloc.mmap_threshold=" + kNoUnmapBelow +
                           ":glibc.malloc.trim_threshold=" + kNoUnmapBelow +
                           ":glibc.malloc.arena_max=" + std::to_string(std::max(1u, cores));
  return (now.empty() ? "" : now + ":") + ours;
}

void rerun_with_malloc_tunables(char** argv) {
  const std::string tunables = tunables_for_colonflat(std::getenv("GLIBC_TUNABLES"), std::thread::hardware_concurrency());
  if (tunables.empty() || !argv || !argv[0]) return;
  if (::setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  ::unsetenv("GLIBC_TUNABLES");  // the exec failed: leave the environment as it was found
}

std::string malloc_tunables() {
  const char* t = std::getenv("GLIBC_TUNABLES");
  return t ? t : "";
}

void release_free_memory() { ::malloc_trim(0); }

}  // namespace cf
