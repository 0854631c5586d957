#pragma once
// CHOLMOD's large blocks (a colon's factor: nnz(L) row indices and values, ~0.15 + 0.3 GB) kept
// for the next factorisation when freed, and fresh ones faulted in on the worker threads.
//
// Why: glibc's malloc maps every block above its largest mmap threshold (32 MiB on 64-bit,
// DEFAULT_MMAP_THRESHOLD_MAX) fresh and unmaps it when freed, so each large factorisation's factor
// was new memory: the kernel zeroes every page at its first touch (clear_page_erms), and CHOLMOD's
// first touch is one serial loop (cholmod_change_factor writes the identity into every column, a
// write every ~300 bytes). A kept block is already resident: a factor of about the same size takes
// it without a fault. A fresh block is touched page by page on thread_count() threads, so the
// kernel's zeroing is split over the cores instead of running on the calling thread.
//
// SuiteSparse_config's malloc/calloc/realloc/free go through cholmod_block_cache()
// (install_for_cholmod()). Blocks below kKeptBlockMinBytes are plain malloc/calloc/realloc
// (advised huge pages from kHugePageMinBytes on), never kept. Thread-safe (CHOLMOD allocates from
// the factorisation's worker threads too).
#include <cstddef>
#include <mutex>
#include <unordered_map>
#include <utility>
#include <vector>

namespace cf::flat_detail {

// From this size on a block is kept when freed: glibc's largest mmap threshold (above it every
// block is a fresh mapping, faulted in anew each time).
constexpr std::size_t kKeptBlockMinBytes = std::size_t(32) << 20;
// At most this many freed blocks are kept: a simplicial numeric factor's two nnz(L)-long arrays
// (row indices, values); past it the smallest one kept is given back (CHOLMOD's workspaces of a
// few n-long columns are freed after the factor they served, and must not push the factor out).
constexpr std::size_t kKeptBlocks = 2;
// A kept block is reused for a request of at least 1 / kReuseMaxOversize of its size, so a reused
// block holds at most twice the memory asked for (a small request does not take a factor-sized
// block that the next factor then misses).
constexpr std::size_t kReuseMaxOversize = 2;

class BlockCache {
 public:
  explicit BlockCache(std::size_t min_bytes = kKeptBlockMinBytes, std::size_t max_kept = kKeptBlocks)
      : min_bytes_(min_bytes), max_kept_(max_kept) {}
  BlockCache(const BlockCache&) = delete;
  BlockCache& operator=(const BlockCache&) = delete;
  ~BlockCache() { trim(); }

  // malloc(bytes): from min_bytes on, the smallest kept block of bytes .. kReuseMaxOversize x bytes,
  // else a fresh block with every page touched (on the worker threads). nullptr when out of memory.
  void* allocate(std::size_t bytes);
  // calloc(n, size): as allocate, and zeroed (a reused block by memset on the worker threads).
  void* allocate_zeroed(std::size_t n, std::size_t size);
  // realloc(p, bytes), contents kept up to the smaller size: a large block that already holds
  // `bytes` is returned as it is; a large one that does not is moved to allocate(bytes) and kept.
  void* reallocate(void* p, std::size_t bytes);
  // free(p): a block of min_bytes or more is kept (the smallest kept given back past max_kept).
  void release(void* p);
  // Every kept block given back to the system.
  void trim();

  struct Stats {
    std::size_t reused = 0;      // large requests served by a kept block
    std::size_t fresh = 0;       // large requests served by new memory
    std::size_t kept = 0;        // blocks kept now
    std::size_t kept_bytes = 0;  // their bytes
  };
  Stats stats() const;

 private:
  void* take_kept(std::size_t bytes);  // (locked) a kept block for `bytes`, or nullptr
  void* adopt_fresh(void* p, std::size_t bytes);  // (call unlocked) a new large block: touched, recorded; nullptr as is
  const std::size_t min_bytes_, max_kept_;
  mutable std::mutex mutex_;
  std::unordered_map<void*, std::size_t> large_;     // live and kept large blocks: their sizes
  std::vector<std::pair<void*, std::size_t>> kept_;  // freed large blocks, oldest first
  std::size_t reused_ = 0, fresh_ = 0;
};

// Writes one byte in every page of [p, p + bytes) on thread_count() threads (the first touch,
// which makes the kernel map and zero the page, split over the cores).
void touch_pages(void* p, std::size_t bytes);

// The process's cache for CHOLMOD's blocks.
BlockCache& cholmod_block_cache();
// Gives cholmod_block_cache()'s kept blocks back when it goes out of scope (also by an exception):
// one at the top of flatten_colon, so the blocks serve the factorisations of one call and never
// outlive it (a caller such as the benchmark or a library user holds no factor memory after it).
struct TrimKeptBlocksAtScopeEnd {
  TrimKeptBlocksAtScopeEnd() = default;
  TrimKeptBlocksAtScopeEnd(const TrimKeptBlocksAtScopeEnd&) = delete;
  TrimKeptBlocksAtScopeEnd& operator=(const TrimKeptBlocksAtScopeEnd&) = delete;
  ~TrimKeptBlocksAtScopeEnd() { cholmod_block_cache().trim(); }
};
// Points SuiteSparse_config's allocator at cholmod_block_cache() (once; CHOLMOD builds only).
void install_for_cholmod();

}  // namespace cf::flat_detail
