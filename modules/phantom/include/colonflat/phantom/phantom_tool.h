#pragma once
// `colonflat phantom -o DIR [--seed N] [--size small|medium|full] [--format nrrd|dicom] ...`
#include <memory>

#include "colonflat/core/tool.h"

namespace cf {

std::unique_ptr<Tool> make_phantom_tool();

}  // namespace cf
