#include "colonflat/core/vtk_messages.h"

#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>

#include <algorithm>

namespace cf {
namespace {

std::string clean(const char* text) {
  std::string s = text ? text : "";
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
  previous_ = vtkOutputWindow::GetInstance();
  if (previous_) previous_->Register(nullptr);
  window_ = CapturingWindow::New();
  vtkOutputWindow::SetInstance(window_);
}

VtkMessageCapture::~VtkMessageCapture() {
  vtkOutputWindow::SetInstance(previous_);
  if (previous_) previous_->UnRegister(nullptr);
  window_->Delete();
}

const std::vector<std::string>& VtkMessageCapture::errors() const {
  return static_cast<CapturingWindow*>(window_)->errors;
}
const std::vector<std::string>& VtkMessageCapture::warnings() const {
  return static_cast<CapturingWindow*>(window_)->warnings;
}
std::string VtkMessageCapture::first_problem() const {
  if (!errors().empty()) return errors().front();
  if (!warnings().empty()) return warnings().front();
  return "";
}

}  // namespace cf
