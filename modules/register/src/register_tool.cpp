#include "colonflat/register/register_tool.h"

#include <array>
#include <iomanip>
#include <ostream>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/register/register_output.h"
#include "colonflat/register/scan.h"

namespace cf {

const ParamTable<RegisterParams>& register_param_table() {
  static const ParamTable<RegisterParams> t = [] {
    ParamTable<RegisterParams> p;
    using P = RegisterParams;
    p.real("bin-mm", &P::bin_mm, "mm", "length bin of the colon profiles", 0.5, 20)
        .real("smooth-mm", &P::smooth_mm, "mm", "Gaussian sigma smoothing each centre line", 0, 100)
        .real("band-mm", &P::band_mm, "mm", "largest departure of the length warping from proportional", 10, 2000)
        .real("prior-weight", &P::prior_weight, "", "cost of leaving the proportional length map", 0, 100)
        .real("warp-smooth-mm", &P::warp_smooth_mm, "mm", "Gaussian sigma smoothing the length map", 0, 200)
        .real("max-twist", &P::max_twist_deg, "deg", "search range of the rotation around the colon (0 = none)", 0, 180)
        .real("twist-window-mm", &P::twist_window_mm, "mm", "colon length per rotation estimate", 10, 500)
        .choice("orientation", &P::orientation, {"auto", "same", "reverse"},
                "prone run direction: auto (tried both ways unless both maps label the rectum), same, reverse")
        .real("match-along-mm", &P::match_along_mm, "mm", "largest distance along the colon of a candidate pair", 0, 500)
        .real("match-around-deg", &P::match_around_deg, "deg", "largest angle around the colon of a candidate pair", 0, 180)
        .real("match-size-ratio", &P::match_size_ratio, "", "largest size ratio of a candidate pair", 1, 100)
        .real("pixel-mm", &P::pixel_mm, "mm", "pixel size of the side-by-side image", 0.1, 10);
    return p;
  }();
  return t;
}

RegisterOptions register_options(const RegisterParams& p) {
  RegisterOptions o;
  o.profile.bin_mm = p.bin_mm;
  o.profile.smooth_mm = p.smooth_mm;
  o.align.band_mm = p.band_mm;
  o.align.prior_weight = p.prior_weight;
  o.align.warp_smooth_mm = p.warp_smooth_mm;
  o.twist.max_twist_deg = p.max_twist_deg;
  o.twist.window_mm = p.twist_window_mm;
  o.orientation = p.orientation;
  o.match_along_mm = p.match_along_mm;
  o.match_around_deg = p.match_around_deg;
  o.match_size_ratio = p.match_size_ratio;
  return o;
}

namespace {

class RegisterTool : public Tool {
 public:
  std::string name() const override { return "register"; }
  std::string summary() const override {
    return "supine-prone registration of two runs: length and rotation alignment, point maps, matched candidates";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app(
        "Registers the prone run to the supine run (each a `colonflat run` output folder with flat.vtp and "
        "candidates.json or polyps.json). Writes OUT/registration.json (length alignment, rotation, candidate "
        "pairs and singles), OUT/supine_to_prone.vtp and OUT/prone_to_supine.vtp (per-vertex correspondence), "
        "OUT/supine_prone.png (both flat colons on one length axis).",
        "colonflat register");
    app.set_version_flag("--version", colonflat_version());
    RegisterParams params;
    std::string supine, prone, dir;
    bool quiet = false;
    app.add_option("SUPINE_RUN_DIR", supine, "supine run folder")->required();
    app.add_option("PRONE_RUN_DIR", prone, "prone run folder")->required();
    app.add_option("-o,--output", dir, "output folder")->required()->type_name("DIR");
    register_param_table().add_to(app, params);
    app.add_flag("-q,--quiet", quiet, "no summary line");
    return run_cli(app, name(), args, out, err, [&]() -> int {
      register_param_table().validate(params);
      Stopwatch clock;
      const ColonScan sup = read_run_dir(supine), pro = read_run_dir(prone);
      const double read_s = clock.seconds();
      ColonRegistration reg(sup, pro, register_options(params));
      reg.run();
      const double register_s = clock.seconds() - read_s;
      write_registration(reg, dir, SideBySideOptions{params.pixel_mm}, register_param_table().to_json(params));
      if (!quiet) report(reg, {read_s, register_s, clock.seconds() - read_s - register_s}, dir, err);
      return kExitOk;
    });
  }

 private:
  // `seconds`: reading, registration, image and writing.
  static void report(const ColonRegistration& reg, const std::array<double, 3>& seconds, const std::string& dir,
                     std::ostream& err) {
    const auto& m = reg.matching();
    err << std::fixed << std::setprecision(0) << "register: supine " << reg.supine_coordinates().profile.length_mm()
        << " mm, prone " << reg.prone_coordinates().profile.length_mm() << " mm"
        << (reg.prone_reversed() ? " (reversed)" : "") << "; " << m.pairs.size() << " candidate pairs, "
        << m.supine_only.size() << " supine-only, " << m.prone_only.size() << " prone-only; " << std::setprecision(1)
        << seconds[0] + seconds[1] + seconds[2] << " s (read " << seconds[0] << ", register " << seconds[1]
        << ", image and write " << seconds[2] << ") -> " << dir << "\n";
  }
};

}  // namespace

std::unique_ptr<Tool> make_register_tool() { return std::make_unique<RegisterTool>(); }

}  // namespace cf
