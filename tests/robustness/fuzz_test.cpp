// Issue 14 item 8: a bounded random-corruption run over every reader. Each valid tiny file is
// corrupted in ways a reader must notice (truncated, a size in its header enlarged, its magic
// overwritten) and read through `colonflat`; every run must exit 2 or 3 with one error line,
// leave no output and no temporary, and keep its input unchanged; the process stays under 1 GB.
#include <sys/resource.h>

#include <cstring>
#include <random>
#include <regex>

#include "colonflat/core/run_stats.h"
#include "volumes.h"

namespace cf::robust {
namespace {

enum class Corruption { kTruncate, kEnlargeSize, kBreakMagic };

struct Sample {
  std::string name;        // file name (format by extension)
  std::string bytes;       // the valid file
  std::size_t min_cut;     // truncation keeps fewer bytes than this (a whole record goes)
  std::size_t magic_at;    // where the format's magic starts
};

// The numbers a header declares as sizes: regex with one capture group per format.
const std::map<std::string, std::regex>& size_fields() {
  static const std::map<std::string, std::regex> m{
      {".off", std::regex(R"(OFF\n(\d+))")},
      {".ply", std::regex(R"(element vertex (\d+))")},
      {".vtk", std::regex(R"(POINTS (\d+))")},
      {".vtp", std::regex(R"re(NumberOfPoints="(\d+)")re")},
      {".nrrd", std::regex(R"(sizes: \d+ \d+ (\d+))")},
      {".mha", std::regex(R"(DimSize = \d+ \d+ (\d+))")},
      {".obj", std::regex(R"(\nf (\d+))")}};
  return m;
}

std::string enlarge(const Sample& s, std::mt19937& rng) {
  std::string b = s.bytes;
  const std::string ext = full_extension(s.name);
  if (ext == ".stl") {  // binary STL: triangle count at byte 80
    std::uint32_t n;
    std::memcpy(&n, &b[80], 4);
    n = n * std::uniform_int_distribution<std::uint32_t>(2, 100000)(rng) + 1;
    std::memcpy(&b[80], &n, 4);
    return b;
  }
  if (ext == ".nii") {  // NIfTI-1: dim[3] (int16) at byte 46
    std::int16_t n;
    std::memcpy(&n, &b[46], 2);
    n = static_cast<std::int16_t>(std::min<int>(32767, n * std::uniform_int_distribution<int>(2, 2000)(rng)));
    std::memcpy(&b[46], &n, 2);
    return b;
  }
  std::smatch m;
  const std::string head = ext == ".obj" ? b : b.substr(0, 4096);  // OBJ: faces come after every vertex
  if (!std::regex_search(head, m, size_fields().at(ext))) return b;
  const long long value = std::stoll(m[1].str());
  const long long bigger = value * std::uniform_int_distribution<long long>(2, 1000000)(rng) + 10;
  b.replace(std::size_t(m.position(1)), std::size_t(m.length(1)), std::to_string(bigger));
  return b;
}

std::string corrupt(const Sample& s, Corruption c, std::mt19937& rng) {
  switch (c) {
    case Corruption::kTruncate:
      return s.bytes.substr(0, std::uniform_int_distribution<std::size_t>(0, s.min_cut - 1)(rng));
    case Corruption::kEnlargeSize:
      return enlarge(s, rng);
    case Corruption::kBreakMagic: {
      std::string b = s.bytes;
      for (std::size_t i = s.magic_at; i < std::min(b.size(), s.magic_at + 4); ++i)
        b[i] = char(std::uniform_int_distribution<int>(0x80, 0xff)(rng));  // never a valid magic byte
      return b;
    }
  }
  return s.bytes;
}

// The last line of a text file (a whole record); binary files lose at least their last byte.
std::size_t min_cut(const std::string& bytes, bool text) {
  if (!text) return bytes.size();
  std::size_t end = bytes.find_last_not_of("\n \r");
  const std::size_t line = bytes.rfind('\n', end);
  return line == std::string::npos ? bytes.size() : line + 1;
}

std::vector<Sample> samples(const testing::TempDir& dir) {
  std::vector<Sample> v;
  auto add = [&](const std::string& name, bool text, std::size_t magic_at = 0) {
    const std::string b = slurp(dir / name);
    v.push_back({name, b, min_cut(b, text), magic_at});
  };
  const Mesh mesh = synthetic::to_mesh(synthetic::torus(10, 3, 12, 6));
  write_mesh(mesh, dir / "m.off");
  add("m.off", true);
  WriteOptions ascii;
  ascii.binary = false;
  write_mesh(mesh, dir / "m.obj", ascii);
  add("m.obj", true);
  v.back().magic_at = v.back().bytes.find("\nv ") + 1;  // OBJ has no magic: break the first vertex
  write_mesh(mesh, dir / "m.ply");
  add("m.ply", false);
  write_mesh(mesh, dir / "m.stl");
  add("m.stl", false, 80);
  write_mesh(mesh, dir / "m.vtk", ascii);
  add("m.vtk", true);
  write_mesh(mesh, dir / "m.vtp");
  add("m.vtp", false);
  const auto ct = small_ct();
  write_itk(ct.GetPointer(), dir / "v.nrrd", false);
  add("v.nrrd", false);
  write_itk(ct.GetPointer(), dir / "vz.nrrd", true);
  add("vz.nrrd", false);
  write_itk(ct.GetPointer(), dir / "v.nii", false);
  add("v.nii", false, 344);  // NIfTI-1 magic "n+1" at byte 344
  write_itk(ct.GetPointer(), dir / "v.nii.gz", true);
  add("v.nii.gz", false);
  write_itk(ct.GetPointer(), dir / "v.mha", false);
  add("v.mha", false);
  v.back().magic_at = v.back().bytes.find("ElementType = ") + 14;  // MetaImage: no magic; break the voxel type
  write_itk(ct.GetPointer(), dir / "vz.mha", true);
  add("vz.mha", false);
  v.back().magic_at = v.back().bytes.find("ElementType = ") + 14;  // MetaImage: no magic; break the voxel type
  write_dicom_series(ct.GetPointer(), dir / "dicom");
  fs::copy_file(dir / "dicom" / "IM00001.dcm", dir / "v.dcm");
  add("v.dcm", false, 128);
  fs::remove_all(dir / "dicom");
  return v;
}

// Corruption kinds a format can reveal: formats without counts (OBJ) cannot reveal a truncation
// at a record boundary; binary STL has no magic (80 free header bytes); DICOM and compressed
// volumes carry their sizes inside binary or compressed headers.
std::vector<Corruption> kinds_for(const std::string& name) {
  const std::string ext = full_extension(name);
  if (ext == ".obj") return {Corruption::kEnlargeSize, Corruption::kBreakMagic};
  if (ext == ".stl") return {Corruption::kTruncate, Corruption::kEnlargeSize};
  if (ext == ".dcm" || ext == ".nii.gz" || name == "vz.nrrd")
    return {Corruption::kTruncate, Corruption::kBreakMagic};
  return {Corruption::kTruncate, Corruption::kEnlargeSize, Corruption::kBreakMagic};
}

double max_rss_mib() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

// >= 1000 corrupted inputs over every reader: exit 2/3, one error line, no output, no temporary,
// input unchanged, peak memory < 1 GB, under 2 minutes.
TEST(RobustFuzz, RandomCorruptionOverEveryReader) {
  testing::TempDir dir;
  const std::vector<Sample> base = samples(dir);
  const bool mesh_stage = bool(find_stage("denoise"));
  std::mt19937 rng(20261201);
  Stopwatch clock;
  std::size_t runs = 0;
  for (int round = 0; runs < 1000; ++round) {
    for (const Sample& s : base) {
      for (Corruption c : kinds_for(s.name)) {
        const fs::path in = dir / ("in_" + s.name), out = dir / "out";
        const std::string bytes = corrupt(s, c, rng);
        spit(in, bytes);
        const bool is_mesh = bool(mesh_format_from_path(in));
        const auto r = is_mesh && mesh_stage
                           ? colonflat({"denoise", in.string(), "-o", (out / "d.vtp").string(), "-q"})
                           : colonflat({"info", in.string()});
        const std::string cmd = is_mesh && mesh_stage ? "denoise" : "info";
        ++runs;
        const std::string what = s.name + " corruption " + std::to_string(int(c)) + " round " + std::to_string(round);
        ASSERT_TRUE(r.code == 2 || r.code == 3) << what << ": exit " << r.code << "\n" << r.out << r.err;
        ASSERT_TRUE(one_error_line(r, cmd, in.string())) << what;
        ASSERT_FALSE(fs::exists(out)) << what;
        ASSERT_TRUE(leftovers(dir.path()).empty()) << what;
        ASSERT_EQ(slurp(in), bytes) << what;
      }
    }
  }
  EXPECT_GE(runs, 1000u);
  EXPECT_LT(clock.seconds(), 120.0);
  EXPECT_LT(max_rss_mib(), 1024.0);
  std::cout << runs << " corrupted inputs in " << clock.seconds() << " s, peak " << max_rss_mib() << " MiB\n";
}

}  // namespace
}  // namespace cf::robust
