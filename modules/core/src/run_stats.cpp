#include "colonflat/core/run_stats.h"

#include <fstream>
#include <string>

namespace cf {
namespace {
double read_status_kib(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.compare(0, key.size(), key) == 0) return std::stod(line.substr(key.size() + 1));
  }
  return 0;
}
}  // namespace

double peak_memory_mib() { return read_status_kib("VmHWM") / 1024.0; }
double current_memory_mib() { return read_status_kib("VmRSS") / 1024.0; }

}  // namespace cf
