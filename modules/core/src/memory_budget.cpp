#include "colonflat/core/memory_budget.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

#include "colonflat/core/error.h"

namespace cf {

std::uint64_t memory_budget_bytes() {
  if (const char* env = std::getenv("COLONFLAT_MEMORY_BUDGET_MIB")) {
    const double mib = std::atof(env);
    if (mib > 0) return static_cast<std::uint64_t>(mib * 1024.0 * 1024.0);
  }
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && page > 0) return static_cast<std::uint64_t>(0.8 * double(pages) * double(page));
  return 8ull << 30;
}

std::string human_bytes(double b) {
  static const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int u = 0;
  while (b >= 1024.0 && u < 5) b /= 1024.0, ++u;
  char buf[64];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", b, units[u]);
  return buf;
}

void check_memory_budget(const std::string& file, const std::string& what, double bytes) {
  const double budget = double(memory_budget_bytes());
  if (bytes > budget)
    throw InputError(file, what + " needs " + human_bytes(bytes) + " in memory, over the memory budget of " +
                               human_bytes(budget) + " (set COLONFLAT_MEMORY_BUDGET_MIB to change it)");
}

void check_declared_data(const std::filesystem::path& file, const std::string& what, double needed) {
  std::error_code ec;
  const double size = double(std::filesystem::file_size(file, ec));
  if (ec) return;
  if (needed > size)
    throw InputError(file.string(), what + " declares at least " + human_bytes(needed) +
                                        " of data but the file holds only " + human_bytes(size) +
                                        " (truncated file or wrong header)");
}

}  // namespace cf
