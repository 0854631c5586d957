#include "colonflat/core/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace cf {
namespace {

// The whole 2 MiB pages inside [p, p + bytes): [first, last), empty when there are none or the
// block is below kHugePageMinBytes.
struct HugeRange {
  std::uintptr_t first = 0, last = 0;
};
HugeRange huge_range(const void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  if (!p || bytes < kHugePageMinBytes) return {};
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  return last > first ? HugeRange{first, last} : HugeRange{};
}

}  // namespace

void advise_huge_pages(void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  const HugeRange r = huge_range(p, bytes);
  if (r.last > r.first) ::madvise(reinterpret_cast<void*>(r.first), r.last - r.first, MADV_HUGEPAGE);  // advice only
#endif
}

void collapse_to_huge_pages(const void* p, std::size_t bytes) {
#ifndef MADV_COLLAPSE
  constexpr int MADV_COLLAPSE = 25;  // Linux 6.1 (older headers lack it; older kernels return EINVAL)
#endif
  const HugeRange r = huge_range(p, bytes);
  if (r.last > r.first) ::madvise(reinterpret_cast<void*>(r.first), r.last - r.first, MADV_COLLAPSE);  // advice only
}

}  // namespace cf
