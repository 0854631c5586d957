// `colonflat run --pacs AET@HOST:PORT --study UID -o OUT [--store]` (issue 28 item 3): the study
// retrieved with C-GET into a temporary folder, run as an exam, and with --store its DICOM results
// sent back with C-STORE once the whole run succeeded (modules/dicom, pacs.h).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <system_error>

#include "colonflat/core/error.h"
#include "colonflat/dicom/pacs.h"
#include "run_plan.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

PacsOptions pacs_options(const RunOptions& o) {
  PacsOptions p;
  p.peer = parse_pacs_address(o.pacs);
  p.own_aet = o.aet;
  if (p.own_aet.empty() || p.own_aet.size() > 16) throw UsageError("--aet must have 1-16 characters (got '" + o.aet + "')");
  return p;
}

// The DICOM results of the run, in the order they are sent.
std::vector<fs::path> result_files(const RunOptions& o) {
  std::vector<fs::path> dirs, files;
  if (o.prone.empty()) dirs = {fs::path(o.outdir) / "dicom"};
  else dirs = {fs::path(o.outdir) / "supine" / "dicom", fs::path(o.outdir) / "prone" / "dicom"};
  std::error_code ec;
  for (const auto& d : dirs)
    for (const auto& e : fs::directory_iterator(d, ec))
      if (e.path().extension() == ".dcm") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

PacsSession::PacsSession(RunOptions& o, std::ostream* log) : log_(log) {
  if (o.pacs.empty()) {
    if (o.store || !o.study.empty()) throw UsageError(std::string(o.store ? "--store" : "--study") + " needs --pacs");
    return;
  }
  if (!o.input.empty()) throw UsageError("--pacs replaces INPUT (got both: " + o.input + ")");
  if (!o.prone.empty()) throw UsageError("--pacs finds the prone scan in the study itself; --prone is not used with it");
  if (o.study.empty()) throw UsageError("--pacs needs --study UID (the StudyInstanceUID to retrieve)");
  const PacsOptions p = pacs_options(o);
  static std::atomic<unsigned> counter{0};
  folder_ = fs::temp_directory_path() / ("colonflat-pacs-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  if (log) *log << "colonflat run: retrieving study " << o.study << " from " << p.peer.text() << " (C-GET)\n";
  std::size_t n = 0;
  try {
    n = pacs_get_study(p, o.study, folder_);
  } catch (...) {  // the destructor does not run for a constructor that throws
    std::error_code ec;
    fs::remove_all(folder_, ec);
    throw;
  }
  if (log) *log << "colonflat run: " << n << " instances received\n";
  o.input = folder_.string();
}

PacsSession::~PacsSession() {
  std::error_code ec;
  if (!folder_.empty()) fs::remove_all(folder_, ec);
}

void PacsSession::store_results(const RunOptions& o, std::ostream& out) const {
  if (!active() || !o.store) return;
  const std::vector<fs::path> files = result_files(o);
  if (files.empty()) throw Error("--store: the run wrote no DICOM result (" + o.outdir + "/dicom/)");
  const PacsOptions p = pacs_options(o);
  pacs_store(p, files);
  if (!o.quiet) out << "stored " << files.size() << " DICOM objects in study " << o.study << " at " << p.peer.text() << "\n";
}

}  // namespace cf
