#pragma once
// Small DCMTK helpers shared by the dicom module's sources.
#include <filesystem>
#include <string>
#include <vector>

class DcmFileFormat;
class DcmItem;
class DcmTagKey;

namespace cf::dicom {

// True when the file holds "DICM" after a 128-byte preamble (a DICOM Part 10 file).
bool has_part10_magic(const std::filesystem::path& file);
// The value of `tag` in `item` (all values, backslash-separated), trimmed; "" when absent.
std::string text(DcmItem* item, const DcmTagKey& tag);
std::string upper(std::string s);
// "1.5\\-2\\3" -> {1.5, -2, 3} (a multi-valued DS).
std::vector<double> numbers(const std::string& backslashed);
// Saves `ff` (explicit little endian) to `file` atomically; returns its SOPInstanceUID. A failed
// write says why in words ("no space left on device").
std::string save_atomically(DcmFileFormat& ff, const std::filesystem::path& file);
// DCMTK's logger prints warnings to stderr: only fatal messages from here on.
void quiet_dcmtk();

}  // namespace cf::dicom
