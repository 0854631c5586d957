// Issue 28 item 6: a write to a full file system gives one plain-words error ("no space left on
// device"), never a library's dump (VTK's "Algorithm ... returned failure for request:
// vtkInformation ..."), nothing on the process's own stderr, and leaves nothing behind.
// The full file system is a small tmpfs mounted by the test (skipped where mounting is not allowed).
#include <sys/mount.h>

#include <cerrno>
#include <cstring>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/write_errors.h"
#include "colonflat/core/library_output.h"
#include "support.h"

namespace cf::robust {
namespace {

constexpr std::size_t kFsBytes = 256 * 1024;  // the tmpfs
constexpr std::size_t kFreeBytes = 8 * 1024;  // left free once the filler is written

class RobustFullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!find_stage("denoise")) GTEST_SKIP() << "no denoise stage in this build";
    input_ = torus_file(dir_, "t.off");
    disk_ = dir_ / "disk";
    fs::create_directory(disk_);
    const std::string opts = "size=" + std::to_string(kFsBytes);
    if (::mount("tmpfs", disk_.c_str(), "tmpfs", 0, opts.c_str()) != 0)
      GTEST_SKIP() << "cannot mount a tmpfs here: " << std::strerror(errno);
    mounted_ = true;
    fill(kFsBytes - kFreeBytes);
    files_before_ = listing(disk_);
  }
  void TearDown() override {
    if (mounted_) ::umount2(disk_.c_str(), MNT_DETACH);
  }
  // A filler file of `bytes` on the tmpfs: what is left is a few KiB, less than any output.
  void fill(std::size_t bytes) const {
    std::ofstream f(disk_ / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (std::size_t n = 0; n + block.size() <= bytes; n += block.size()) f << block;
  }
  // `colonflat ARGS` failed with exit 1 and one error line saying "no space left on device",
  // printed nothing else (not even on the process's own stderr) and left nothing on the disk.
  void expect_disk_full(const std::vector<std::string>& args) {
    CommandResult r;
    std::string printed;
    {
      LibraryOutputCapture own_output;
      r = colonflat(args);
      printed = own_output.text();
    }
    SCOPED_TRACE(args[0] + " " + args.back());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(one_error_line(r, args[0], "no space left on device"));
    EXPECT_EQ(r.err.find("vtkInformation"), std::string::npos) << r.err;
    EXPECT_EQ(printed, "");
    EXPECT_EQ(listing(disk_), files_before_);
  }
  testing::TempDir dir_;
  fs::path input_, disk_;
  bool mounted_ = false;
  std::vector<std::string> files_before_;
};

// The file system helper names the cause only when there is one.
TEST_F(RobustFullDisk, FileSystemProblemNamesAFullDisk) {
  EXPECT_EQ(file_system_problem(dir_.path()), "");
  fill(kFsBytes);  // now truly full
  EXPECT_EQ(file_system_problem(disk_ / "any.vtp"), "no space left on device");
}

// VTK's XML writer (VTP), VTK's legacy writer and OpenMesh's OFF writer on a full disk.
TEST_F(RobustFullDisk, MeshWritersSayNoSpace) {
  for (const char* name : {"d.vtp", "d.vtk", "d.off"})
    expect_disk_full({"denoise", input_.string(), "-o", (disk_ / name).string(), "-q"});
}

// A report written with a plain stream (JSON, which fails silently) on the full disk, the mesh
// elsewhere: the transaction refuses to commit the cut report, and the mesh does not appear alone.
TEST_F(RobustFullDisk, TransactionRefusesCutReports) {
  fill(kFsBytes);
  files_before_ = listing(disk_);
  expect_disk_full({"denoise", input_.string(), "-o", dir_.str("d.vtp"), "--report", (disk_ / "report.json").string(),
                    "-q"});
  EXPECT_FALSE(fs::exists(dir_ / "d.vtp"));
}

}  // namespace
}  // namespace cf::robust
