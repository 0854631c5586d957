// C-GET of a study and C-STORE of results (DCMTK dcmnet's DcmSCU), each failure in one line.
#include "colonflat/dicom/pacs.h"

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <dcmtk/dcmnet/diutil.h>
#include <dcmtk/dcmnet/scu.h>

#include <set>

#include "colonflat/core/error.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// What a result of ours or a CT colonography study holds.
const char* const kStorageClasses[] = {
    UID_CTImageStorage, UID_EnhancedCTImageStorage, UID_SecondaryCaptureImageStorage, UID_SegmentationStorage,
    UID_Comprehensive3DSRStorage, UID_ComprehensiveSRStorage, UID_EnhancedSRStorage, UID_BasicTextSRStorage,
    UID_GrayscaleSoftcopyPresentationStateStorage};

OFList<OFString> transfer_syntaxes() {
  OFList<OFString> ts;
  ts.push_back(UID_LittleEndianExplicitTransferSyntax);
  ts.push_back(UID_LittleEndianImplicitTransferSyntax);
  return ts;
}

// The cause of a failed connection or association, in words.
std::string association_problem(const OFCondition& c, const PacsOptions& o) {
  const std::string t = c.text();
  if (c == DUL_ASSOCIATIONREJECTED)
    return "association refused (is the PACS's AE title " + o.peer.aet + " and does it know " + o.own_aet + "?)";
  if (t.find("refused") != std::string::npos) return "no association: connection refused (is the PACS running?)";
  if (t.find("imeout") != std::string::npos || t.find("timed out") != std::string::npos)
    return "no association: time-out after " + std::to_string(o.timeout_s) + " s";
  return "no association: " + t;
}

// An SCU with our AE title, the peer, the time-outs; associated (else throws).
class Association {
 public:
  Association(const PacsOptions& o, const std::vector<std::pair<std::string, T_ASC_SC_ROLE>>& contexts) : o_(o) {
    dicom::quiet_dcmtk();
    scu_.setAETitle(o.own_aet.c_str());
    scu_.setPeerHostName(o.peer.host.c_str());
    scu_.setPeerPort(Uint16(o.peer.port));
    scu_.setPeerAETitle(o.peer.aet.c_str());
    scu_.setConnectionTimeout(o.timeout_s);
    scu_.setACSETimeout(Uint32(o.timeout_s));
    scu_.setDIMSETimeout(Uint32(o.timeout_s));
    scu_.setDIMSEBlockingMode(DIMSE_NONBLOCKING);
    for (const auto& [syntax, role] : contexts) scu_.addPresentationContext(syntax.c_str(), transfer_syntaxes(), role);
    OFCondition c = scu_.initNetwork();
    if (c.good()) c = scu_.negotiateAssociation();
    if (c.bad()) throw Error("PACS " + o.peer.text() + ": " + association_problem(c, o));
  }
  ~Association() {
    if (scu_.isConnected()) scu_.releaseAssociation();
  }
  DcmSCU& scu() { return scu_; }
  [[noreturn]] void fail(const std::string& what) { throw Error("PACS " + o_.peer.text() + ": " + what); }

 private:
  const PacsOptions& o_;
  DcmSCU scu_;
};

}  // namespace

PacsPeer parse_pacs_address(const std::string& address, const std::string& option) {
  const auto at = address.find('@'), colon = address.rfind(':');
  PacsPeer p;
  if (at == std::string::npos || colon == std::string::npos || colon < at) {
    throw UsageError(option + " expects AET@HOST:PORT (got '" + address + "')");
  }
  p.aet = address.substr(0, at);
  p.host = address.substr(at + 1, colon - at - 1);
  const std::string port = address.substr(colon + 1);
  p.port = port.find_first_not_of("0123456789") == std::string::npos && !port.empty() ? std::stoi(port) : 0;
  if (p.aet.empty() || p.aet.size() > 16 || p.host.empty() || p.port < 1 || p.port > 65535)
    throw UsageError(option + " expects AET@HOST:PORT with an AE title of 1-16 characters and a port 1-65535 (got '" +
                     address + "')");
  return p;
}

std::size_t pacs_get_study(const PacsOptions& o, const std::string& study_uid, const fs::path& dir) {
  std::vector<std::pair<std::string, T_ASC_SC_ROLE>> contexts = {
      {UID_GETStudyRootQueryRetrieveInformationModel, ASC_SC_ROLE_DEFAULT}};
  for (const char* sop : kStorageClasses) contexts.emplace_back(sop, ASC_SC_ROLE_SCP);
  fs::create_directories(dir);
  Association a(o, contexts);
  a.scu().setStorageDir(dir.c_str());
  a.scu().setStorageMode(DCMSCU_STORAGE_DISK);
  const T_ASC_PresentationContextID pc = a.scu().findPresentationContextID(UID_GETStudyRootQueryRetrieveInformationModel, "");
  if (pc == 0) a.fail("does not offer C-GET (Study Root)");
  DcmDataset request;
  request.putAndInsertString(DCM_QueryRetrieveLevel, "STUDY");
  request.putAndInsertString(DCM_StudyInstanceUID, study_uid.c_str());
  OFList<RetrieveResponse*> responses;
  const OFCondition c = a.scu().sendCGETRequest(pc, &request, &responses);
  Uint16 status = 0, completed = 0, failed = 0, warned = 0;
  if (!responses.empty()) {
    const RetrieveResponse* last = responses.back();
    status = last->m_status, completed = last->m_numberOfCompletedSubops, failed = last->m_numberOfFailedSubops;
    warned = last->m_numberOfWarningSubops;
  }
  for (RetrieveResponse* r : responses) delete r;
  if (c.bad()) a.fail(std::string("C-GET of study ") + study_uid + " failed: " + c.text());
  if (failed || warned || (status != STATUS_Success && completed))
    a.fail("study " + study_uid + " incomplete: " + std::to_string(failed + warned) + " of " +
           std::to_string(completed + failed + warned) + " instances not retrieved");
  std::size_t received = 0;
  for (const auto& e : fs::directory_iterator(dir)) received += e.is_regular_file() ? 1 : 0;
  if (received == 0) a.fail("study " + study_uid + " not found");
  return received;
}

void pacs_store(const PacsOptions& o, const std::vector<fs::path>& files) {
  std::set<std::string> classes;
  for (const auto& f : files) {
    DcmFileFormat ff;
    if (ff.loadFileUntilTag(f.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_fileOnly, DCM_PixelData).bad())
      throw InputError(f.string(), "not a DICOM file");
    classes.insert(dicom::text(ff.getDataset(), DCM_SOPClassUID));
  }
  std::vector<std::pair<std::string, T_ASC_SC_ROLE>> contexts;
  for (const auto& c : classes) contexts.emplace_back(c, ASC_SC_ROLE_DEFAULT);
  Association a(o, contexts);
  for (const auto& f : files) {
    DcmFileFormat ff;
    ff.loadFile(f.c_str());
    const std::string sop = dicom::text(ff.getDataset(), DCM_SOPClassUID);
    const T_ASC_PresentationContextID pc = a.scu().findPresentationContextID(sop.c_str(), "");
    if (pc == 0) a.fail("does not accept " + f.filename().string() + " (SOP class " + sop + ")");
    Uint16 status = 0;
    const OFCondition c = a.scu().sendSTORERequest(pc, "", ff.getDataset(), status);
    if (c.bad()) a.fail("C-STORE of " + f.filename().string() + " failed: " + c.text());
    if (status != STATUS_Success) a.fail("refused " + f.filename().string() + " (status " + std::to_string(status) + ")");
  }
}

}  // namespace cf
