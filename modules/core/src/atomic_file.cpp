#include "colonflat/core/atomic_file.h"
#include "colonflat/core/write_errors.h"

#include <signal.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <fstream>
#include <system_error>

#include "colonflat/core/error.h"

namespace fs = std::filesystem;

namespace cf {

namespace {

constexpr const char* kStagingPrefix = ".colonflat-staging-";

fs::path parent_or_dot(const fs::path& p) { return p.has_parent_path() ? p.parent_path() : fs::path("."); }

// Creates the missing folders of `dir`; returns those it created (outermost first).
std::vector<fs::path> create_folders(const fs::path& dir, const fs::path& for_target) {
  std::vector<fs::path> missing;
  for (fs::path d = dir; !d.empty() && !fs::exists(d); d = d.parent_path()) {
    missing.insert(missing.begin(), d);
    if (d == d.parent_path()) break;
  }
  for (const auto& d : missing) {
    std::error_code ec;
    fs::create_directory(d, ec);
    if (ec) throw Error(for_target.string() + ": cannot create folder " + d.string() + ": " + ec.message());
  }
  return missing;
}

void commit_rename(const fs::path& tmp, const fs::path& target) {
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code rec;
    fs::remove_all(tmp, rec);
    throw Error(target.string() + ": cannot write: " + ec.message());
  }
}

// The pid in ".colonflat-staging-<pid>" or ".<stem>.tmp-<pid>-<n><ext>"; 0 when the name is neither.
long temporary_owner(const std::string& name) {
  std::size_t at = std::string::npos;
  if (name.rfind(kStagingPrefix, 0) == 0) at = std::string(kStagingPrefix).size();
  else if (!name.empty() && name[0] == '.' && name.find(".tmp-") != std::string::npos) at = name.find(".tmp-") + 5;
  if (at == std::string::npos) return 0;
  long pid = 0;
  std::size_t k = at;
  for (; k < name.size() && std::isdigit(static_cast<unsigned char>(name[k])); ++k) pid = pid * 10 + (name[k] - '0');
  return k > at ? pid : 0;
}

bool process_gone(long pid) { return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH; }

// A write that failed, or may have been cut short by a stream that fails silently (an unchecked
// std::ofstream), on a file system that says why: the error in its words.
void throw_if_file_system_refuses(const fs::path& written, const fs::path& target) {
  const std::string why = file_system_problem(written);
  if (!why.empty()) throw Error(target.string() + ": cannot write: " + why);
}

}  // namespace

std::string file_system_problem(const fs::path& path) {
  std::error_code ec;
  fs::path p = path;
  while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
  if (p.empty()) p = ".";
  struct statvfs s {};
  if (::statvfs(p.c_str(), &s) != 0) return "";
  if (s.f_flag & ST_RDONLY) return "read-only file system";
  // root may use the blocks reserved for it; everyone else only the available ones.
  const bool root = ::geteuid() == 0;
  const auto blocks = root ? s.f_bfree : s.f_bavail;
  const auto inodes = root ? s.f_ffree : s.f_favail;
  if (blocks == 0 || (s.f_files > 0 && inodes == 0)) return "no space left on device";
  return "";
}

fs::path temp_sibling(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  return parent_or_dot(target) / ("." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                                  std::to_string(counter++) + target.extension().string());
}

std::size_t remove_stale_temporaries(const fs::path& dir) {
  std::size_t removed = 0;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const long pid = temporary_owner(e.path().filename().string());
    if (!pid || pid == ::getpid() || !process_gone(pid)) continue;
    std::error_code rec;
    fs::remove_all(e.path(), rec);
    if (!rec) ++removed;
  }
  return removed;
}

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  create_folders(parent_or_dot(target), target);
  remove_stale_temporaries(parent_or_dot(target));
  const fs::path tmp = temp_sibling(target);
  register_for_cleanup(tmp);
  try {
    try {
      write(tmp);
    } catch (const Error&) {
      throw_if_file_system_refuses(tmp, target);  // the library's words replaced by the system's
      throw;
    }
    if (!fs::exists(tmp)) throw Error(target.string() + ": the writer produced no file");
    throw_if_file_system_refuses(tmp, target);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    unregister_for_cleanup(tmp);
    throw;
  }
  commit_rename(tmp, target);
  unregister_for_cleanup(tmp);
}

OutputTransaction::~OutputTransaction() {
  std::error_code ec;
  if (!committed_)
    for (auto& [tmp, target] : staged_) fs::remove_all(tmp, ec);
  for (auto& [tmp, target] : staged_) unregister_for_cleanup(tmp);
  for (auto& [folder, staging] : staging_) {
    fs::remove_all(staging, ec);
    unregister_for_cleanup(staging);
  }
  for (auto it = created_dirs_.rbegin(); it != created_dirs_.rend(); ++it) {
    if (!committed_) fs::remove(*it, ec);  // only removes a folder left empty
    unregister_for_cleanup(*it);
  }
}

std::vector<fs::path> OutputTransaction::targets() const {
  std::vector<fs::path> v;
  for (const auto& [tmp, target] : staged_) v.push_back(target);
  return v;
}

fs::path OutputTransaction::staging_folder(const fs::path& folder) const {
  std::error_code ec;
  for (const auto& [f, staging] : staging_)
    if (f == folder || fs::equivalent(f, folder, ec)) return staging;
  return {};
}

// One staging folder per output folder; the counter keeps two transactions of one process apart.
fs::path OutputTransaction::staging_for(const fs::path& folder, const fs::path& target) {
  fs::path staging = staging_folder(folder);
  if (!staging.empty()) return staging;
  static std::atomic<unsigned> counter{0};
  staging = folder / (kStagingPrefix + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  register_for_cleanup(staging);
  std::error_code ec;
  fs::create_directory(staging, ec);
  if (ec) {
    unregister_for_cleanup(staging);
    throw Error(target.string() + ": cannot create staging folder " + staging.string() + ": " + ec.message());
  }
  staging_.emplace_back(folder, staging);
  return staging;
}

fs::path OutputTransaction::stage(const fs::path& target) {
  const fs::path dir = parent_or_dot(target);
  for (const auto& d : create_folders(dir, target)) {
    created_dirs_.push_back(d);
    register_for_cleanup(d);
  }
  remove_stale_temporaries(dir);
  for (const auto& [tmp, old_target] : staged_)
    if (old_target == target) throw Error(target.string() + ": staged twice in one transaction");
  const fs::path tmp = staging_for(dir, target) / target.filename();
  register_for_cleanup(tmp);
  staged_.emplace_back(tmp, target);
  return tmp;
}

void OutputTransaction::rollback(std::size_t renamed) {
  std::error_code ec;
  for (std::size_t i = 0; i < renamed; ++i) fs::remove_all(staged_[i].second, ec);
  for (auto& [backup, target] : backups_) fs::rename(backup, target, ec);
  backups_.clear();
}

void OutputTransaction::commit() {
  for (auto& [tmp, target] : staged_)
    if (!fs::exists(tmp)) throw Error(target.string() + ": the writer produced no file");
  // A file system that filled up while the outputs were written may hold cut files (a stream
  // that failed stays silent): nothing is committed then.
  for (auto& [tmp, target] : staged_) throw_if_file_system_refuses(tmp, target);
  std::size_t renamed = 0;
  try {
    for (auto& [tmp, target] : staged_) {
      std::error_code ec;
      // An existing file is kept aside until every rename succeeded; so is an existing folder
      // that a staged folder replaces (never a folder in the place of a file target).
      if (fs::exists(target, ec) && fs::is_directory(target, ec) == fs::is_directory(tmp, ec)) {
        const fs::path backup = temp_sibling(target);  // not removed on a signal: it is the old content
        fs::rename(target, backup, ec);
        if (!ec) backups_.emplace_back(backup, target);
      }
      commit_rename(tmp, target);
      ++renamed;
    }
  } catch (...) {
    rollback(renamed);
    throw;
  }
  std::error_code ec;
  for (auto& [backup, target] : backups_) {
    fs::remove_all(backup, ec);
    unregister_for_cleanup(backup);
  }
  backups_.clear();
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
