#include "dicom_common.h"

#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/oflog/oflog.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/write_errors.h"
#include "colonflat/core/error.h"

namespace cf::dicom {

bool has_part10_magic(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char head[132] = {};
  in.read(head, sizeof head);
  return in.gcount() == 132 && std::memcmp(head + 128, "DICM", 4) == 0;
}

std::string text(DcmItem* item, const DcmTagKey& tag) {
  OFString v;
  if (!item || item->findAndGetOFStringArray(tag, v).bad()) return "";
  std::string s = v.c_str();
  const auto a = s.find_first_not_of(" \0", 0, 2), b = s.find_last_not_of(" \0", std::string::npos, 2);
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  return s;
}

std::string save_atomically(DcmFileFormat& ff, const std::filesystem::path& file) {
  const std::string uid = text(ff.getDataset(), DCM_SOPInstanceUID);
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    const OFCondition c = ff.saveFile(tmp.c_str(), EXS_LittleEndianExplicit);
    if (c.bad()) {
      const std::string why = file_system_problem(tmp);
      throw Error(file.string() + ": cannot write: " + (why.empty() ? std::string(c.text()) : why));
    }
  });
  return uid;
}

std::vector<double> numbers(const std::string& backslashed) {
  std::vector<double> v;
  std::stringstream in(backslashed);
  for (std::string part; std::getline(in, part, '\\');) v.push_back(std::strtod(part.c_str(), nullptr));
  return v;
}

void quiet_dcmtk() { OFLog::configure(OFLogger::FATAL_LOG_LEVEL); }

}  // namespace cf::dicom
