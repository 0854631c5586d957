#pragma once
// Atomic output: write to a temporary file next to the target (same extension, so format
// detection by extension still works), then rename over the target. A failure removes the
// temporary and leaves any existing target untouched. Temporaries and staging folders are also
// removed when the process is interrupted (SIGINT, SIGTERM, SIGHUP), and those a killed run left
// behind (their process no longer exists) are removed the next time outputs go to that folder.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace cf {

// A temporary sibling path of `target`: "<dir>/.<stem>.tmp-<pid>-<n><ext>".
std::filesystem::path temp_sibling(const std::filesystem::path& target);

// Calls write(tmp) then renames tmp -> target. Throws cf::Error if writing or renaming fails.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

// Several outputs that must appear together or not at all: stage() returns a temporary path for
// each target; commit() renames them all; the destructor removes any that were not committed.
// Every folder that receives a target gets one hidden staging folder,
// "<folder>/.colonflat-staging-<pid>-<n>/", holding the target's temporary under the target's
// own name (so format detection by extension still works); staging folders are removed at the
// end, on failure and on interruption. A target may be a folder: the caller creates the folder
// at the staged path and fills it; an existing folder of that name is replaced on commit.
// commit() checks every temporary first, then renames; if a rename fails, the targets already
// renamed are restored to their previous content.
class OutputTransaction {
 public:
  OutputTransaction() = default;
  // The older form with a staging root: no longer needed (every output folder gets its staging
  // folder); kept so that callers written against it still build.
  explicit OutputTransaction(const std::filesystem::path& /*staging_root*/) {}
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();
  std::filesystem::path stage(const std::filesystem::path& target);
  void commit();
  // The targets staged so far (in staging order).
  std::vector<std::filesystem::path> targets() const;
  // The staging folder of `folder` ("" when nothing was staged there).
  std::filesystem::path staging_folder(const std::filesystem::path& folder) const;

 private:
  std::filesystem::path staging_for(const std::filesystem::path& folder, const std::filesystem::path& target);
  void rollback(std::size_t renamed);
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // tmp, target
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> backups_; // backup, target
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staging_; // folder, its staging folder
  std::vector<std::filesystem::path> created_dirs_;
  bool committed_ = false;
};

// Writes text atomically (reports, JSON).
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

// Removes, in `dir`, staging folders and temporary files left by processes that no longer run.
// Returns how many were removed.
std::size_t remove_stale_temporaries(const std::filesystem::path& dir);

// The signal-time cleanup list (used by the above; exposed for tests): paths registered here are
// unlinked (files) or removed (empty folders) when SIGINT/SIGTERM/SIGHUP arrives, after which
// the signal's default action runs (the exit status says which signal).
void register_for_cleanup(const std::filesystem::path& path);
void unregister_for_cleanup(const std::filesystem::path& path);

}  // namespace cf
