#pragma once
// Some libraries print straight to the process's stderr/stdout (MetaImage, NrrdIO/teem, GDCM,
// NIfTI). While a LibraryOutputCapture lives, file descriptors 1 and 2 go to a temporary file, so
// that nothing reaches the user's terminal; text() returns what was printed, to be folded into
// one error line. Not thread-safe: use around a reader call on the main thread.
#include <string>

namespace cf {

class LibraryOutputCapture {
 public:
  LibraryOutputCapture();
  ~LibraryOutputCapture();
  LibraryOutputCapture(const LibraryOutputCapture&) = delete;
  LibraryOutputCapture& operator=(const LibraryOutputCapture&) = delete;
  // What was printed so far, without ANSI colour codes, lines joined by "; ".
  std::string text();

 private:
  void restore();
  int saved_out_ = -1, saved_err_ = -1, file_ = -1;
};

}  // namespace cf
