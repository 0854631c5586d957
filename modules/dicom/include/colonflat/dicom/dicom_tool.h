#pragma once
// `colonflat dicom RUN_DIR --source SERIES`: the DICOM results of a run folder (RUN_DIR/dicom/,
// docs/pacs.md) from its files. `colonflat run` on a DICOM input writes them at its end (a run
// finisher on the run's memory); on any other input it writes none.
#include <memory>

#include "colonflat/core/tool.h"

namespace cf {

std::unique_ptr<Tool> make_dicom_tool();

}  // namespace cf
