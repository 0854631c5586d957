#pragma once
// Large scratch arrays on transparent huge pages (2 MiB) where the system allows them
// (/sys/kernel/mm/transparent_hugepage/enabled = madvise or always): a fresh 2 MiB page costs one
// page fault instead of 512, and page faults are among the largest costs of whole-mesh passes on
// virtual machines (denoise: 78 K faults for a 1.56 M-face surface). Advice only: without
// transparent huge pages nothing changes. Small arrays (below kHugePageMinBytes) are left alone.
#include <cstddef>
#include <vector>

namespace cf {

constexpr std::size_t kHugePageMinBytes = std::size_t(4) << 20;

// Advises huge pages for the whole 2 MiB pages inside [p, p + bytes) (bytes >= kHugePageMinBytes).
// Call before the memory is first written.
void advise_huge_pages(void* p, std::size_t bytes);

// Moves the whole 2 MiB pages inside [p, p + bytes) of memory already written onto huge pages
// now (MADV_COLLAPSE, Linux 6.1 and later; elsewhere nothing happens). For arrays that another
// library filled and that are then read at random for a long time: a huge page covers 512
// small pages' translations, so random reads miss the TLB far less.
void collapse_to_huge_pages(const void* p, std::size_t bytes);

// v.reserve(n), with the new block advised before anything is written to it.
template <class T>
void reserve_huge(std::vector<T>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  std::vector<T> fresh;
  fresh.reserve(n);
  advise_huge_pages(fresh.data(), n * sizeof(T));
  fresh.insert(fresh.end(), v.begin(), v.end());
  v.swap(fresh);
}

// v.assign(n, value) / v.resize(n) on a reserve_huge() block.
template <class T>
void assign_huge(std::vector<T>& v, std::size_t n, const T& value) {
  if (v.capacity() < n) std::vector<T>().swap(v);  // nothing to keep
  reserve_huge(v, n);
  v.assign(n, value);
}
template <class T>
void resize_huge(std::vector<T>& v, std::size_t n) {
  reserve_huge(v, n);
  v.resize(n);
}

}  // namespace cf
