// Text meshes (ASCII OFF, OBJ, ASCII PLY) whose vertex holds "nan" or "inf": OpenMesh's parsers
// read such a number as something finite or read what follows out of step (an OFF then shows up
// as faces referencing vertex ids out of range, or as a non-orientable surface). This scan, run
// before OpenMesh when the file mentions nan or inf at all, names the vertex and its coordinate.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/core/error.h"
#include "mesh_header_check.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::vector<std::string> tokens_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> t;
  for (std::string w; in >> w;) t.push_back(w);
  return t;
}

bool blank_or_comment(const std::string& line) {
  const auto at = line.find_first_not_of(" \t\r");
  return at == std::string::npos || line[at] == '#';
}

// The next line that holds something; false at the end of the file.
bool next_content_line(std::istream& in, std::string& line) {
  while (std::getline(in, line))
    if (!blank_or_comment(line)) return true;
  return false;
}

// Throws when one of the coordinates t[first..first+2] of vertex `v` is not a finite number.
void check_vertex(const fs::path& path, std::size_t v, const std::vector<std::string>& t, std::size_t first) {
  for (std::size_t k = 0; k < 3 && first + k < t.size(); ++k) {
    const std::string& word = t[first + k];
    char* end = nullptr;
    const double x = std::strtod(word.c_str(), &end);
    if (end == word.c_str() || *end != '\0' || !std::isfinite(x))
      throw InputError(path.string(), "vertex " + std::to_string(v) + " has a coordinate that is not a finite number: " +
                                          std::string(1, "xyz"[k]) + " = " + word);
  }
}

void scan_off(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  if (!next_content_line(in, line)) return;
  std::vector<std::string> t = tokens_of(line);
  if (t.empty() || t[0].find("OFF") == std::string::npos || (t.size() > 1 && t[1] == "BINARY")) return;
  t.erase(t.begin());  // the counts follow the keyword on its line or on the next one
  if (t.empty() && next_content_line(in, line)) t = tokens_of(line);
  if (t.empty()) return;
  const long nv = std::strtol(t[0].c_str(), nullptr, 10);
  for (long v = 0; v < nv && next_content_line(in, line); ++v) check_vertex(path, std::size_t(v), tokens_of(line), 0);
}

void scan_obj(const fs::path& path) {
  std::ifstream in(path);
  std::size_t v = 0;
  for (std::string line; std::getline(in, line);) {
    const auto t = tokens_of(line);
    if (t.empty() || t[0] != "v") continue;
    check_vertex(path, v++, t, 1);
  }
}

// ASCII PLY: the elements before "vertex" are skipped line by line (one element a line), then the
// x, y and z properties of each vertex are checked.
void scan_ply(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::size_t skip = 0, count = 0, x_at = 0;
  bool ascii = false, in_vertex = false, seen_vertex = false;
  int prop = 0;
  while (std::getline(in, line)) {
    const auto t = tokens_of(line);
    if (t.empty()) continue;
    if (t[0] == "end_header") break;
    if (t[0] == "format") ascii = t.size() > 1 && t[1] == "ascii";
    if (t[0] == "element" && t.size() > 2) {
      in_vertex = t[1] == "vertex";
      const std::size_t n = std::strtoul(t[2].c_str(), nullptr, 10);
      if (in_vertex) count = n, seen_vertex = true, prop = 0;
      else if (!seen_vertex) skip += n;
    } else if (t[0] == "property" && in_vertex) {
      if (t.back() == "x") x_at = std::size_t(prop);
      ++prop;
    }
  }
  if (!ascii) return;
  for (std::size_t i = 0; i < skip && next_content_line(in, line);) ++i;
  for (std::size_t v = 0; v < count && next_content_line(in, line); ++v) check_vertex(path, v, tokens_of(line), x_at);
}

// True when the file holds "nan" or "inf" in any case (read in 1 MiB chunks): only then is the
// file parsed a second time.
bool mentions_nonfinite(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string carry, chunk(1 << 20, '\0');
  while (in.read(&chunk[0], static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    std::string window = carry + chunk.substr(0, static_cast<std::size_t>(in.gcount()));
    for (char& c : window) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (window.find("nan") != std::string::npos || window.find("inf") != std::string::npos) return true;
    carry = window.substr(window.size() > 2 ? window.size() - 2 : 0);
  }
  return false;
}

}  // namespace

void check_text_vertex_coordinates(const fs::path& path, MeshFormat format) {
  if (format != MeshFormat::kOFF && format != MeshFormat::kOBJ && format != MeshFormat::kPLY) return;
  if (!mentions_nonfinite(path)) return;
  switch (format) {
    case MeshFormat::kOFF: return scan_off(path);
    case MeshFormat::kOBJ: return scan_obj(path);
    case MeshFormat::kPLY: return scan_ply(path);
    default: return;
  }
}

}  // namespace cf
