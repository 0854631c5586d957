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
// Root ignores permission bits, so as root the unwritable case runs as the user nobody.
TEST_F(RobustPaths, EmptyUnknownAndUnwritableOutputsRefused) {
  expect_refused(colonflat({"denoise", input_.string(), "-o", ""}), "denoise", "empty output path");
  expect_refused(colonflat({"denoise", input_.string(), "-o", dir_.str("d.xyz")}), "denoise", "unknown format");
  fs::create_directory(dir_ / "ro");
  using P = fs::perms;
  fs::permissions(dir_ / "ro", P::owner_read | P::owner_exec | P::group_read | P::group_exec | P::others_read | P::others_exec);
  before_ = {"ro", "t.off"};
  const std::vector<std::string> args = {"denoise", input_.string(), "-o", dir_.str("ro/d.vtp")};
  const CommandResult r = ::geteuid() == 0 ? colonflat_as_nobody(args) : colonflat(args);
  ASSERT_NE(r.code, 125) << r.err;
  expect_refused(r, "denoise", "is not writable");
}

// The same as nobody in a folder that is writable for nobody: the dropped rights do not by
// themselves make the command fail (the refusal above is the folder's permissions).
TEST_F(RobustPaths, UnprivilegedRunWritesWhereAllowed) {
  if (::geteuid() != 0) GTEST_SKIP() << "not root: the test above already ran unprivileged";
  fs::create_directory(dir_ / "rw");
  fs::permissions(dir_ / "rw", fs::perms::all);
  const CommandResult r = colonflat_as_nobody({"denoise", input_.string(), "-o", dir_.str("rw/d.vtp"), "-q"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "rw" / "d.vtp"));
  EXPECT_TRUE(leftovers(dir_.path()).empty());
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

// Issue 14 item 2 for stand-alone commands: every output of a folder goes into that folder's one
// staging folder under its own name (nothing else appears beside the targets), and appears
// only at the commit; a second folder gets its own staging folder.
TEST(RobustTransaction, OneStagingFolderPerOutputFolder) {
  testing::TempDir dir;
  OutputTransaction tx;
  const fs::path a = tx.stage(dir / "a.vtp"), b = tx.stage(dir / "b.json"), c = tx.stage(dir / "sub" / "c.png");
  EXPECT_EQ(a.parent_path(), b.parent_path());
  EXPECT_EQ(a.parent_path(), tx.staging_folder(dir.path()));
  EXPECT_EQ(a.parent_path().parent_path(), dir.path());
  EXPECT_EQ(a.filename(), "a.vtp");
  EXPECT_EQ(c.parent_path(), tx.staging_folder(dir / "sub"));
  EXPECT_NE(c.parent_path(), a.parent_path());
  spit(a, "a"), spit(b, "b"), spit(c, "c");
  const auto staged = listing(dir.path());
  EXPECT_EQ(std::count_if(staged.begin(), staged.end(), [](const std::string& f) { return f.find('/') == std::string::npos; }),
            2);  // the staging folder and sub/: no file beside the targets yet
  tx.commit();
  EXPECT_EQ(slurp(dir / "a.vtp"), "a");
  EXPECT_EQ(slurp(dir / "sub" / "c.png"), "c");
  EXPECT_THROW(tx.stage(dir / "a.vtp"), Error);  // the same target twice in one transaction
}

// A staged folder (the review report's report_files/) replaces an existing folder of that name on
// commit, and an uncommitted transaction leaves the old folder as it was.
TEST(RobustTransaction, StagedFolderReplacesOldFolderOnlyOnCommit) {
  testing::TempDir dir;
  fs::create_directories(dir / "files");
  spit(dir / "files" / "old.png", "old");
  for (const bool commit : {false, true}) {
    {
      OutputTransaction tx;
      const fs::path staged = tx.stage(dir / "files");
      fs::create_directories(staged);
      spit(staged / "new.png", "new");
      if (commit) tx.commit();
    }
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"files", commit ? "files/new.png" : "files/old.png"}));
  }
}

// SIGTERM and SIGINT during writing remove the staging folder and temporaries (the process then
// dies of the signal, as it should).
TEST(RobustSignals, InterruptRemovesStagingAndTemporaries) {
  testing::TempDir dir;
  for (int sig : {SIGTERM, SIGINT}) {
    const pid_t child = ::fork();
    if (child == 0) {
      OutputTransaction tx;
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
