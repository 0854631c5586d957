#pragma once
// A PACS as input and output (docs/pacs.md): a study retrieved with C-GET, results sent back with
// C-STORE (DCMTK dcmnet). Every failure is one line naming the PACS and the cause: no association
// (connection refused, time-out), association refused (unknown AE title), study not found, a
// series incomplete (failed sub-operations), an object refused.
#include <filesystem>
#include <string>
#include <vector>

namespace cf {

struct PacsPeer {
  std::string aet, host;
  int port = 0;
  std::string text() const { return aet + "@" + host + ":" + std::to_string(port); }
};

// "AET@HOST:PORT" -> peer. Throws UsageError naming `option` when malformed.
PacsPeer parse_pacs_address(const std::string& address, const std::string& option = "--pacs");

struct PacsOptions {
  PacsPeer peer;
  std::string own_aet = "COLONFLAT";  // our calling AE title
  int timeout_s = 30;                 // connection, association and each DIMSE message
};

// Retrieves every instance of the study into `dir` (flat, one file per instance) with C-GET at
// study level. Returns the number of instances received. Throws Error: no association, refused,
// time-out, study not found (no instance), incomplete (failed or warned sub-operations).
std::size_t pacs_get_study(const PacsOptions& o, const std::string& study_uid, const std::filesystem::path& dir);

// Sends the files with C-STORE on one association; throws Error at the first refusal (the
// association is opened before anything is sent: an unreachable or refusing PACS stores nothing).
void pacs_store(const PacsOptions& o, const std::vector<std::filesystem::path>& files);

}  // namespace cf
