#include "mesh_header_check.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "colonflat/core/error.h"
#include "colonflat/core/memory_budget.h"

namespace cf {
namespace {

constexpr std::size_t kHeaderBytes = 1 << 16;
// zlib cannot compress better than about 1032:1; VTK XML may hold zlib-compressed data.
constexpr double kMaxCompression = 1100.0;

std::string head_of(const std::filesystem::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string s(n, '\0');
  in.read(&s[0], static_cast<std::streamsize>(n));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

// The largest number following `key` (a regex with one capture) in `text`; -1 when absent.
double largest_match(const std::string& text, const std::regex& key) {
  double best = -1;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), key); it != std::sregex_iterator(); ++it)
    best = std::max(best, std::strtod((*it)[1].str().c_str(), nullptr));
  return best;
}

void check_counts(const std::filesystem::path& path, double vertices, double faces, double min_bytes,
                  double compression = 1.0) {
  if (vertices < 0 && faces < 0) return;
  vertices = std::max(vertices, 0.0);
  faces = std::max(faces, 0.0);
  std::ostringstream what;
  what << "the header (" << std::size_t(vertices) << " vertices, " << std::size_t(faces) << " faces)";
  check_declared_data(path, what.str(), min_bytes / compression);
  // Soup (3 doubles a point, ~4 ids a face) plus the halfedge mesh built from it.
  check_memory_budget(path.string(), what.str(), 120.0 * vertices + 120.0 * faces);
}

void check_off(const std::filesystem::path& path, const std::string& head) {
  std::istringstream in(head);
  std::string magic;
  in >> magic;
  if (magic.find("OFF") == std::string::npos) return;
  std::string next;
  in >> next;
  if (next == "BINARY") return;  // OpenMesh reads the binary counts itself
  std::string line, rest = next;
  std::getline(in, line);
  rest += line;
  while (rest.find_first_not_of(" \t\r") == std::string::npos || rest[rest.find_first_not_of(" \t\r")] == '#') {
    if (!std::getline(in, rest)) return;
  }
  std::istringstream counts(rest);
  double nv = -1, nf = -1;
  if (!(counts >> nv >> nf)) return;
  check_counts(path, nv, nf, 6.0 * nv + 7.0 * nf - 2.0);  // "x y z\n" and "3 a b c\n" at their shortest
}

void check_ply(const std::filesystem::path& path, const std::string& head) {
  if (head.rfind("ply", 0) != 0) return;
  const double nv = largest_match(head, std::regex(R"(element\s+vertex\s+(\d+))"));
  const double nf = largest_match(head, std::regex(R"(element\s+face\s+(\d+))"));
  check_counts(path, nv, nf, 3.0 * std::max(nv, 0.0) + 4.0 * std::max(nf, 0.0));
}

void check_stl(const std::filesystem::path& path, const std::string& head) {
  if (head.size() < 84 || head.rfind("solid", 0) == 0) return;  // ASCII STL: no counts
  std::uint32_t n = 0;
  std::memcpy(&n, head.data() + 80, 4);
  check_counts(path, 3.0 * n, n, 84.0 + 50.0 * n);
}

// True when `word` occurs anywhere in the file (read in 1 MiB chunks).
bool file_contains(const std::filesystem::path& path, const std::string& word) {
  std::ifstream in(path, std::ios::binary);
  std::string carry, chunk(1 << 20, '\0');
  while (in.read(&chunk[0], static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    const std::string window = carry + chunk.substr(0, static_cast<std::size_t>(in.gcount()));
    if (window.find(word) != std::string::npos) return true;
    carry = window.substr(window.size() > word.size() ? window.size() - word.size() : 0);
  }
  return false;
}

// VTK 9.1's legacy reader can crash on a file cut before its sections (e.g. inside FIELD), so a
// file without a POINTS and a cell section is refused before VTK sees it.
void check_vtk_legacy_sections(const std::filesystem::path& path) {
  if (!file_contains(path, "POINTS "))
    throw InputError(path.string(), "no POINTS section (truncated or not a VTK PolyData file)");
  for (const char* cells : {"POLYGONS ", "TRIANGLE_STRIPS ", "LINES ", "VERTICES "})
    if (file_contains(path, cells)) return;
  throw InputError(path.string(), "no cell section (POLYGONS, LINES, ...): truncated file?");
}

void check_vtk_legacy(const std::filesystem::path& path, const std::string& head) {
  check_vtk_legacy_sections(path);
  const double np = largest_match(head, std::regex(R"(POINTS\s+(\d+))"));
  const double nc = largest_match(head, std::regex(R"((?:POLYGONS|TRIANGLE_STRIPS|LINES|VERTICES)\s+\d+\s+(\d+))"));
  check_counts(path, np, nc, 3.0 * std::max(np, 0.0) + 1.0 * std::max(nc, 0.0));
}

void check_vtk_xml(const std::filesystem::path& path, const std::string& head) {
  const double np = largest_match(head, std::regex(R"re(NumberOfPoints="(\d+)")re"));
  const double nc = largest_match(head, std::regex(R"re(NumberOf(?:Polys|Lines|Strips|Verts)="(\d+)")re"));
  check_counts(path, np, nc, 12.0 * std::max(np, 0.0) + 8.0 * std::max(nc, 0.0), kMaxCompression);
}

}  // namespace

void check_declared_mesh_size(const std::filesystem::path& path, MeshFormat format) {
  const std::string head = head_of(path, kHeaderBytes);
  switch (format) {
    case MeshFormat::kOFF: return check_off(path, head);
    case MeshFormat::kPLY: return check_ply(path, head);
    case MeshFormat::kSTL: return check_stl(path, head);
    case MeshFormat::kVTK: return check_vtk_legacy(path, head);
    case MeshFormat::kVTP: return check_vtk_xml(path, head);
    case MeshFormat::kOBJ: return;  // no counts: memory follows the file size
  }
}

}  // namespace cf
