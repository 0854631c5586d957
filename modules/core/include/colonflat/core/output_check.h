#pragma once
// Checks a command's output paths before any work starts: no empty name, no path written twice,
// no input ever written (same path, hard link or symbolic link to it), no folder in the way, a
// writable folder, and an extension the writer knows. Every command (stand-alone stages, `run`,
// module tools) lists its inputs and outputs here and calls check() first.
//
//   PathPlan plan("denoise");
//   plan.input("t.off");
//   plan.output("d.vtp", "-o", {".vtp", ".off"});
//   plan.output("t.off", "--report", {".json"});
//   plan.check();   // UsageError: "t.off: --report would overwrite the input t.off"
#include <filesystem>
#include <string>
#include <vector>

namespace cf {

// True when a and b name the same file: equivalent existing files (hard links, symbolic links),
// or the same normalised absolute path.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// True when `inner` is `outer` or lies inside the folder `outer` (after resolving links).
bool path_inside(const std::filesystem::path& inner, const std::filesystem::path& outer);

class PathPlan {
 public:
  // An input file or folder (DICOM); a folder input protects every file inside it.
  void input(const std::filesystem::path& path);
  // An output; `option` names it in messages ("-o", "--report"); `extensions` (lower case, with
  // the dot; ".nii.gz" allowed) lists the formats its writer knows (empty: any).
  void output(const std::filesystem::path& path, const std::string& option,
              const std::vector<std::string>& extensions = {});
  // An output folder (`run -o DIR`): must not be an input file nor contain an input file.
  void output_folder(const std::filesystem::path& path, const std::string& option);
  // Throws UsageError naming the first problem (path and option in the message).
  void check() const;

 private:
  struct Out {
    std::filesystem::path path;
    std::string option;
    std::vector<std::string> extensions;
    bool folder = false;
  };
  void check_one(const Out& o) const;
  std::vector<std::filesystem::path> inputs_;
  std::vector<Out> outputs_;
};

// Lower-case extension with ".nii.gz"-style double extensions kept together.
std::string full_extension(const std::filesystem::path& path);

}  // namespace cf
