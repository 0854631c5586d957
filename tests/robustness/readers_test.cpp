// Issue 14 item 3: readers verify what they read (sizes against headers, file size and memory
// budget before allocating; NaN/inf voxels; a CT is not a mask; degenerate faces refused).
#include <sys/resource.h>

#include "colonflat/core/run_stats.h"
#include "volumes.h"

namespace cf::robust {
namespace {

double max_rss_mib() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

// `colonflat info FILE` fails with exit 3 and one line naming the file and `needle`, within a
// second and without a large allocation.
void expect_bad_input(const fs::path& file, const std::string& needle) {
  Stopwatch clock;
  auto r = colonflat({"info", file.string()});
  EXPECT_EQ(r.code, 3) << r.out << r.err;
  EXPECT_TRUE(one_error_line(r, "info", file.string() + ": "));
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_LT(clock.seconds(), 1.0);
  EXPECT_LT(max_rss_mib(), 1024.0);
}

// Keeps the first `fraction` of a file's bytes.
void cut(const fs::path& p, double fraction) {
  const std::string s = slurp(p);
  spit(p, s.substr(0, std::size_t(double(s.size()) * fraction)));
}

// A NIfTI and a MetaImage cut in half are refused (the declared data do not fit the file).
TEST(RobustReaders, VolumesCutInHalfRefused) {
  testing::TempDir dir;
  for (const char* name : {"ct.nii", "ct.mha", "raw.nrrd"}) {
    write_itk(small_ct().GetPointer(), dir / name, false);
    cut(dir / name, 0.5);
    expect_bad_input(dir / name, "declares at least");
  }
  for (const char* name : {"ct.nii.gz", "ctz.mha", "ctz.nrrd"}) {  // compressed: the decoder notices
    write_itk(small_ct().GetPointer(), dir / name, true);
    cut(dir / name, 0.5);
    auto r = colonflat({"info", dir.str(name)});
    EXPECT_EQ(r.code, 3) << name << ": " << r.out << r.err;
    EXPECT_TRUE(one_error_line(r, "info", dir.str(name)));
  }
}

// A 1 KB NRRD header declaring 1500^3 voxels is refused at once, naming the sizes.
TEST(RobustReaders, HugeDeclaredNrrdRefusedFast) {
  testing::TempDir dir;
  spit(dir / "big.nrrd", "NRRD0004\ntype: short\ndimension: 3\nsizes: 1500 1500 1500\nencoding: raw\n"
                         "endian: little\nspace: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n\n" +
                             std::string(1000, '\0'));
  expect_bad_input(dir / "big.nrrd", "1500 x 1500 x 1500");
  spit(dir / "bigz.nrrd", "NRRD0004\ntype: short\ndimension: 3\nsizes: 1500 1500 1500\nencoding: gzip\n"
                          "endian: little\n\n" + std::string(1000, 'x'));
  expect_bad_input(dir / "bigz.nrrd", "1500 x 1500 x 1500");
}

// A NIfTI whose header is patched to declare 1000^3 voxels is refused before allocation.
TEST(RobustReaders, HugeDeclaredNiftiRefusedFast) {
  testing::TempDir dir;
  write_itk(small_ct().GetPointer(), dir / "ct.nii", false);
  std::string s = slurp(dir / "ct.nii");
  const std::int16_t thousand = 1000;
  for (int d = 1; d <= 3; ++d) std::memcpy(&s[40 + 2 * d], &thousand, 2);  // dim[1..3] of the NIfTI-1 header
  spit(dir / "ct.nii", s);
  expect_bad_input(dir / "ct.nii", "1000 x 1000 x 1000");
}

// The memory budget refuses a volume that fits its file but not the budget.
TEST(RobustReaders, MemoryBudgetRefusesBeforeAllocation) {
  testing::TempDir dir;
  write_itk(small_ct().GetPointer(), dir / "ct.nrrd", false);
  ::setenv("COLONFLAT_MEMORY_BUDGET_MIB", "0.01", 1);
  expect_bad_input(dir / "ct.nrrd", "memory budget");
  ::unsetenv("COLONFLAT_MEMORY_BUDGET_MIB");
}

// A float CT with NaN in every 7th voxel is refused with the count.
TEST(RobustReaders, NanVoxelsRefusedWithCount) {
  testing::TempDir dir;
  auto ct = small_ct();
  const std::size_t n = ct->GetLargestPossibleRegion().GetNumberOfPixels();
  std::size_t nans = 0;
  for (std::size_t i = 0; i < n; i += 7, ++nans) ct->GetBufferPointer()[i] = std::nanf("");
  ct->GetBufferPointer()[1] = INFINITY;
  write_itk(ct.GetPointer(), dir / "nan.nrrd", true);
  expect_bad_input(dir / "nan.nrrd", std::to_string(nans + 1) + " of " + std::to_string(n) + " voxels are NaN or infinite");
}

// A CT given where a mask is read (`reconstruct`, `run --from reconstruct`) is refused.
TEST(RobustReaders, CtIsNotAMask) {
  if (!find_stage("reconstruct")) GTEST_SKIP() << "no reconstruct stage";
  testing::TempDir dir;
  write_ct_volume(small_ct().GetPointer(), dir / "ct.nrrd");
  auto r = colonflat({"reconstruct", dir.str("ct.nrrd"), "-o", dir.str("s.vtp")});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_error_line(r, "reconstruct", "not a mask"));
  r = colonflat({"run", dir.str("ct.nrrd"), "--from", "reconstruct", "-o", dir.str("out"), "-q"});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_TRUE(one_error_line(r, "run", "not a mask"));
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"ct.nrrd"});
}

// `info` on a mask says it is a mask with its volume, not HU notes.
TEST(RobustReaders, InfoUnderstandsMasks) {
  testing::TempDir dir;
  auto mask = MaskImage::New();
  MaskImage::SizeType size{{10, 10, 10}};
  mask->SetRegions(MaskImage::RegionType(size));
  mask->Allocate();
  mask->FillBuffer(0);
  for (int i = 0; i < 100; ++i) mask->GetBufferPointer()[i] = 1;
  write_mask(mask.GetPointer(), dir / "m.nrrd");
  auto r = colonflat({"info", dir.str("m.nrrd")});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("100 voxels = 1"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("HU"), std::string::npos) << r.out;
}

// An OFF header declaring 10 M vertices without data is refused at once.
TEST(RobustReaders, HugeDeclaredMeshRefusedFast) {
  testing::TempDir dir;
  spit(dir / "big.off", "OFF\n10000000 20000000 0\n0 0 0\n");
  expect_bad_input(dir / "big.off", "10000000 vertices");
  spit(dir / "big.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 10000000\nproperty float x\n"
                        "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                        "end_header\n" + std::string(100, '\0'));
  expect_bad_input(dir / "big.ply", "10000000 vertices");
}

// A face with 2 vertices or a repeated corner ("3 0 0 0") is refused by the stages, never
// silently dropped.
TEST(RobustReaders, DegenerateFacesRefused) {
  if (!find_stage("denoise")) GTEST_SKIP() << "no denoise stage";
  testing::TempDir dir;
  const std::string tetra = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n";
  spit(dir / "two.off", tetra + "2 0 3\n");
  spit(dir / "rep.off", tetra + "3 0 0 0\n");
  for (const char* name : {"two.off", "rep.off"}) {
    std::string text = slurp(dir / name);
    text.replace(text.find("4 4 0"), 5, "4 4 0");
    auto r = colonflat({"denoise", dir.str(name), "-o", dir.str("d.vtp"), "-q"});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_TRUE(one_error_line(r, "denoise", dir.str(name)));
    EXPECT_TRUE(r.err.find("fewer than 3 vertices") != std::string::npos ||
                r.err.find("repeat") != std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "d.vtp"));
  }
}

}  // namespace
}  // namespace cf::robust
