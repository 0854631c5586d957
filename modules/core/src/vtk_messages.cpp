#include "colonflat/core/vtk_messages.h"

#include <vtkAlgorithm.h>
#include <vtkErrorCode.h>
#include <vtkLogger.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>

#include <algorithm>

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

class CapturingWindow : public vtkOutputWindow {
 public:
  static CapturingWindow* New();
  vtkTypeMacro(CapturingWindow, vtkOutputWindow);
  void DisplayText(const char*) override {}
  void DisplayErrorText(const char* t) override { errors.push_back(clean(t)); }
  void DisplayWarningText(const char* t) override { warnings.push_back(clean(t)); }
  void DisplayGenericWarningText(const char* t) override { warnings.push_back(clean(t)); }
  void DisplayDebugText(const char*) override {}
  std::vector<std::string> errors, warnings;
};
vtkStandardNewMacro(CapturingWindow);

}  // namespace

VtkMessageCapture::VtkMessageCapture() {
  // VTK's logger prints its own coloured copy of errors to stderr: off while capturing.
  saved_verbosity_ = static_cast<int>(vtkLogger::GetCurrentVerbosityCutoff());
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  previous_ = vtkOutputWindow::GetInstance();
  if (previous_) previous_->Register(nullptr);
  window_ = CapturingWindow::New();
  vtkOutputWindow::SetInstance(window_);
}

VtkMessageCapture::~VtkMessageCapture() {
  vtkOutputWindow::SetInstance(previous_);
  if (previous_) previous_->UnRegister(nullptr);
  window_->Delete();
  vtkLogger::SetStderrVerbosity(static_cast<vtkLogger::Verbosity>(saved_verbosity_));
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
