#include "colonflat/core/output_check.h"

#include <unistd.h>

#include <algorithm>

#include "colonflat/core/error.h"

namespace fs = std::filesystem;

namespace cf {

namespace {

fs::path normalised(const fs::path& p) {
  std::error_code ec;
  fs::path c = fs::weakly_canonical(fs::absolute(p), ec);
  return ec ? fs::absolute(p).lexically_normal() : c;
}

// The nearest folder of `p` that exists (the one whose permissions decide whether p can be made).
fs::path nearest_existing_folder(const fs::path& p) {
  fs::path d = fs::absolute(p).parent_path();
  std::error_code ec;
  while (!d.empty() && !fs::exists(d, ec) && d != d.parent_path()) d = d.parent_path();
  return d;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : " ") + x;
  return s;
}

}  // namespace

std::string full_extension(const fs::path& path) {
  std::string n = path.filename().string();
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* two : {".nii.gz", ".tar.gz"})
    if (n.size() > 7 && n.compare(n.size() - 7, 7, two) == 0) return two;
  const auto dot = n.rfind('.');
  return dot == std::string::npos || dot == 0 ? "" : n.substr(dot);
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ea, eb, ec;
  if (fs::exists(a, ea) && fs::exists(b, eb)) {
    const bool eq = fs::equivalent(a, b, ec);
    if (!ec) return eq;
  }
  return normalised(a) == normalised(b);
}

bool path_inside(const fs::path& inner, const fs::path& outer) {
  const fs::path i = normalised(inner), o = normalised(outer);
  auto oi = o.begin(), ii = i.begin();
  for (; oi != o.end(); ++oi, ++ii)
    if (ii == i.end() || *oi != *ii) return false;
  return true;
}

void PathPlan::input(const fs::path& path) {
  if (!path.empty()) inputs_.push_back(path);
}

void PathPlan::output(const fs::path& path, const std::string& option, const std::vector<std::string>& extensions) {
  outputs_.push_back({path, option, extensions, false});
}

void PathPlan::output_folder(const fs::path& path, const std::string& option) {
  outputs_.push_back({path, option, {}, true});
}

void PathPlan::check_one(const Out& o) const {
  const std::string name = o.path.string();
  if (name.empty()) throw UsageError(o.option + ": empty output path");
  std::error_code ec;
  for (const auto& in : inputs_) {
    if (same_file(o.path, in))
      throw UsageError(name + ": " + o.option + " would overwrite the input " + in.string());
    if (fs::is_directory(in, ec) && path_inside(o.path, in))
      throw UsageError(name + ": " + o.option + " lies inside the input folder " + in.string());
  }
  if (!o.folder) {
    if (fs::is_directory(o.path, ec)) throw UsageError(name + ": " + o.option + " names a folder, not a file");
    if (!o.extensions.empty() &&
        std::find(o.extensions.begin(), o.extensions.end(), full_extension(o.path)) == o.extensions.end())
      throw UsageError(name + ": " + o.option + " has an unknown format '" + full_extension(o.path) +
                       "' (use " + join(o.extensions) + ")");
  } else if (fs::exists(o.path, ec) && !fs::is_directory(o.path, ec)) {
    throw UsageError(name + ": " + o.option + " is a file, not a folder");
  }
  const fs::path dir = o.folder && fs::is_directory(o.path, ec) ? fs::absolute(o.path) : nearest_existing_folder(o.path);
  if (!fs::is_directory(dir, ec)) throw UsageError(name + ": " + o.option + ": " + dir.string() + " is not a folder");
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw UsageError(name + ": " + o.option + ": folder " + dir.string() + " is not writable");
}

void PathPlan::check() const {
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    check_one(outputs_[i]);
    for (std::size_t j = 0; j < i; ++j) {
      if (outputs_[i].folder || outputs_[j].folder) continue;
      if (same_file(outputs_[i].path, outputs_[j].path))
        throw UsageError(outputs_[i].path.string() + ": written twice (" + outputs_[j].option + " and " +
                         outputs_[i].option + ")");
    }
  }
}

}  // namespace cf
