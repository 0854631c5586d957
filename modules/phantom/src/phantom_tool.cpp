#include "colonflat/phantom/phantom_tool.h"

#include <iomanip>
#include <ostream>

#include "colonflat/core/error.h"
#include "colonflat/core/output_check.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/phantom/phantom.h"
#include "colonflat/phantom/phantom_exam.h"

namespace cf {
namespace {

// Options of `--from-mask` and the options that do not apply to it.
struct MaskCli {
  std::string mask;
  bool no_header = false, no_bladder = false, deep_pools = false, pressed_bowel = false;
  int bowel_loops = 4;
  double long_stretch_mm = 0, slice_mm = 0;
};
const char* const kSyntheticOnly[] = {"--size", "--format", "--collapsed", "--polyps", "--topological-noise",
                                      "--oral-contrast", "--excreted-contrast", "--enhanced-vessels", "--rectal-tube",
                                      "--realistic"};

void add_mask_options(CLI::App& app, MaskCli& m) {
  app.add_option("--from-mask", m.mask,
                 "paint the CT around this real lumen mask (0/1, any volume format; LPS geometry kept) instead of the "
                 "synthetic colon: body, colon wall, bone, pools, fully tagged stretches, small bowel, bladder "
                 "(docs/phantom.md)")
      ->type_name("MASK");
  app.add_flag("--no-position-header", m.no_header, "with --from-mask: no PatientPosition in ct.nrrd");
  app.add_option("--bowel-loops", m.bowel_loops, "with --from-mask: small-bowel loops with oral contrast (default 4; range [0, 8])")
      ->type_name("N");
  app.add_flag("--no-bladder", m.no_bladder, "with --from-mask: no bladder");
  app.add_option("--long-stretch", m.long_stretch_mm,
                 "with --from-mask: one stretch of this length (mm, 100-400) completely filled with tagged fluid where "
                 "the colon lies beside other parts of itself")
      ->type_name("MM");
  app.add_flag("--deep-pools", m.deep_pools, "with --from-mask: pools at 30-50 % of their pocket, over the folds (one level along a segment)");
  app.add_flag("--pressed-bowel", m.pressed_bowel, "with --from-mask: touching small-bowel loops pressed against the colon wall");
  app.add_option("--slice-spacing", m.slice_mm, "with --from-mask: resample the mask to this slice spacing first (mm, 0.5-3)")
      ->type_name("MM");
}
const char* const kMaskOnly[] = {"--no-position-header", "--bowel-loops", "--no-bladder", "--long-stretch",
                                 "--deep-pools", "--pressed-bowel", "--slice-spacing"};

// colonflat phantom --from-mask MASK -o DIR: checks, paints and writes (all files or none).
int run_from_mask(CLI::App& app, const MaskCli& m, const PhantomOptions& o, const std::string& dir, bool quiet,
                  std::ostream& err) {
  for (const char* opt : kSyntheticOnly)
    if (app.count(opt) > 0) throw UsageError(std::string(opt) + " does not apply with --from-mask");
  MaskPhantomOptions mo;
  mo.seed = o.seed;
  mo.position = o.position;
  mo.position_header = !m.no_header;
  mo.noise_hu = o.noise_hu;
  mo.blur_mm = o.blur_mm;
  mo.fully_tagged = app.count("--fully-tagged-segments") ? o.fully_tagged_segments : 1;
  mo.bowel_loops = m.bowel_loops;
  mo.bladder = !m.no_bladder;
  mo.pools = o.tagged_fluid;
  mo.long_stretch_mm = m.long_stretch_mm;
  mo.deep_pools = m.deep_pools;
  mo.pressed_bowel = m.pressed_bowel;
  if (app.count("--slice-spacing") && !(m.slice_mm >= 0.5 && m.slice_mm <= 3))
    throw UsageError("--slice-spacing must be in [0.5, 3] mm");
  gravity_of_position(mo.position);
  PathPlan plan;
  plan.input(m.mask);
  for (const char* f : {"ct.nrrd", "lumen_mask.nrrd", "labels.nrrd", "phantom.json", "polyps.json", "centerline.json", "noise_sites.json"})
    plan.output(std::filesystem::path(dir) / f, "-o");
  plan.check();
  Stopwatch t;
  ProgressScope phases(quiet ? nullptr : &err, "phantom");
  MaskImage::Pointer mask = read_binary_mask(m.mask);
  if (m.slice_mm > 0) mask = resample_mask_slices(mask, m.slice_mm);
  MaskPhantom p = paint_phantom_from_mask(mask, mo);
  p.phantom.description["files"]["mask"] = m.mask;
  write_phantom(p.phantom, dir, "nrrd");
  phase_done("written");
  if (!quiet) {
    const auto& v = p.phantom.description["volumes_ml"];
    err << std::fixed << std::setprecision(1) << "phantom: from " << m.mask << ": lumen " << v["lumen"].get<double>()
        << " mL, colon fluid " << v["colon_fluid"].get<double>() << " mL (" << p.phantom.description["pools"]["count"].get<int>()
        << " pools), small bowel " << v["small_bowel"].get<double>() << " mL, bladder " << v["bladder"].get<double>()
        << " mL, " << o.position << (m.no_header ? " (no position header)" : "") << "; " << std::setprecision(2)
        << t.seconds() << " s, peak " << std::setprecision(0) << peak_memory_mib() << " MiB -> " << dir << "\n";
  }
  return kExitOk;
}

class PhantomTool : public Tool {
 public:
  std::string name() const override { return "phantom"; }
  std::string summary() const override {
    return "synthetic CT colonography phantom with ground truth (lumen mask, polyps, centreline, noise sites)";
  }
  int run(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) override {
    CLI::App app(
        "Writes a synthetic abdominal CT (HU, LPS mm) with an insufflated colon, tagged fluid, polyps and "
        "deliberate topological noise, plus its ground truth: DIR/ct.nrrd (or DIR/dicom/ with --format dicom), "
        "lumen_mask.nrrd, labels.nrrd, polyps.json, centerline.json, noise_sites.json, phantom.json. Deterministic for a "
        "given seed.",
        "colonflat phantom");
    app.set_version_flag("--version", colonflat_version());
    PhantomOptions o;
    std::string dir, format = "nrrd";
    bool quiet = false;
    app.add_option("-o,--output", dir, "output folder")->required()->type_name("DIR");
    app.add_option("--seed", o.seed, "random seed (default 1)")->type_name("N")->check(
        CLI::Validator([](std::string& v) { return v.rfind('-', 0) == 0 ? "must be >= 0 (got " + v + ")" : std::string(); }, ""));
    app.add_option("--size", o.size, "small: 128^3 at 2.8 x 2.8 x 3.125 mm (seconds); medium: 256 x 256 x 200 at "
                                     "1.4 x 1.4 x 2 mm; full: 512 x 512 x 400 at 0.7 x 0.7 x 1 mm (default " + o.size + ")")
        ->type_name("small|medium|full");
    app.add_option("--format", format, "volume format: nrrd (DIR/ct.nrrd) or dicom (DIR/dicom/, one file per slice) "
                                       "(default nrrd)")
        ->type_name("nrrd|dicom");
    app.add_flag("--collapsed", o.collapsed_segment, "include a collapsed stretch of descending colon");
    app.add_flag("--fluid,!--no-fluid", o.tagged_fluid, "pools of tagged fluid (default on)");
    app.add_flag("--polyps,!--no-polyps", o.polyps, "polyps (default on)");
    app.add_flag("--topological-noise,!--no-topological-noise", o.topological_noise,
                 "strands, near-touching segments, holes through folds (default on)");
    app.add_option("--noise", o.noise_hu, "noise standard deviation [HU] (default 20; range [0, 500])")->type_name("HU");
    app.add_option("--blur", o.blur_mm, "partial-volume blur sigma [mm] (default 0 = automatic; range [0, 5])")
        ->type_name("MM");
    app.add_option("--position", o.position, "patient position: supine (posterior down, DICOM HFS) or prone (anterior "
                                             "down, HFP; same colon and polyps as supine, mobile colon displaced); "
                                             "with --from-mask also left-down (HFDL) or right-down (HFDR) "
                                             "(default supine)")
        ->type_name("supine|prone|left-down|right-down");
    app.add_option("--fully-tagged-segments", o.fully_tagged_segments,
                   "colon stretches completely filled with tagged fluid, between collapsed necks (default 0; range [0, 3])")
        ->type_name("K");
    app.add_flag("--oral-contrast", o.oral_contrast, "small-bowel loops with positive oral contrast and gas bubbles");
    app.add_flag("--excreted-contrast", o.excreted_contrast, "bladder with excreted contrast");
    app.add_flag("--enhanced-vessels", o.enhanced_vessels, "contrast-enhanced aorta");
    app.add_flag("--rectal-tube", o.rectal_tube, "rectal catheter (air lumen) through the anus into the rectum");
    bool realistic = false;
    app.add_flag("--realistic", realistic,
                 "all of the above: oral and excreted contrast, enhanced aorta, rectal tube and (unless given) 2 fully "
                 "tagged stretches");
    bool exam = false;
    app.add_flag("--exam", exam,
                 "a DICOM exam as a PACS exports it: DIR/exam/ST0/SE1 (localizer), SE2 (supine), SE3 (prone) of one "
                 "patient and study, and each scan's ground truth in DIR/supine/ and DIR/prone/")
        ->excludes(app.get_option("--position"))
        ->excludes(app.get_option("--format"));
    app.add_flag("-q,--quiet", quiet, "no progress output");
    MaskCli mask;
    add_mask_options(app, mask);
    return run_cli(app, name(), args, out, err, [&]() -> int {
      if (!mask.mask.empty()) return run_from_mask(app, mask, o, dir, quiet, err);
      for (const char* opt : kMaskOnly)
        if (app.count(opt) > 0) throw UsageError(std::string(opt) + " needs --from-mask");
      if (format != "nrrd" && format != "dicom") throw UsageError("--format must be nrrd or dicom (got '" + format + "')");
      if (realistic) {
        o.oral_contrast = o.excreted_contrast = o.enhanced_vessels = o.rectal_tube = true;
        if (app.count("--fully-tagged-segments") == 0) o.fully_tagged_segments = 2;
      }
      Stopwatch t;
      ProgressScope phases(quiet ? nullptr : &err, "phantom");
      Phantom p = generate_phantom(o);
      const double gen = t.seconds();
      if (exam) write_exam(o, p, dir);
      else write_phantom(p, dir, format);
      phase_done("written");
      if (!quiet) {
        err << std::fixed << std::setprecision(2) << "phantom: colon "
            << p.description["colon"]["length_mm"].get<double>() / 1000.0 << " m, lumen "
            << p.description["colon"]["lumen_volume_ml"].get<double>() << " mL, " << p.polyps.size() << " polyps, "
            << p.noise_sites.size() << " noise sites; generated in " << gen << " s, written in " << t.seconds() - gen
            << " s, peak " << std::setprecision(0) << peak_memory_mib() << " MiB -> " << dir << "\n";
      }
      return kExitOk;
    });
  }

 private:
  // --exam: the prone scan of the same patient too, then the study as a PACS exports it.
  static void write_exam(PhantomOptions o, const Phantom& supine, const std::string& dir) {
    o.position = "prone";
    const Phantom prone = generate_phantom(o);
    write_phantom_exam(supine, prone, dir);
  }
};

}  // namespace

std::unique_ptr<Tool> make_phantom_tool() { return std::make_unique<PhantomTool>(); }

}  // namespace cf
