#include "colonflat/core/vtk_messages.h"

#include <vtkAlgorithm.h>
#include <vtkErrorCode.h>
#include <vtkLogger.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>

#include <algorithm>
#include <mutex>

#include "colonflat/core/write_errors.h"

namespace cf {
namespace {

constexpr const char* kPipelineDump = " returned failure for request";

// "Algorithm vtkXMLPolyDataWriter (0x55..) returned failure for request: vtkInformation ..." ->
// "vtkXMLPolyDataWriter failed": the executive's dump of the request says nothing to a user.
std::string shorten_pipeline_dump(const std::string& s) {
  const auto at = s.find(kPipelineDump);
  if (at == std::string::npos) return s;
  std::string head = s.substr(0, at);
  if (head.rfind("Algorithm ", 0) == 0) head = head.substr(10);
  const auto paren = head.find(" (0x") != std::string::npos ? head.find(" (0x") : head.find("(0x");
  if (paren != std::string::npos) head = head.substr(0, paren);
  return head + " failed";
}

bool is_pipeline_dump(const std::string& s) {
  return s.size() > 7 && s.compare(s.size() - 7, 7, " failed") == 0 && s.find(' ') == s.size() - 7;
}

std::string clean(const char* text) {
  std::string s = text ? text : "";
  if (s.find(kPipelineDump) != std::string::npos) {
    // "ERROR: In .../vtkExecutive.cxx, line 753\nvtkCompositeDataPipeline (0x..): Algorithm ..."
    const auto alg = s.find("Algorithm ");
    return shorten_pipeline_dump(alg == std::string::npos ? s : s.substr(alg));
  }
  // "ERROR: In /path/file.cxx, line 12\nvtkXMLPolyDataReader (0x55..): message" -> "message"
  auto pos = s.find("): ");
  if (pos != std::string::npos) s = s.substr(pos + 3);
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s;
}

// One capture's messages (a vtkOutputWindow only to be deleted like one; never installed).
class CapturingWindow : public vtkOutputWindow {
 public:
  static CapturingWindow* New();
  vtkTypeMacro(CapturingWindow, vtkOutputWindow);
  std::vector<std::string> errors, warnings;
};
vtkStandardNewMacro(CapturingWindow);

// The process-wide state of the captures, under one mutex: the captures alive (in creation
// order), VTK's own window (kept, and given every message while no capture lives: the router
// is installed once and never removed, so no thread can be left holding a deleted window), and
// vtkLogger's stderr cutoff before the first of the captures alive.
struct Captures {
  std::mutex mutex;
  std::vector<CapturingWindow*> alive;
  vtkOutputWindow* previous = nullptr;
  bool routed = false;
  int saved_verbosity = 0;
};
Captures& captures() {
  static Captures c;
  return c;
}
thread_local std::vector<CapturingWindow*> tl_captures;  // this thread's captures, innermost last

// Installed at the first capture: each message goes to the calling thread's innermost capture,
// else to the capture created last, else (no capture alive) to VTK's own window.
class RoutingWindow : public vtkOutputWindow {
 public:
  static RoutingWindow* New();
  vtkTypeMacro(RoutingWindow, vtkOutputWindow);
  void DisplayText(const char* t) override { forward(t, &vtkOutputWindow::DisplayText); }
  void DisplayErrorText(const char* t) override {
    if (!add(t, true)) forward(t, &vtkOutputWindow::DisplayErrorText);
  }
  void DisplayWarningText(const char* t) override {
    if (!add(t, false)) forward(t, &vtkOutputWindow::DisplayWarningText);
  }
  void DisplayGenericWarningText(const char* t) override {
    if (!add(t, false)) forward(t, &vtkOutputWindow::DisplayGenericWarningText);
  }
  void DisplayDebugText(const char* t) override { forward(t, &vtkOutputWindow::DisplayDebugText); }

 private:
  // Stores the message in a capture; false when none is alive.
  static bool add(const char* t, bool error) {
    std::lock_guard<std::mutex> lock(captures().mutex);
    CapturingWindow* w = !tl_captures.empty() ? tl_captures.back()
                         : !captures().alive.empty() ? captures().alive.back() : nullptr;
    if (w) (error ? w->errors : w->warnings).push_back(clean(t));
    return w != nullptr;
  }
  // Text and debug lines while a capture lives are dropped (as before); otherwise VTK's window shows them.
  static void forward(const char* t, void (vtkOutputWindow::*show)(const char*)) {
    vtkOutputWindow* previous = nullptr;
    {
      std::lock_guard<std::mutex> lock(captures().mutex);
      if (captures().alive.empty()) previous = captures().previous;
    }
    if (previous) (previous->*show)(t);
  }
};
vtkStandardNewMacro(RoutingWindow);

}  // namespace

VtkMessageCapture::VtkMessageCapture() : window_(CapturingWindow::New()) {
  auto* w = static_cast<CapturingWindow*>(window_);
  Captures& c = captures();
  std::lock_guard<std::mutex> lock(c.mutex);
  if (!c.routed) {
    c.previous = vtkOutputWindow::GetInstance();
    if (c.previous) c.previous->Register(nullptr);  // kept for the process's life
    RoutingWindow* router = RoutingWindow::New();
    vtkOutputWindow::SetInstance(router);
    router->Delete();  // the instance slot holds it
    c.routed = true;
  }
  if (c.alive.empty()) {
    // VTK's logger prints its own coloured copy of errors to stderr: off while capturing.
    c.saved_verbosity = static_cast<int>(vtkLogger::GetCurrentVerbosityCutoff());
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  }
  c.alive.push_back(w);
  tl_captures.push_back(w);
}

VtkMessageCapture::~VtkMessageCapture() {
  auto* w = static_cast<CapturingWindow*>(window_);
  Captures& c = captures();
  {
    std::lock_guard<std::mutex> lock(c.mutex);
    c.alive.erase(std::find(c.alive.begin(), c.alive.end(), w));
    tl_captures.erase(std::find(tl_captures.begin(), tl_captures.end(), w));
    if (c.alive.empty()) vtkLogger::SetStderrVerbosity(static_cast<vtkLogger::Verbosity>(c.saved_verbosity));
  }
  window_->Delete();
}

const std::vector<std::string>& VtkMessageCapture::errors() const {
  return static_cast<CapturingWindow*>(window_)->errors;
}
const std::vector<std::string>& VtkMessageCapture::warnings() const {
  return static_cast<CapturingWindow*>(window_)->warnings;
}
std::string VtkMessageCapture::first_problem() const {
  for (const auto& e : errors())
    if (!is_pipeline_dump(e)) return e;
  if (!warnings().empty()) return warnings().front();
  if (!errors().empty()) return errors().front();
  return "";
}

std::string VtkMessageCapture::write_problem(vtkAlgorithm* writer, const std::string& file) const {
  const unsigned long code = writer ? writer->GetErrorCode() : 0;
  std::string problem = first_problem();
  if (code == vtkErrorCode::OutOfDiskSpaceError || problem.find("disk space") != std::string::npos)
    return "no space left on device";
  const std::string fs_problem = file_system_problem(file);
  if (!fs_problem.empty()) return fs_problem;
  if (!problem.empty()) return problem;
  if (code != vtkErrorCode::NoError) return "VTK error code " + std::to_string(code);  // its name lives in CommonMisc, not linked here
  return "the VTK writer failed";
}

}  // namespace cf
