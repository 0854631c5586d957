#pragma once
// Disjoint sets with path halving and union by size; used by topology, components and denoising.
#include <cstdint>
#include <numeric>
#include <vector>

#include "colonflat/core/huge_pages.h"
namespace cf {

class UnionFind {
 public:
  explicit UnionFind(std::size_t n = 0) { reset(n); }
  void reset(std::size_t n) {
    resize_huge(parent_, n);
    std::iota(parent_.begin(), parent_.end(), 0u);
    assign_huge(size_, n, 1u);
  }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  // Returns true if a and b were in different sets.
  bool unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }
  std::size_t size() const { return parent_.size(); }

 private:
  std::vector<std::uint32_t> parent_, size_;
};

}  // namespace cf
