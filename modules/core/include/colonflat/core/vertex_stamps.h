// Marks by vertex id kept between calls of a search (one instance per thread): a mark counts only
// when its stamp is the current call's, so a call costs only the vertices it reaches, not a clear
// of the whole array nor a hash map of the reached ids.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cf {

class VertexStamps {
 public:
  // A new call on a mesh of `vertices` vertices: nothing is marked. The array grows with 1/8 of
  // headroom (the vertices a few surgeries add) instead of at every call.
  void start(std::size_t vertices) {
    if (stamp_.size() < vertices) stamp_.resize(vertices + vertices / 8, 0);
    if (++call_ == 0) {  // wrapped: no old stamp may equal a new call
      std::fill(stamp_.begin(), stamp_.end(), 0);
      call_ = 1;
    }
  }
  bool marked(int v) const { return stamp_[std::size_t(v)] == call_; }
  void mark(int v) { stamp_[std::size_t(v)] = call_; }
  // The array's length: a per-vertex value array beside it is sized to match.
  std::size_t size() const { return stamp_.size(); }

 private:
  std::vector<std::uint32_t> stamp_;
  std::uint32_t call_ = 0;
};

}  // namespace cf
