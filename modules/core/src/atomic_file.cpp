#include "colonflat/core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

#include "colonflat/core/error.h"

namespace fs = std::filesystem;

namespace cf {

fs::path temp_sibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  return dir / ("." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter++) + target.extension().string());
}

namespace {
void ensure_parent(const fs::path& target) {
  if (target.has_parent_path() && !fs::exists(target.parent_path())) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw Error(target.string() + ": cannot create folder " + target.parent_path().string() + ": " + ec.message());
  }
}
void commit_rename(const fs::path& tmp, const fs::path& target) {
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(target.string() + ": cannot write: " + ec.message());
  }
}
}  // namespace

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  ensure_parent(target);
  const fs::path tmp = temp_sibling(target);
  try {
    write(tmp);
    if (!fs::exists(tmp)) throw Error(target.string() + ": the writer produced no file");
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  commit_rename(tmp, target);
}

OutputTransaction::~OutputTransaction() {
  if (committed_) return;
  for (auto& [tmp, target] : staged_) {
    std::error_code ec;
    fs::remove(tmp, ec);
  }
}

fs::path OutputTransaction::stage(const fs::path& target) {
  ensure_parent(target);
  staged_.emplace_back(temp_sibling(target), target);
  return staged_.back().first;
}

void OutputTransaction::commit() {
  for (auto& [tmp, target] : staged_)
    if (!fs::exists(tmp)) throw Error(target.string() + ": the writer produced no file");
  for (auto& [tmp, target] : staged_) commit_rename(tmp, target);
  committed_ = true;
}

void write_text_atomically(const fs::path& target, const std::string& text) {
  write_atomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw Error(target.string() + ": cannot write");
  });
}

}  // namespace cf
