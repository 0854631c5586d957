#include "colonflat/core/malloc_tunables.h"

#include <unistd.h>

#include <cstdlib>

namespace cf {

namespace {
constexpr const char* kHugeTlbKey = "glibc.malloc.hugetlb";
}

std::string tunables_with_huge_page_malloc(const char* current) {
  const std::string now = current ? current : "";
  if (now.find(kHugeTlbKey) != std::string::npos) return "";
  return (now.empty() ? "" : now + ":") + kHugeTlbKey + "=1";
}

void rerun_with_huge_page_malloc(char** argv) {
  const std::string tunables = tunables_with_huge_page_malloc(std::getenv("GLIBC_TUNABLES"));
  if (tunables.empty() || !argv || !argv[0]) return;
  if (::setenv("GLIBC_TUNABLES", tunables.c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  ::unsetenv("GLIBC_TUNABLES");  // the exec failed: leave the environment as it was found
}

std::string malloc_tunables() {
  const char* t = std::getenv("GLIBC_TUNABLES");
  return t ? t : "";
}

}  // namespace cf
