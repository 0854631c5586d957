#pragma once
// The number of worker threads every stage may use, and the two ways the stages split work over
// them. One process-wide setting: `--threads N` of every command (and `colonflat run`) sets it;
// the default is every core the machine offers (std::thread::hardware_concurrency()), or the
// environment variable COLONFLAT_THREADS when it holds a positive integer.
//
// Contract for callers: results must not depend on the thread count. Split work so that each
// piece is computed the same way whoever computes it, and combine pieces in a fixed order
// (index order), never in completion order.
#include <cstddef>
#include <functional>
#include <vector>

namespace cf {

// Worker threads to use, >= 1.
int thread_count();
// Sets the count; n <= 0 restores the default (all cores / COLONFLAT_THREADS). The libraries'
// own thread pools follow it too (VTK's SMP tools and threaded image filters here; ITK's once
// its module registered a listener), so that --threads N bounds every pool of the process, not
// only ColonFlat's own (a cohort scheduler's `threads:` is then obeyed).
void set_thread_count(int n);
// Called with the new thread_count() by every set_thread_count(), and once at registration.
// For libraries core does not link (ITK: volume_io.h's itk_follows_thread_count()).
using ThreadCountListener = void (*)(int threads);
void add_thread_count_listener(ThreadCountListener listener);
// The default the machine gives (>= 1): COLONFLAT_THREADS if set and positive, else all cores.
int default_thread_count();

// Calls body(begin, end) on contiguous chunks covering [0, n), one chunk per thread (at most
// min(thread_count(), max_threads) threads; fewer when n is small). Chunk c is
// [n*c/T, n*(c+1)/T). The calling thread runs chunk 0. An exception thrown by any chunk is
// rethrown here after all chunks finished (the first one by chunk index).
void parallel_for(std::size_t n, const std::function<void(std::size_t begin, std::size_t end)>& body,
                  int max_threads = 1 << 30);

// Calls body(i) for every i in [0, n) on up to min(thread_count(), max_threads, n) threads, each
// taking the next unclaimed index (the calling thread takes index 0 first). For work cut into more
// pieces than threads whose results do not depend on who computes them (face_blocks.h's fixed
// blocks): a thread that starts late (its core busy) takes fewer pieces instead of leaving the
// caller waiting for a fixed share. Exceptions as in parallel_for (the first by index).
void parallel_indices(std::size_t n, const std::function<void(std::size_t i)>& body, int max_threads = 1 << 30);

// Runs every task, on up to thread_count() threads (tasks are taken in index order; the caller
// runs some of them). Exceptions as in parallel_for (the first by task index).
void parallel_tasks(const std::vector<std::function<void()>>& tasks);

// User + system CPU seconds of this process so far, all threads (getrusage). CPU over wall time
// of a stretch of work is the number of cores it kept busy (stage reports record both).
double process_cpu_seconds();

}  // namespace cf
