#pragma once
// Plain words for why a write failed, from the file system itself (issue 28 item 6): a library's
// message (VTK's pipeline dump, ITK's exception text, DCMTK's condition) or a stream's silent
// failure is replaced by what the user can act on.
#include <filesystem>
#include <string>

namespace cf {

// "no space left on device" when the file system holding `path` has no free block (or no free
// inode) left for this process, "read-only file system" when it is mounted read-only; "" otherwise.
std::string file_system_problem(const std::filesystem::path& path);

}  // namespace cf
