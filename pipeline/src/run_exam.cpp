// `colonflat run EXAM -o OUT`: a DICOM exam as INPUT (issue 28 item 1). Its CT colonography scans
// are chosen by modules/dicom (exam.h); the run then goes on as `run SERIES` or, for a supine and
// a prone scan, as `run SUPINE --prone PRONE`.
#include <system_error>

#include "colonflat/dicom/exam.h"
#include "colonflat/volume/volume_io.h"
#include "run_plan.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// A DICOMDIR, a folder with DICOM files in subfolders, or a folder holding several series.
bool exam_input(const std::string& input) {
  if (input.empty()) return false;
  if (is_dicom_exam(input)) return true;
  std::error_code ec;
  return fs::is_directory(input, ec) && list_dicom_series(input).size() > 1;
}

}  // namespace

bool resolve_exam_input(RunOptions& o, std::ostream* log, bool force) {
  if (!o.from.empty() || !(force || exam_input(o.input))) return false;
  const ExamChoice choice = choose_exam_scans(o.input, scan_exam(o.input));
  if (log) *log << "colonflat run: " << o.input << ": " << choice.text();
  o.exam = choice.to_json();
  o.exam["path"] = o.input;
  o.input = choice.supine->input_path().string();
  if (choice.two_scans()) o.prone = choice.prone->input_path().string();
  return true;
}

}  // namespace cf
