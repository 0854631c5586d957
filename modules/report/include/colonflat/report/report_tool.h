#pragma once
// `colonflat report RUN_DIR [--ct FILE] [--truth FILE] [options]`: (re)builds report.html,
// report_files/ and polyps.mrk.json of a run folder from its files. `colonflat run` calls it at
// its end.
#include <memory>

#include "colonflat/core/params.h"
#include "colonflat/core/tool.h"
#include "colonflat/report/report.h"

namespace cf {

// Every parameter of the report, declared once (CLI, --help, ranges).
const ParamTable<ReportOptions>& report_param_table();

std::unique_ptr<Tool> make_report_tool();

}  // namespace cf
