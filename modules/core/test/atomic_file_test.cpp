// Atomic outputs: all-or-nothing, the previous file stays when writing fails.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A throwing writer leaves the target as it was and removes its temporary.
TEST(AtomicFile, ThrowingWriterLeavesTarget) {
  testing::TempDir dir;
  const fs::path d = dir.path();
  write_text_atomically(d / "a.txt", "one");
  EXPECT_THROW(write_atomically(d / "a.txt",
                                [](const fs::path& tmp) {
                                  std::ofstream(tmp) << "partial";
                                  throw Error("boom");
                                }),
               Error);
  EXPECT_EQ(slurp(d / "a.txt"), "one");
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator()), 1);
}

// A transaction that is not committed leaves no file; a committed one writes all.
TEST(AtomicFile, TransactionIsAllOrNothing) {
  testing::TempDir dir;
  const fs::path d = dir.path() / "out";
  {
    OutputTransaction tx;
    std::ofstream(tx.stage(d / "x.txt")) << "x";
    std::ofstream(tx.stage(d / "sub" / "y.txt")) << "y";
  }
  EXPECT_FALSE(fs::exists(d / "x.txt"));
  EXPECT_FALSE(fs::exists(d / "sub" / "y.txt"));
  {
    OutputTransaction tx;
    std::ofstream(tx.stage(d / "x.txt")) << "x";
    std::ofstream(tx.stage(d / "sub" / "y.txt")) << "y";
    tx.commit();
  }
  EXPECT_EQ(slurp(d / "x.txt"), "x");
  EXPECT_EQ(slurp(d / "sub" / "y.txt"), "y");
}

// The temporary keeps the target's extension (format detection by extension still works).
TEST(AtomicFile, TempKeepsExtension) {
  EXPECT_EQ(temp_sibling("/a/b/mesh.vtp").extension(), ".vtp");
  EXPECT_EQ(temp_sibling("/a/b/mesh.vtp").parent_path(), fs::path("/a/b"));
}

}  // namespace
}  // namespace cf
