#pragma once
// `colonflat register SUPINE_RUN_DIR PRONE_RUN_DIR -o OUT [params] [-q]` (docs/register.md).
#include <memory>

#include "colonflat/core/params.h"
#include "colonflat/core/tool.h"
#include "colonflat/register/register.h"
#include "colonflat/register/side_by_side.h"

namespace cf {

// The command's parameters, one field each; defaults come from the algorithm's Options structs.
struct RegisterParams {
  double bin_mm = ProfileOptions{}.bin_mm;
  double smooth_mm = ProfileOptions{}.smooth_mm;
  double band_mm = AlignOptions{}.band_mm;
  double prior_weight = AlignOptions{}.prior_weight;
  double warp_smooth_mm = AlignOptions{}.warp_smooth_mm;
  double max_twist_deg = TwistOptions{}.max_twist_deg;
  double twist_window_mm = TwistOptions{}.window_mm;
  std::string orientation = RegisterOptions{}.orientation;
  double match_along_mm = RegisterOptions{}.match_along_mm;
  double match_around_deg = RegisterOptions{}.match_around_deg;
  double match_size_ratio = RegisterOptions{}.match_size_ratio;
  double position_sigma_mm = AlignOptions{}.position_sigma_mm;
  double support_radius_mm = RegisterOptions{}.support_radius_mm;
  double max_unsupported_mm = RegisterOptions{}.max_unsupported_mm;
  double match_3d_mm = RegisterOptions{}.match_3d_mm;
  double pixel_mm = SideBySideOptions{}.pixel_mm;
  bool review = true;  // the supine-prone review page OUT/report.html (+ report_files/)
};

const ParamTable<RegisterParams>& register_param_table();
RegisterOptions register_options(const RegisterParams& p);

std::unique_ptr<Tool> make_register_tool();

}  // namespace cf
