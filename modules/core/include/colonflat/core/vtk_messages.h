#pragma once
// VTK reports problems by printing through its output window and carrying on. While a
// VtkMessageCapture lives, those messages are collected instead of printed, so callers can turn
// them into one clear error (and nothing VTK says leaks onto the user's terminal).
// Thread-safe: captures on different threads (a stage running while another thread writes the
// previous stage's files) each get their own thread's messages; a message from a thread without a
// capture (a VTK worker thread) goes to the capture created last.
#include <string>
#include <vector>

class vtkAlgorithm;
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
  // The first error, else the first warning, else "". VTK's pipeline dump ("Algorithm X returned
  // failure for request: vtkInformation ... Debug: Off ...") comes last, reduced to "X failed".
  std::string first_problem() const;
  // Why `writer` failed, in words: "no space left on device" (VTK's out-of-disk-space error code,
  // or a full file system at `file`), else first_problem(), else "VTK error code N".
  std::string write_problem(vtkAlgorithm* writer, const std::string& file) const;

 private:
  vtkOutputWindow* window_;  // this capture's messages (never installed: the shared router feeds it)
};

}  // namespace cf
