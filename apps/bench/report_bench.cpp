// Review-report benchmark: on a finished run folder (default: a full-phantom run, made with
// `colonflat run -o DIR`), the time of `colonflat report` against the run's own time, its phases
// (load: run files and CT; image: layout and lookup; ct: planes for clicks; cards: CT views,
// crops, endoluminal views; page), and the size of what it writes. Target: the report adds
// <= 10 % to a full-phantom run.
// Run in Release: ./build/apps/bench/report_bench RUN_DIR [repeats]
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "bench_cli.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage.h"
#include "colonflat/report/report.h"

namespace fs = std::filesystem;

namespace {

std::uintmax_t folder_bytes(const fs::path& dir) {
  std::uintmax_t total = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) total += e.file_size();
  return total;
}

void row(const char* what, const fs::path& dir, const cf::ReportOptions& opts, double run_s) {
  cf::Stopwatch sw;
  const cf::ReportResult r = cf::write_review_report(dir, opts);
  const double s = sw.seconds();
  const double mib = (folder_bytes(dir / "report_files") + fs::file_size(dir / "report.html")) / 1048576.0;
  std::printf("%-26s %6d %6d %7d %6d %9.2f %9.1f %8.1f %9.0f\n", what, r.candidates, r.known_polyps, r.images,
              r.endoluminal_views, s, run_s > 0 ? 100.0 * s / run_s : 0.0, mib, cf::peak_memory_mib());
  std::printf("    phases:");
  for (const auto& [name, secs] : r.phases) std::printf(" %s %.2f s", name.c_str(), secs);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  cf::bench::BenchCli cli("report_bench", "Review-report benchmark on a finished run folder (see the file's header)");
  std::string run_dir;
  int repeats = 1;
  cli.app().add_option("run_dir", run_dir, "run folder from `colonflat run -o RUN_DIR`")->required()->check(CLI::ExistingDirectory);
  cli.app().add_option("repeats", repeats, "repeats of the default row")->check(CLI::Range(1, 100));
  return cli.run(argc, argv, [&] {
    const fs::path dir = run_dir;
    const nlohmann::json rr = cf::read_json_file(dir / "run_report.json");
    const double run_s = rr.value("total_time_s", 0.0);
    std::printf("run %s: %.1f s (run_report.json total_time_s); load average %.2f\n", dir.c_str(), run_s,
                cf::bench::load_average());
    std::printf("%-26s %6s %6s %7s %6s %9s %9s %8s %9s\n", "case", "cands", "known", "images", "endo", "time_s",
                "%_of_run", "MiB", "peak_MiB");
    cf::ReportOptions defaults;
    for (int i = 0; i < repeats; ++i) row("default", dir, defaults, run_s);
    cf::ReportOptions no_endo = defaults;
    no_endo.endoluminal = false;
    row("no endoluminal views", dir, no_endo, run_s);
    cf::ReportOptions coarse = defaults;
    coarse.stack_step_mm = 8;
    row("CT planes every 8 mm", dir, coarse, run_s);
    row("default (report last)", dir, defaults, run_s);
    return 0;
  });
}
