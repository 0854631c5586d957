#include "bench_cli.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <fstream>
#include <regex>
#include <stdexcept>

#include "colonflat/core/malloc_tunables.h"

namespace cf::bench {

BenchCli::BenchCli(std::string name, std::string description) : name_(std::move(name)), app_(description, name_) {
  app_.allow_extras();
  app_.option_defaults()->always_capture_default();
}

int BenchCli::run(int argc, char** argv, const std::function<int()>& body) {
  rerun_with_malloc_tunables(argv);  // measure with the allocator settings colonflat runs with
  try {
    app_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app_.exit(e);
  }
  passed_on_ = {argv[0]};
  for (const std::string& extra : app_.remaining()) {
    if (extra.rfind("--benchmark_", 0) != 0) {  // refused before any work, not after the table
      std::fprintf(stderr, "%s: error: unknown argument '%s' (see --help)\n", name_.c_str(), extra.c_str());
      return 2;
    }
    passed_on_.push_back(extra);
  }
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name_.c_str(), e.what());
    return 1;
  }
}

int BenchCli::run_google_benchmarks() {
  std::vector<char*> args;
  for (std::string& a : passed_on_) args.push_back(a.data());
  int count = int(args.size());
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

std::pair<int, int> parse_range(const std::string& text) {
  static const std::regex range(R"((\d+)(?:-(\d+))?)");
  std::smatch m;
  if (!std::regex_match(text, m, range)) throw std::invalid_argument("'" + text + "' is not N or N-M");
  const int first = std::stoi(m[1]);
  const int last = m[2].matched ? std::stoi(m[2]) : first;
  if (last < first) throw std::invalid_argument("'" + text + "': the range runs backwards");
  return {first, last};
}

double load_average() {
  double load = 0;
  std::ifstream in("/proc/loadavg");
  if (!(in >> load)) load = 0;
  return load;
}

}  // namespace cf::bench
