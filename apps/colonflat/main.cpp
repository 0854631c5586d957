// The `colonflat` dispatcher: every command is a library function (pipeline/dispatch.h).
#include <iostream>
#include <string>
#include <vector>

#include "colonflat/core/malloc_tunables.h"
#include "colonflat/pipeline/dispatch.h"

int main(int argc, char** argv) {
  cf::rerun_with_malloc_tunables(argv);  // allocator settings (core/malloc_tunables.h)
  std::vector<std::string> args(argv + 1, argv + argc);
  return cf::colonflat_main(args, std::cout, std::cerr);
}
