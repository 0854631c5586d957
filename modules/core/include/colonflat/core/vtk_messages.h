#pragma once
// VTK reports problems by printing through its output window and carrying on. While a
// VtkMessageCapture lives, those messages are collected instead of printed, so callers can turn
// them into one clear error (and nothing VTK says leaks onto the user's terminal).
#include <string>
#include <vector>

class vtkOutputWindow;

namespace cf {

class VtkMessageCapture {
 public:
  VtkMessageCapture();
  ~VtkMessageCapture();
  VtkMessageCapture(const VtkMessageCapture&) = delete;
  VtkMessageCapture& operator=(const VtkMessageCapture&) = delete;
  // Errors and warnings seen so far, each reduced to its text (no file/line prefix).
  const std::vector<std::string>& errors() const;
  const std::vector<std::string>& warnings() const;
  // The first error, else the first warning, else "".
  std::string first_problem() const;

 private:
  vtkOutputWindow* previous_;
  vtkOutputWindow* window_;
};

}  // namespace cf
