#pragma once
// Resident memory of the test process, for tests that check what a step gives back to the kernel.
#include <unistd.h>

#include <fstream>

namespace cf::testing {

// Resident memory of this process in MiB (/proc/self/statm, second field, in pages).
inline double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  double size = 0, resident = 0;
  statm >> size >> resident;
  return resident * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

}  // namespace cf::testing
