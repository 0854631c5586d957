#pragma once
// The segmenter's large voxel buffers (huge-page blocks, reused while a BlockReuse is alive).
#include <cstddef>
#include <vector>

#include "colonflat/core/default_init_allocator.h"

namespace cf::segment_detail {

// Large voxel buffers (crop-sized and more): blocks of at least 4 MiB are mapped directly and
// advised for transparent huge pages, so a fresh buffer costs 1/512 of the page faults (on 2 loaded
// virtual cores the 4 KiB faults of the ~20 full-crop buffers cost about a third of the CPU time).
// While a BlockReuse is alive, a freed block is kept mapped and handed to the next request of its
// mapped size (its pages already backed: no page faults, no zeroing by the kernel); a request no kept
// block fits releases them all before mapping a new one, so kept blocks never raise the peak.
void* huge_page_alloc(std::size_t bytes);
void huge_page_free(void* p, std::size_t bytes);
class BlockReuse {
 public:
  BlockReuse();
  ~BlockReuse();  // the last open scope releases the kept blocks
  BlockReuse(const BlockReuse&) = delete;
  BlockReuse& operator=(const BlockReuse&) = delete;
};
// Bytes of freed blocks kept for reuse now (0 outside a BlockReuse scope).
std::size_t kept_block_bytes();
// Unmaps the kept blocks now (before allocations of other kinds, e.g. the heap's or ITK's).
void release_kept_blocks();
template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}
  T* allocate(std::size_t n) { return static_cast<T*>(huge_page_alloc(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) { huge_page_free(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const { return true; }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const { return false; }
};
template <class T>
using Buffer = std::vector<T, HugePageAllocator<T>>;
using Bytes = Buffer<unsigned char>;
// The same blocks, but resize(n) leaves new elements default-initialised (no value-initialising
// pass: a trivial T keeps whatever the block holds). Only for buffers whose every element is then
// written over the workers (fill_parallel, a parallel copy): a fresh block's pages are then first
// touched, faulted and zeroed by the kernel on the worker threads, not serially on the caller's.
template <class T>
using RawHugePageAllocator = DefaultInitAllocator<HugePageAllocator<T>>;  // core/default_init_allocator.h
template <class T>
using RawBuffer = std::vector<T, RawHugePageAllocator<T>>;

}  // namespace cf::segment_detail
