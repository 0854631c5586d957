#pragma once
// Per-face loops of the flatten stage on every worker thread (core/threads.h), with results that
// do not depend on the thread count: the items are cut into fixed blocks of kFaceBlock (not into
// one chunk per thread), each block's partial result is computed the same way whoever computes it,
// and the partials are combined in block order. A loop of at most one block runs as plain
// sequential code.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "colonflat/core/threads.h"

namespace cf::flat_detail {

// Items per block: large enough that a block's work (a few hundred microseconds of per-face
// arithmetic) dwarfs the cost of handing it to a thread, small enough that 2-32 threads share a
// 0.1 M-face region evenly.
constexpr std::size_t kFaceBlock = 8192;

inline std::size_t face_blocks(std::size_t n) { return (n + kFaceBlock - 1) / kFaceBlock; }

// Calls body(begin, end) on every block [b kFaceBlock, min(n, (b + 1) kFaceBlock)), each thread
// taking the next block (parallel_indices: a late thread takes fewer blocks; the CT mask's window
// piece, 8 blocks on 2 threads, had its caller doing 58 % of the face loops in fixed halves).
// body must write only what its own items own.
template <class Body>
void for_each_block(std::size_t n, Body&& body) {
  const std::size_t nb = face_blocks(n);
  if (nb <= 1) {
    if (n > 0) body(std::size_t(0), n);
    return;
  }
  parallel_indices(nb, [&](std::size_t b) { body(b * kFaceBlock, std::min(n, (b + 1) * kFaceBlock)); });
}

// Sum of part(begin, end) over the blocks, added in block order.
template <class Part>
double block_sum(std::size_t n, Part&& part) {
  const std::size_t nb = face_blocks(n);
  if (nb <= 1) return n > 0 ? part(std::size_t(0), n) : 0.0;
  std::vector<double> partial(nb, 0.0);
  for_each_block(n, [&](std::size_t begin, std::size_t end) { partial[begin / kFaceBlock] = part(begin, end); });
  double sum = 0;
  for (double p : partial) sum += p;
  return sum;
}

// Minimum of part(begin, end) over the blocks (`none` when n = 0).
template <class Part>
double block_min(std::size_t n, double none, Part&& part) {
  const std::size_t nb = face_blocks(n);
  if (nb <= 1) return n > 0 ? part(std::size_t(0), n) : none;
  std::vector<double> partial(nb, none);
  for_each_block(n, [&](std::size_t begin, std::size_t end) { partial[begin / kFaceBlock] = part(begin, end); });
  return *std::min_element(partial.begin(), partial.end());
}

}  // namespace cf::flat_detail
