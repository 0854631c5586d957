#pragma once
// Bounded memory from untrusted files: readers compare what a header declares with the file's
// size and with a memory budget before allocating, and refuse at once with the numbers.
#include <cstdint>
#include <filesystem>
#include <string>

namespace cf {

// The budget in bytes: COLONFLAT_MEMORY_BUDGET_MIB if set (> 0), else 80 % of physical memory.
std::uint64_t memory_budget_bytes();

// "1.5 GiB", "820 KiB", "12 bytes".
std::string human_bytes(double bytes);

// Throws InputError(file, "<what> needs <bytes> in memory, over the memory budget of <budget> (set
// COLONFLAT_MEMORY_BUDGET_MIB to change it)") when bytes > budget.
void check_memory_budget(const std::string& file, const std::string& what, double bytes);

// Throws InputError(file, "<what> declares at least <needed> of data but the file holds only
// <size>") when needed > file size.
void check_declared_data(const std::filesystem::path& file, const std::string& what, double needed_bytes);

}  // namespace cf
