// Issue 14 items 1-2: no path written twice, no input ever written, outputs checked before the
// work, staging + rename, cleanup on failure, on signals and of stale temporaries.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "colonflat/core/atomic_file.h"
#include "support.h"

namespace cf::robust {
namespace {

class RobustPaths : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!find_stage("denoise")) GTEST_SKIP() << "no denoise stage in this build";
    input_ = torus_file(dir_, "t.off");
    original_ = slurp(input_);
  }
  // The command failed with exit 2, one error line naming `needle`, the input is unchanged and
  // no output or temporary appeared.
  void expect_refused(const CommandResult& r, const std::string& cmd, const std::string& needle) {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(one_error_line(r, cmd, needle));
    EXPECT_EQ(slurp(input_), original_);
    EXPECT_EQ(listing(dir_.path()), before_);
  }
  testing::TempDir dir_;
  fs::path input_;
  std::string original_;
  std::vector<std::string> before_ = {"t.off"};
};

// `--report` naming the input is refused before any work; the input keeps its bytes.
TEST_F(RobustPaths, ReportOverInputRefused) {
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("d.vtp"), "--report", input_.string(), "-q"}),
                 "denoise", "would overwrite the input");
}

// A hard link and a symbolic link to the input count as the input.
TEST_F(RobustPaths, HardAndSymbolicLinksToInputRefused) {
  fs::create_hard_link(input_, dir_ / "hard.json");
  fs::create_symlink(input_, dir_ / "soft.json");
  before_ = {"hard.json", "soft.json", "t.off"};
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("d.vtp"), "--report", dir_.str("hard.json")}),
                 "denoise", "would overwrite the input");
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("d.vtp"), "--params-out", dir_.str("soft.json")}),
                 "denoise", "would overwrite the input");
}

// Two outputs on one path (`--loops` = `-o`) are refused: the surface would be lost.
TEST_F(RobustPaths, SamePathTwiceRefused) {
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("x.vtp"), "--loops", dir_.str("x.vtp")}),
                 "denoise", "written twice");
}

// An empty output name, an unknown output format and an unwritable folder are refused up front.
TEST_F(RobustPaths, EmptyUnknownAndUnwritableOutputsRefused) {
  expect_refused(colonflat({"denoise", input_.string(), "-o", ""}), "denoise", "empty output path");
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("d.xyz")}), "denoise", "unknown format");
  fs::create_directory(dir_ / "ro");
  fs::permissions(dir_ / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  before_ = {"ro", "t.off"};
  if (::access((dir_ / "ro").c_str(), W_OK) == 0) GTEST_SKIP() << "running as root: permissions not enforced";
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("ro/d.vtp")}), "denoise", "not writable");
}

// `run --params-out INPUT` is refused before the first stage.
TEST_F(RobustPaths, RunParamsOutOverInputRefused) {
  expect_refused(colonflat({"run", input_.string(), "--from", "denoise", "-o", dir_.str("out"), "--params-out",
                            input_.string(), "-q"}),
                 "run", "would overwrite the input");
}

// `run -o` the folder holding the input, or a phantom folder (phantom.json), is refused: the
// ground truth (lumen_mask.nrrd, polyps.json) must not be replaced.
TEST_F(RobustPaths, RunIntoInputOrPhantomFolderRefused) {
  expect_refused(colonflat({"run", input_.string(), "--from", "denoise", "-o", dir_.path().string(), "-q"}), "run",
                 "folder holding the input");
  fs::create_directory(dir_ / "ph");
  spit(dir_ / "ph" / "phantom.json", "{}");
  before_ = {"ph", "ph/phantom.json", "t.off"};
  expect_refused(colonflat({"run", input_.string(), "--from", "denoise", "-o", dir_.str("ph"), "-q"}), "run",
                 "phantom folder");
}

// When the last output of `run` cannot be written (a folder in its place), nothing is written:
// the check happens before the first stage.
TEST_F(RobustPaths, RunLastOutputBlockedWritesNothing) {
  fs::create_directories(dir_ / "out" / "run_report.txt");
  before_ = {"out", "out/run_report.txt", "t.off"};
  expect_refused(colonflat({"run", input_.string(), "--from", "denoise", "--to", "denoise", "-o", dir_.str("out")}),
                 "run", "names a folder");
}

// A run that succeeds leaves its outputs and no staging folder or temporary.
TEST_F(RobustPaths, SuccessfulRunLeavesNoStaging) {
  auto r = colonflat({"run", input_.string(), "--from", "denoise", "--to", "denoise", "-o", dir_.str("out"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "denoised.vtp"));
  EXPECT_TRUE(leftovers(dir_.path()).empty());
  EXPECT_EQ(slurp(input_), original_);
}

// Stale staging folders and temporaries of a process that no longer exists are removed by the
// next command writing into that folder; those of live processes are kept.
TEST_F(RobustPaths, StaleTemporariesCleaned) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child), live = std::to_string(::getppid());
  fs::create_directories(dir_ / "out" / (".colonflat-staging-" + dead));
  spit(dir_ / "out" / (".colonflat-staging-" + dead) / "surface.vtp", "x");
  spit(dir_ / "out" / (".denoised.tmp-" + dead + "-0.vtp"), "x");
  spit(dir_ / "out" / (".denoised.tmp-" + live + "-0.vtp"), "x");
  auto r = colonflat({"run", input_.string(), "--from", "denoise", "--to", "denoise", "-o", dir_.str("out"), "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(leftovers(dir_ / "out"), std::vector<std::string>{".denoised.tmp-" + live + "-0.vtp"});
}

// SIGTERM and SIGINT during writing remove the staging folder and temporaries (the process then
// dies of the signal, as it should).
TEST(RobustSignals, InterruptRemovesStagingAndTemporaries) {
  testing::TempDir dir;
  for (int sig : {SIGTERM, SIGINT}) {
    const pid_t child = ::fork();
    if (child == 0) {
      OutputTransaction tx(dir.path());
      spit(tx.stage(dir / "a.vtp"), "staged in the staging folder");
      spit(tx.stage(dir / "sub" / "b.json"), "a temporary sibling");
      ::raise(sig);
      ::_exit(0);  // not reached
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig);
    EXPECT_TRUE(listing(dir.path()).empty()) << ::testing::PrintToString(listing(dir.path()));
  }
}

}  // namespace
}  // namespace cf::robust
