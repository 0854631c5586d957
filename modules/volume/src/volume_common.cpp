// Helpers shared by the volume module's files: library quieting, names, ITK messages, formats.
#include <gdcmDirectory.h>
#include <gdcmReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>
#include <itkGDCMImageIO.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageRegionConstIterator.h>
#include <itkImageSeriesReader.h>
#include <itkImageSeriesWriter.h>
#include <itkMetaDataObject.h>
#include <itkMetaImageIO.h>
#include <itkMultiThreaderBase.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/threads.h"

#include "volume_internal.h"

namespace cf {
namespace vio {

const char* const kEnhancedCtSop = "1.2.840.10008.5.1.4.1.1.2.1";
const char* const kCtSop = "1.2.840.10008.5.1.4.1.1.2";
void quiet_libraries() {
  static std::once_flag once;
  std::call_once(once, [] {
    itk::Object::GlobalWarningDisplayOff();  // warnings would print to stderr; we report errors ourselves
    gdcm::Trace::WarningOff();
    gdcm::Trace::DebugOff();
    gdcm::Trace::ErrorOff();
  });
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// ".nii.gz" or the last extension, lower case.
std::string full_ext(const fs::path& p) {
  const std::string n = lower(p.filename().string());
  if (n.size() > 7 && n.compare(n.size() - 7, 7, ".nii.gz") == 0) return ".nii.gz";
  return lower(p.extension().string());
}

// First line of an ITK exception description, without ITK's decoration ("ITK ERROR:",
// "NrrdImageIO(0x55...):") and with a reason where ITK gives none.
std::string itk_message(const itk::ExceptionObject& e) {
  std::string d = e.GetDescription() ? e.GetDescription() : "";
  const auto nl = d.find('\n');
  if (nl != std::string::npos) d = d.substr(0, nl);
  if (d.rfind("ITK ERROR: ", 0) == 0) d = d.substr(11);
  const auto addr = d.find("(0x"), close = d.find("): ");
  if (addr != std::string::npos && close != std::string::npos && addr < close) d = d.substr(close + 3);
  while (!d.empty() && (d.back() == ' ' || d.back() == '.' || d.back() == '\r' || d.back() == ':')) d.pop_back();
  // "Read: Error reading <file>" says nothing more than that the pixel data could not be read.
  if (d.rfind("Read: Error reading", 0) == 0 || d.rfind("Error reading", 0) == 0)
    d = "cannot read the pixel data (truncated or corrupt file)";
  if (d.empty()) d = "unreadable";
  return d;
}

std::string trim(const char* v) {
  if (!v) return "";
  std::string s(v);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  std::size_t b = 0;
  while (b < s.size() && s[b] == ' ') ++b;
  return s.substr(b);
}

// A DICOM multi-valued decimal string "a\b\c" (value representation DS) as numbers.
std::vector<double> ds_values(const std::string& s) {
  std::string t = s;
  std::replace(t.begin(), t.end(), '\\', ' ');
  std::istringstream in(t);
  in.imbue(std::locale::classic());
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

bool has_dicom_magic(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  char buf[132];
  if (!in.read(buf, 132)) return false;
  return std::memcmp(buf + 128, "DICM", 4) == 0;
}
itk::ImageIOBase::Pointer io_for(const fs::path& p, bool for_writing) {
  const std::string e = full_ext(p);
  if (e == ".nrrd" || e == ".nhdr") return itk::NrrdImageIO::New().GetPointer();
  if (e == ".nii" || e == ".nii.gz") return itk::NiftiImageIO::New().GetPointer();
  if (e == ".mha" || e == ".mhd") return itk::MetaImageIO::New().GetPointer();
  if (!for_writing && (e == ".dcm" || e == ".ima" || has_dicom_magic(p))) return itk::GDCMImageIO::New().GetPointer();
  return nullptr;
}

const char* const kReadFormats = ".nrrd .nhdr .nii .nii.gz .mha .mhd, a DICOM file or a DICOM series folder";
const char* const kWriteFormats = ".nrrd .nii .nii.gz .mha";


std::string fmt(double v, int prec) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << std::setprecision(prec) << v;
  return s.str();
}

}  // namespace vio
std::string patient_position(const itk::ImageBase<3>* image) {
  std::string v;
  if (!image || !itk::ExposeMetaData<std::string>(image->GetMetaDataDictionary(), "0018|5100", v)) return "";
  v.erase(std::remove_if(v.begin(), v.end(), [](unsigned char c) { return std::isspace(c) || c == 0; }), v.end());
  std::transform(v.begin(), v.end(), v.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  return v;
}

void set_patient_position(itk::ImageBase<3>* image, const std::string& position) {
  if (!image) return;
  auto& d = image->GetMetaDataDictionary();
  if (position.empty()) {
    if (d.HasKey("0018|5100")) d.Erase("0018|5100");
    return;
  }
  itk::EncapsulateMetaData<std::string>(d, "0018|5100", position);
}

void itk_follows_thread_count() {
  add_thread_count_listener([](int n) { itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(itk::ThreadIdType(n)); });
}

}  // namespace cf
