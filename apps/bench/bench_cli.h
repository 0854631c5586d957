#pragma once
// The benchmark apps' shared command line, on CLI11 (the parser `colonflat` itself uses).
//
//   int main(int argc, char** argv) {
//     cf::bench::BenchCli cli("flatten_bench", "Flattening benchmark: ...");
//     bool table_only = false;
//     cli.app().add_flag("--table-only", table_only, "the table without Google Benchmark");
//     return cli.run(argc, argv, [&] { ...; return cli.run_google_benchmarks(); });
//   }
//
// Google Benchmark's own options (--benchmark_*) are passed on to benchmark::Initialize; any other
// undeclared argument is refused (exit 2) before the bench does any work. `--help` lists the
// bench's own options. A parse error prints CLI11's message with its exit code; an exception
// thrown by the body prints one line `NAME: error: WHAT` and exits 1.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

namespace cf::bench {

class BenchCli {
 public:
  BenchCli(std::string name, std::string description);
  CLI::App& app() { return app_; }
  // Parses argv, then runs `body` (its return value is the exit code).
  int run(int argc, char** argv, const std::function<int()>& body);
  // Google Benchmark with the options this bench did not declare; returns 0.
  int run_google_benchmarks();

 private:
  std::string name_;
  CLI::App app_;
  std::vector<std::string> passed_on_;  // argv[0] and the undeclared options, in order
};

// "3" -> {3, 3}; "1-5" -> {1, 5}. Throws std::invalid_argument on anything else or first > last.
std::pair<int, int> parse_range(const std::string& text);

// The 1-minute load average (/proc/loadavg; 0 when unreadable): printed with every timing table.
double load_average();

}  // namespace cf::bench
