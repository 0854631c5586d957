#pragma once
// Atomic output: write to a temporary file next to the target (same extension, so format
// detection by extension still works), then rename over the target. A failure removes the
// temporary and leaves any existing target untouched.
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

// Several outputs that must appear together or not at all: stage() returns a temp path for
// each target; commit() renames them all; the destructor removes any that were not committed.
class OutputTransaction {
 public:
  OutputTransaction() = default;
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();
  std::filesystem::path stage(const std::filesystem::path& target);
  void commit();

 private:
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  // tmp, target
  bool committed_ = false;
};

// Writes text atomically (reports, JSON).
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

}  // namespace cf
