// PACS round trip (issue 28 items 3-5) against a real Orthanc (Debian package `orthanc`), never a
// mock: the test starts /usr/sbin/Orthanc on loopback ports it picks, with a configuration it
// writes into a temporary folder, stores the phantom exam in it (DCMTK's storescu), runs
// `colonflat run --pacs ... --store`, checks through Orthanc's REST API (loopback) that the study
// now holds the SEG, SR and SC series, checks the failure cases, and stops Orthanc at the end.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "colonflat/dicom/exam.h"
#include "colonflat/pipeline/registry.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/files.h"
#include "colonflat/testing/shell.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr const char* kOrthanc = "/usr/sbin/Orthanc";

using testing::shell;

// A TCP port on the loopback that nothing listens on now (the kernel's choice).
int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(s);
  return ntohs(a.sin_port);
}

// One Orthanc in a temporary folder, on ports of its own; stopped (SIGTERM, then waited for) by
// stop() or the destructor.
class Orthanc {
 public:
  explicit Orthanc(const fs::path& dir) : dir_(dir), http_(free_port()), dicom_(free_port()) {
    fs::create_directories(dir / "db");
    const nlohmann::json config = {{"Name", "colonflat-test"},        {"StorageDirectory", (dir / "db").string()},
                                   {"IndexDirectory", (dir / "db").string()}, {"HttpPort", http_},
                                   {"DicomPort", dicom_},               {"DicomAet", "ORTHANC"},
                                   {"DicomCheckCalledAet", true},       {"RemoteAccessAllowed", false},
                                   {"AuthenticationEnabled", false},    {"Plugins", nlohmann::json::array()},
                                   {"DicomAlwaysAllowStore", true},     {"DicomAlwaysAllowGet", true},
                                   {"DicomCheckModalityHost", false}};
    std::ofstream(dir / "orthanc.json") << config.dump(2);
  }
  ~Orthanc() { stop(); }
  // Starts it and waits (up to 30 s) until its REST API answers.
  bool start() {
    pid_ = ::fork();
    if (pid_ == 0) {
      const std::string log = (dir_ / "orthanc.log").string(), cfg = (dir_ / "orthanc.json").string();
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      ::execl(kOrthanc, kOrthanc, cfg.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    for (int i = 0; i < 300; ++i) {
      if (rest("/system").first == 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  // GET (or POST with `body`) on the REST API, loopback only.
  std::pair<int, std::string> rest(const std::string& path, const std::string& body = "") const {
    std::string cmd = "curl -sf --max-time 10 http://127.0.0.1:" + std::to_string(http_) + path;
    if (!body.empty()) cmd += " -X POST -d '" + body + "'";
    return shell(cmd);
  }
  std::string address(const std::string& aet = "ORTHANC") const {
    return aet + "@127.0.0.1:" + std::to_string(dicom_);
  }
  int dicom_port() const { return dicom_; }
  // The modality of every series of the study, sorted ("CT", "OT", "SEG", "SR", ...).
  std::vector<std::string> series_modalities(const std::string& study_uid) const {
    const auto [code, out] =
        rest("/tools/find", nlohmann::json{{"Level", "Series"}, {"Expand", true},
                                            {"Query", {{"StudyInstanceUID", study_uid}}}}.dump());
    std::vector<std::string> m;
    if (code != 0) return m;
    for (const auto& s : nlohmann::json::parse(out)) m.push_back(s["MainDicomTags"].value("Modality", ""));
    std::sort(m.begin(), m.end());
    return m;
  }

 private:
  fs::path dir_;
  int http_, dicom_;
  pid_t pid_ = -1;
};

class PacsOrthanc : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kOrthanc)) GTEST_SKIP() << "Orthanc not installed (scripts/install-deps.sh installs it)";
    if (shell("command -v storescu && command -v curl").first != 0) GTEST_SKIP() << "storescu or curl missing";
    if (!find_stage("render")) GTEST_SKIP() << "this build lacks the render stage";
    orthanc_ = std::make_unique<Orthanc>(dir_ / "orthanc");
    ASSERT_TRUE(orthanc_->start()) << testing::slurp(dir_ / "orthanc" / "orthanc.log");
    const auto p = testing::run_colonflat({"phantom", "--exam", "-o", dir_.str("phantom"), "--seed", "2", "--size",
                                           "small", "-q"});
    ASSERT_EQ(p.code, 0) << p.err;
    study_ = scan_exam(dir_ / "phantom" / "exam").front().study_uid;
    const auto s = shell("storescu -aet TESTER -aec ORTHANC +sd +r 127.0.0.1 " + std::to_string(orthanc_->dicom_port()) +
                         " " + dir_.str("phantom/exam"));
    ASSERT_EQ(s.first, 0) << s.second;
    ASSERT_EQ(orthanc_->series_modalities(study_), (std::vector<std::string>{"CT", "CT", "CT"}));
  }
  testing::TempDir dir_;
  std::unique_ptr<Orthanc> orthanc_;
  std::string study_;
};

// The study retrieved by C-GET runs as an exam (supine + prone, the localizer left out), and with
// --store its SEG, SR and SC of both scans land in the same study.
TEST_F(PacsOrthanc, RunFromPacsStoresSegSrAndScInTheStudy) {
  const auto r = testing::run_colonflat({"run", "--pacs", orthanc_->address(), "--study", study_, "-o",
                                         dir_.str("out"), "--store", "--set", "render.snapshots=false"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("stored 6 DICOM objects in study " + study_), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("not used: series 1"), std::string::npos) << r.err;
  EXPECT_EQ(orthanc_->series_modalities(study_),
            (std::vector<std::string>{"CT", "CT", "CT", "OT", "OT", "SEG", "SEG", "SR", "SR"}));
  const nlohmann::json report = nlohmann::json::parse(testing::slurp(dir_ / "out" / "supine" / "run_report.json"));
  EXPECT_EQ(report["exam"]["used"].size(), 2u);
  EXPECT_EQ(report["exam"]["not_used"][0]["series_number"], 1);
}

// Wrong AE title, unknown study, Orthanc stopped: one error line each, exit 1, nothing stored
// and no output folder.
TEST_F(PacsOrthanc, FailuresGiveOneClearErrorAndStoreNothing) {
  struct Case {
    std::string address, study, words;
  };
  const std::vector<Case> cases = {
      {orthanc_->address("WRONG"), study_, "association refused"},
      {orthanc_->address(), "1.2.3.4.5", "study 1.2.3.4.5 not found"},
  };
  for (const auto& c : cases) {
    const auto r = testing::run_colonflat({"run", "--pacs", c.address, "--study", c.study, "-o", dir_.str("out"),
                                           "--store", "-q"});
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("colonflat run: error: PACS " + c.address + ": " + c.words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
  EXPECT_EQ(orthanc_->series_modalities(study_), (std::vector<std::string>{"CT", "CT", "CT"}));
  const std::string address = orthanc_->address();
  orthanc_->stop();
  const auto r = testing::run_colonflat({"run", "--pacs", address, "--study", study_, "-o", dir_.str("out"), "-q"});
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err, "colonflat run: error: PACS " + address + ": no association: connection refused (is the PACS running?)\n");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  const std::string retrieved = "colonflat-pacs-" + std::to_string(::getpid()) + "-";
  for (const auto& e : fs::directory_iterator(fs::temp_directory_path()))  // no retrieved study left behind
    EXPECT_NE(e.path().filename().string().rfind(retrieved, 0), 0u) << e.path();
}

}  // namespace
}  // namespace cf
