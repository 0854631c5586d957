// FaceGrid's compressed rows of the constructor's faces per cell (FaceGrid::StaticCells,
// face_grid.h): an open-addressing table from cell code to row.
#include <algorithm>
#include <vector>

#include "colonflat/core/huge_pages.h"
#include "colonflat/denoise/face_grid.h"

namespace cf {

std::uint32_t FaceGrid::StaticCells::find_or_add(std::uint64_t code) {
  if (2 * (count_.size() + 1) > slot_code_.size()) rehash(std::max<std::size_t>(4096, 2 * slot_code_.size()));
  const std::size_t mask = slot_code_.size() - 1;
  std::size_t s = slot(code, mask);
  for (; slot_code_[s] != kEmpty; s = (s + 1) & mask)
    if (slot_code_[s] == code) return slot_row_[s];
  slot_code_[s] = code;
  slot_row_[s] = static_cast<std::uint32_t>(count_.size());
  count_.push_back(0);
  return slot_row_[s];
}

void FaceGrid::StaticCells::rehash(std::size_t slots) {
  std::vector<std::uint64_t> old_code;
  std::vector<std::uint32_t> old_row;
  assign_huge(old_code, slots, kEmpty);
  assign_huge(old_row, slots, kNoRow);
  old_code.swap(slot_code_);
  old_row.swap(slot_row_);
  const std::size_t mask = slots - 1;
  for (std::size_t i = 0; i < old_code.size(); ++i) {
    if (old_code[i] == kEmpty) continue;
    std::size_t s = slot(old_code[i], mask);
    while (slot_code_[s] != kEmpty) s = (s + 1) & mask;
    slot_code_[s] = old_code[i];
    slot_row_[s] = old_row[i];
  }
}

void FaceGrid::StaticCells::finish_counts() {
  start_.assign(count_.size() + 1, 0);
  for (std::size_t r = 0; r < count_.size(); ++r) start_[r + 1] = start_[r] + count_[r];
  resize_huge(faces_, start_.back());
  cursor_.assign(start_.begin(), start_.end() - 1);
}

}  // namespace cf
