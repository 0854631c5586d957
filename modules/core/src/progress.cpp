#include "colonflat/core/progress.h"

#include <cmath>
#include <iomanip>
#include <mutex>
#include <sstream>

namespace cf {
namespace {

std::mutex& scope_mutex() {
  static std::mutex m;
  return m;
}
std::mutex& line_mutex() {
  static std::mutex m;
  return m;
}
ProgressScope* g_innermost = nullptr;  // guarded by scope_mutex()

}  // namespace

void write_progress_line(std::ostream* log, const std::string& line) {
  if (!log) return;
  std::lock_guard<std::mutex> lock(line_mutex());
  *log << line << std::endl;
}

ProgressScope::ProgressScope(std::ostream* log, std::string step) : log_(log), step_(std::move(step)) {
  std::lock_guard<std::mutex> lock(scope_mutex());
  outer_ = g_innermost;
  g_innermost = this;
}

ProgressScope::~ProgressScope() {
  std::lock_guard<std::mutex> lock(scope_mutex());
  // Scopes close in reverse order of opening; one that is not innermost (a bug) is unlinked.
  for (ProgressScope** p = &g_innermost; *p; p = &(*p)->outer_)
    if (*p == this) {
      *p = outer_;
      break;
    }
}

nlohmann::json ProgressScope::phases() const {
  std::lock_guard<std::mutex> lock(scope_mutex());
  return phases_;
}

void phase_done(const std::string& phase) {
  std::ostream* log = nullptr;
  std::string line;
  {
    std::lock_guard<std::mutex> lock(scope_mutex());
    ProgressScope* scope = g_innermost;
    if (!scope) return;
    const double s = scope->since_last_.seconds();
    scope->since_last_.restart();
    scope->phases_.push_back({{"phase", phase}, {"time_s", std::round(s * 1000) / 1000}});
    std::ostringstream text;
    text << scope->step_ << ": " << phase << " " << std::fixed << std::setprecision(s < 10 ? 2 : 1) << s << " s";
    line = text.str();
    log = scope->log_;
  }
  write_progress_line(log, line);
}

}  // namespace cf
