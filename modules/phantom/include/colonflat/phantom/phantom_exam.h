#pragma once
// The phantom patient's CT colonography study as a PACS exports it (`colonflat phantom --exam`,
// docs/pacs.md).
#include <filesystem>

#include "colonflat/phantom/phantom.h"

namespace cf {

// DIR/exam/ST0/SE1 (series 1, the localizer: a frontal projection of the supine CT, ImageType
// ORIGINAL\PRIMARY\LOCALIZER), SE2 (series 2, the supine scan, HFS) and SE3 (series 3, the prone
// scan, HFP): one patient, one study, each scan with its own series and frame of reference.
// DIR/supine/ and DIR/prone/ hold each scan's ground truth (write_phantom's files without the CT).
// All appear together or not at all.
void write_phantom_exam(const Phantom& supine, const Phantom& prone, const std::filesystem::path& dir);

}  // namespace cf
