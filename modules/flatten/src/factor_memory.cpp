// CHOLMOD's large blocks kept between factorisations, fresh ones faulted in on the worker threads
// (see factor_memory.h).
#include "factor_memory.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "colonflat/core/huge_pages.h"
#include "colonflat/core/threads.h"

#ifdef COLONFLAT_HAVE_CHOLMOD
#include <cholmod.h>
#endif

namespace cf::flat_detail {

namespace {

std::size_t page_bytes() {
  static const std::size_t bytes = [] {
    const long p = sysconf(_SC_PAGESIZE);
    return p > 0 ? std::size_t(p) : std::size_t(4096);
  }();
  return bytes;
}

void* advised(void* p, std::size_t bytes) {
  if (p && bytes >= kHugePageMinBytes) advise_huge_pages(p, bytes);
  return p;
}

// memset(p, 0, bytes) on the worker threads (contiguous chunks: the same bytes for any count).
void zero_on_threads(void* p, std::size_t bytes) {
  char* c = static_cast<char*>(p);
  parallel_for(bytes, [c](std::size_t begin, std::size_t end) { std::memset(c + begin, 0, end - begin); });
}

}  // namespace

void touch_pages(void* p, std::size_t bytes) {
  const std::size_t page = page_bytes(), pages = (bytes + page - 1) / page;
  volatile char* c = static_cast<volatile char*>(p);
  parallel_for(pages, [c, page](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) c[k * page] = 0;
  });
}

void* BlockCache::take_kept(std::size_t bytes) {
  std::size_t best = kept_.size();
  for (std::size_t k = 0; k < kept_.size(); ++k) {
    const std::size_t size = kept_[k].second;
    if (size >= bytes && size / kReuseMaxOversize <= bytes && (best == kept_.size() || size < kept_[best].second))
      best = k;
  }
  if (best == kept_.size()) return nullptr;
  void* p = kept_[best].first;
  kept_.erase(kept_.begin() + std::ptrdiff_t(best));
  ++reused_;
  return p;
}

void* BlockCache::adopt_fresh(void* p, std::size_t bytes) {
  if (!p) return nullptr;
  touch_pages(p, bytes);  // faulted in here, on the worker threads
  std::lock_guard<std::mutex> lock(mutex_);
  large_[p] = bytes;
  ++fresh_;
  return p;
}

void* BlockCache::allocate(std::size_t bytes) {
  if (bytes < min_bytes_) return advised(std::malloc(bytes), bytes);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (void* p = take_kept(bytes)) return p;
  }
  return adopt_fresh(advised(std::malloc(bytes), bytes), bytes);
}

void* BlockCache::allocate_zeroed(std::size_t n, std::size_t size) {
  if (size != 0 && n > std::numeric_limits<std::size_t>::max() / size) return nullptr;
  const std::size_t bytes = n * size;
  if (bytes < min_bytes_) return advised(std::calloc(n, size), bytes);
  void* p = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    p = take_kept(bytes);
  }
  if (p) {
    zero_on_threads(p, bytes);
    return p;
  }
  return adopt_fresh(advised(std::calloc(n, size), bytes), bytes);  // fresh pages read as zero
}

void* BlockCache::reallocate(void* p, std::size_t bytes) {
  if (!p) return allocate(bytes);
  std::size_t size = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = large_.find(p);
    if (it == large_.end()) return advised(std::realloc(p, bytes), bytes);  // a small block: as malloc does
    size = it->second;
  }
  if (bytes <= size) return p;
  void* q = std::realloc(p, bytes);  // glibc moves a mapping's pages (mremap) instead of copying them
  if (!q) return nullptr;            // p is left as it was (realloc's contract)
  advised(q, bytes);
  touch_pages(static_cast<char*>(q) + size, bytes - size);
  std::lock_guard<std::mutex> lock(mutex_);
  large_.erase(p);
  large_[q] = bytes;
  return q;
}

void BlockCache::release(void* p) {
  if (!p) return;
  std::vector<void*> given_back;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = large_.find(p);
    if (it == large_.end()) {
      given_back.push_back(p);
    } else {
      kept_.emplace_back(p, it->second);
      while (kept_.size() > max_kept_) {  // the smallest given back: a large block costs the most to fault in again
        const auto smallest = std::min_element(kept_.begin(), kept_.end(),
                                               [](const auto& a, const auto& b) { return a.second < b.second; });
        given_back.push_back(smallest->first);
        large_.erase(smallest->first);
        kept_.erase(smallest);
      }
    }
  }
  for (void* q : given_back) std::free(q);
}

void BlockCache::trim() {
  std::vector<std::pair<void*, std::size_t>> kept;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    kept.swap(kept_);
    for (const auto& k : kept) large_.erase(k.first);
  }
  for (const auto& k : kept) std::free(k.first);
}

BlockCache::Stats BlockCache::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Stats s;
  s.reused = reused_;
  s.fresh = fresh_;
  s.kept = kept_.size();
  for (const auto& k : kept_) s.kept_bytes += k.second;
  return s;
}

BlockCache& cholmod_block_cache() {
  static BlockCache* cache = new BlockCache();  // never destroyed: CHOLMOD may free during exit
  return *cache;
}

#ifdef COLONFLAT_HAVE_CHOLMOD
namespace {
void* cache_malloc(std::size_t bytes) { return cholmod_block_cache().allocate(bytes); }
void* cache_calloc(std::size_t n, std::size_t size) { return cholmod_block_cache().allocate_zeroed(n, size); }
void* cache_realloc(void* p, std::size_t bytes) { return cholmod_block_cache().reallocate(p, bytes); }
void cache_free(void* p) { cholmod_block_cache().release(p); }
}  // namespace

void install_for_cholmod() {
  static std::once_flag once;
  std::call_once(once, [] {
    SuiteSparse_config.malloc_func = cache_malloc;
    SuiteSparse_config.calloc_func = cache_calloc;
    SuiteSparse_config.realloc_func = cache_realloc;
    SuiteSparse_config.free_func = cache_free;
  });
}
#else
void install_for_cholmod() {}
#endif

}  // namespace cf::flat_detail
