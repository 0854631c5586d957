// VtkMessageCapture on several threads and BackgroundOutputWriter (core vtk_messages.h,
// stage_runner.h): what `colonflat run` relies on to write a stage's files while the next runs;
// run_stage_recorded's release of the memory a stage freed.
#include <gtest/gtest.h>

#include "colonflat/testing/resident_memory.h"

#include <malloc.h>
#include <unistd.h>

#include <vtkNew.h>
#include <vtkXMLPolyDataReader.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "colonflat/core/run_stats.h"
#include "colonflat/core/stage.h"
#include "colonflat/core/stage_runner.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {
namespace {

// Reads a file that does not exist: VTK reports an error naming it through its output window.
void read_missing(const std::string& name) {
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(name.c_str());
  r->Update();
}

bool mentions(const std::vector<std::string>& lines, const std::string& what) {
  for (const auto& l : lines)
    if (l.find(what) != std::string::npos) return true;
  return false;
}

// Two threads, each with its own capture alive at the same time, each get exactly their own
// thread's VTK errors (the file each one read), never the other's.
TEST(CoreVtkMessages, CapturesOnTwoThreadsGetTheirOwnMessages) {
  std::atomic<int> ready{0};
  std::vector<std::string> errors[2];
  auto worker = [&](int t) {
    VtkMessageCapture capture;
    ++ready;
    while (ready < 2) std::this_thread::yield();  // both captures alive
    for (int k = 0; k < 20; ++k) read_missing("/nonexistent/thread_" + std::to_string(t) + ".vtp");
    ++ready;
    while (ready < 4) std::this_thread::yield();  // neither ends before the other read
    errors[t] = capture.errors();
  };
  std::thread a(worker, 0), b(worker, 1);
  a.join();
  b.join();
  for (int t = 0; t < 2; ++t) {
    EXPECT_TRUE(mentions(errors[t], "thread_" + std::to_string(t))) << t;
    EXPECT_FALSE(mentions(errors[t], "thread_" + std::to_string(1 - t))) << t;
  }
}

// A capture nested in another on one thread gets the messages while it lives; the outer one
// gets those before and after.
TEST(CoreVtkMessages, InnermostCaptureOfAThreadGetsItsMessages) {
  VtkMessageCapture outer;
  read_missing("/nonexistent/before.vtp");
  {
    VtkMessageCapture inner;
    read_missing("/nonexistent/inner.vtp");
    EXPECT_TRUE(mentions(inner.errors(), "inner.vtp"));
    EXPECT_FALSE(mentions(inner.errors(), "before.vtp"));
  }
  read_missing("/nonexistent/after.vtp");
  EXPECT_TRUE(mentions(outer.errors(), "before.vtp"));
  EXPECT_TRUE(mentions(outer.errors(), "after.vtp"));
  EXPECT_FALSE(mentions(outer.errors(), "inner.vtp"));
}

// Jobs run one after the other in submission order, and a failed job's error reaches the next
// submit() or wait() (the run fails with the write's message).
TEST(CoreBackgroundOutputWriter, RunsJobsInOrderAndRethrowsAFailedWrite) {
  std::vector<int> order;
  BackgroundOutputWriter writer;
  for (int i = 0; i < 3; ++i) {
    PendingOutputs job;
    job.writes.push_back([&order, i] {
      std::this_thread::sleep_for(std::chrono::milliseconds(5 * (3 - i)));
      order.push_back(i);
    });
    writer.submit(std::move(job));
  }
  writer.wait();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2}));
  PendingOutputs failing;
  failing.writes.push_back([] { throw std::runtime_error("cannot write: no space left on device"); });
  writer.submit(std::move(failing));
  try {
    writer.wait();
    FAIL() << "the failed write was not rethrown";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write: no space left on device");
  }
  writer.wait();  // the error is reported once
}

// Stopwatch::lap returns the time since the start (or the previous lap) and starts a new interval:
// consecutive laps split the time a second stopwatch measures over them, without a gap or overlap.
TEST(CoreStopwatch, LapsSplitTheIntervalAndRestart) {
  const Stopwatch whole;
  Stopwatch laps;
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  const double first = laps.lap();
  EXPECT_GE(first, 0.03);
  EXPECT_LT(laps.seconds(), first);  // restarted by the lap
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double second = laps.lap();
  EXPECT_GE(second, 0.01);
  const double total = whole.seconds();
  EXPECT_LE(first + second, total);
  EXPECT_GT(first + second, total - 0.25);  // a loaded machine may pause the thread between the calls
}

// A stage that fills and frees a 64 MiB scratch block, nothing else (no parameters, no ports).
class ScratchStage : public Stage {
 public:
  const StageSpec& spec() const override {
    static const StageSpec s{"scratch", "fills and frees a scratch block", {}, {}};
    return s;
  }
  std::vector<ParamInfo> params() const override { return {}; }
  void add_cli_options(CLI::App&) override {}
  nlohmann::json params_json() const override { return nlohmann::json::object(); }
  void set_params_json(const nlohmann::json&, const std::string&) override {}
  void validate_params() const override {}
  void run(ArtifactBag&, RunContext&) override {
    char* block = static_cast<char*>(std::malloc(kBytes));
    if (!block) throw Error("no memory for the scratch block");
    std::memset(block, 1, kBytes);
    __asm__ volatile("" : : "r"(block) : "memory");  // the writes happen (not optimised away)
    std::free(block);
  }
  static constexpr std::size_t kBytes = std::size_t(64) << 20;
};

// With malloc keeping freed blocks in the heap (ColonFlat's thresholds, set here with mallopt),
// the 64 MiB a stage freed are not resident any more once run_stage_recorded returns: the next
// stage's peak does not carry them.
TEST(CoreStageRunner, MemoryTheStageFreedIsGivenBack) {
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 1 << 30), 1);
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
  const double before = testing::resident_mib();
  ScratchStage stage;
  ArtifactBag bag;
  RunContext ctx;
  run_stage_recorded(stage, bag, ctx, 0.0);
  const double after = testing::resident_mib();
  mallopt(M_TRIM_THRESHOLD, 128 * 1024);
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  EXPECT_LT(after - before, 16.0) << "resident after the stage: +" << after - before << " MiB";
}

}  // namespace
}  // namespace cf
