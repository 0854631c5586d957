// Supine-prone registration benchmark (Release; modes and columns: docs/register.md, "Benchmark"):
//   register_bench              synthetic full-length pairs (1.5 m, known correspondence), also
//                               with stretches left out of one scan (issue 27).
//   register_bench --phantom 1-5 [--size full|small] --work DIR
//                               phantom pairs (`colonflat phantom [--position prone]`, `colonflat run`).
//   register_bench --cuts SEED [--size full|small] --work DIR [--held-out] [--no-cli]
//                               one phantom patient run from its true lumen masks, the masks cut
//                               (collapse, tagged stretches dropped, split +3, rectum cut; issue 27).
//   register_bench --real-mask MASK --work DIR [--table X Y Z] [--turn DEG] [--painted] [--cases K...]
//                  [--held-out] [--polyp-seed N] [--polyps N]
//                               the real lumen mask with 10 synthetic polyps, cut as --cuts (by path
//                               distance through the lumen), the prone mask moved on the table; a
//                               polyp counts as seen in a scan only with that scan's wall within its
//                               diameter (on_wall: a cut can take the wall around a polyp away).
//   register_bench --write-synthetic DIR [--twist DEG]     a small synthetic pair as run folders.
//   register_bench --pair SUP_RUN PRO_RUN [--truth SUP_PHANTOM PRO_PHANTOM]   one pair of run folders.
// Columns: polyps >= 6 mm seen in both; matched = truth polyps paired with themselves when the two
// truth lists are matched through the registration; false = pairs joining different polyps;
// along (median, max) / around = error of each polyp's registered position; det_* = the same for
// the runs' detected candidates (det_np: two non-polyp candidates); time = registration wall time;
// lps_* = baseline without registration (the same LPS point taken in the other scan).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_cli.h"
#include "register_bench_real.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/pipeline/dispatch.h"
#include "colonflat/register/register.h"
#include "colonflat/testdata/lumen_cut.h"
#include "colonflat/testdata/mask_pair.h"
#include "colonflat/testdata/phantom_pair.h"
#include "colonflat/testdata/synthetic_pair.h"

namespace {
namespace fs = std::filesystem;
constexpr double kPi = 3.141592653589793;

double median(std::vector<double> v) { return cf::upper_median(std::move(v)); }
double largest(const std::vector<double>& v) { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); }

struct Row {
  std::string name;
  size_t vertices = 0;
  int polyps = 0, matched = 0, false_matches = 0, det_pairs = -1, det_false = -1, det_nonpolyp = 0;
  std::string pieces = "-";  // colon bands supine / prone (piecewise layout, pieces.h)
  int missed = 0;            // polyps seen in both scans and not paired
  double along = NAN, around = NAN, seconds = 0, along_max = NAN;  // along: median and largest error
  double lps_along = NAN, lps_around = NAN;  // baseline: the same LPS point taken in the other scan
};

void print_header() {
  std::printf("load average %.2f\n", cf::bench::load_average());
  std::printf("%-28s %9s %7s %6s %7s %5s %6s %9s %7s %10s %9s %9s %6s %7s %11s %12s\n", "pair", "vertices", "pieces",
              "polyps", "matched", "false", "missed", "along_mm", "max_mm", "around_deg", "det_pairs", "det_false", "det_np", "time_s",
              "lps_along", "lps_around");
}

void print_row(const Row& r) {
  std::printf("%-28s %9zu %7s %6d %7d %5d %6d %9.1f %7.1f %10.1f %9d %9d %6d %7.2f %11.1f %12.1f\n", r.name.c_str(),
              r.vertices, r.pieces.c_str(), r.polyps, r.matched, r.false_matches, r.missed, r.along, r.along_max, r.around,
              r.det_pairs,
              r.det_false, r.det_nonpolyp, r.seconds, r.lps_along, r.lps_around);
  std::fflush(stdout);
}

// Counts pairs joining the same id (matched) and different ids (false).
void count_id_pairs(const cf::CandidateMatching& m, int& matched, int& false_matches) {
  matched = false_matches = 0;
  for (const auto& p : m.pairs) (p.supine_id == p.prone_id ? matched : false_matches) += 1;
}

std::string piece_counts(const cf::ColonRegistration& reg) {
  if (!reg.piecewise()) return "-";
  return std::to_string(reg.pieces().supine.size()) + "/" + std::to_string(reg.pieces().prone.size());
}

Row synthetic_row(const std::string& name, const cf::SyntheticPairOptions& o) {
  const cf::SyntheticPair pair = cf::make_synthetic_pair(o);
  Row r{name, pair.supine.lps.size(), int(pair.polyps.size())};
  cf::Stopwatch clock;
  cf::ColonRegistration reg(pair.supine, pair.prone);
  reg.run();
  r.seconds = clock.seconds();
  std::vector<cf::ScanCandidate> ts, tp;  // the true polyps seen in that scan
  r.polyps = 0;
  for (const auto& q : pair.polyps) {
    if (q.in_supine) ts.push_back({q.id, q.supine_lps, q.size_mm, 1});
    if (q.in_prone) tp.push_back({q.id, q.prone_lps, q.size_mm, 1});
    r.polyps += q.in_supine && q.in_prone;
  }
  count_id_pairs(reg.match(ts, tp), r.matched, r.false_matches);
  r.missed = r.polyps - r.matched;
  r.pieces = piece_counts(reg);
  std::vector<double> along, around;
  for (const auto& q : pair.polyps) {
    if (!q.in_supine || !q.in_prone) continue;
    const auto [s, t] = reg.locate(q.supine_lps, cf::Direction::kSupineToProne);
    const int w = reg.map_vertex(cf::Direction::kSupineToProne, s, t);
    if (w < 0) continue;
    along.push_back(std::abs(pair.prone_sigma[size_t(w)] - q.sigma_mm));
    const double d = std::fmod(std::abs(pair.prone_phi[size_t(w)] - q.phi_rad), 2 * kPi);
    around.push_back((d > kPi ? 2 * kPi - d : d) * 180 / kPi);
  }
  r.along = median(along), r.around = median(around), r.along_max = largest(along);
  count_id_pairs(reg.matching(), r.det_pairs, r.det_false);
  return r;
}

// The same 1.5 m pairs with the two segmentations differing (issue 27): stretches left out of one
// scan's map, so that its colon is several bands.
void pieces_table() {
  std::printf("\nSynthetic pairs whose segmentations differ (stretches of material mm left out of one scan)\n");
  print_header();
  struct Case { const char* name; std::vector<std::pair<double, double>> sup, pro; bool shuffle; };
  const std::vector<Case> cases = {
      {"prone collapse 20 mm", {}, {{700, 720}}, false},
      {"prone 25 % tagged dropped", {}, {{500, 875}}, false},
      {"prone split +3, order wrong", {}, {{300, 315}, {750, 765}, {1100, 1115}}, true},
      {"prone rectum cut 60 mm", {}, {{0, 60}}, false},
      {"both differ", {{1000, 1030}}, {{400, 520}, {1250, 1265}}, false},
      {"supine 25 % dropped + split", {{200, 575}, {900, 915}}, {{1200, 1215}}, false}};
  for (int seed = 1; seed <= 2; ++seed)
    for (const Case& c : cases) {
      cf::SyntheticPairOptions o;
      o.length_mm = 1500, o.radius_mm = 25, o.spacing_mm = 0.7, o.shift_mm = 60, o.slide_mm = 20, o.polyps = 10;
      o.seed = std::uint64_t(seed), o.supine_removed = c.sup, o.prone_removed = c.pro, o.shuffle_pieces = c.shuffle;
      print_row(synthetic_row(std::string(c.name) + " s" + std::to_string(seed), o));
    }
}

void synthetic_table() {
  std::printf("Synthetic pairs: 1.5 m colon, radius 25 mm, 0.7 mm vertices; prone middle shifted 60 mm, wall slid "
              "+-20 mm along the colon\n");
  print_header();
  cf::SyntheticPairOptions o;
  o.length_mm = 1500, o.radius_mm = 25, o.spacing_mm = 0.7, o.shift_mm = 60, o.slide_mm = 20, o.polyps = 10;
  for (int seed = 1; seed <= 3; ++seed) {
    o.seed = std::uint64_t(seed);
    print_row(synthetic_row("synthetic seed " + std::to_string(seed), o));
  }
  o.seed = 1, o.twist_deg = 20;
  print_row(synthetic_row("twist 20 deg", o));
  o.twist_deg = 0, o.centreline = false, o.reverse_prone = true;
  print_row(synthetic_row("no centreline, reversed", o));
  pieces_table();
}

// ---- phantom pairs -------------------------------------------------------------------------

// The truth polyp a detected candidate stands for (-1 = none).
int hit(const std::vector<cf::ScanCandidate>& truth, const cf::ScanCandidate& c) {
  for (const auto& q : truth)
    if ((q.lps - c.lps).norm() <= q.size_mm / 2 + 5) return q.id;
  return -1;
}

// det_pairs / det_false / det_np of the registration's pairs of detected candidates.
void count_detected(const cf::ColonRegistration& reg, const std::vector<cf::ScanCandidate>& ts,
                    const std::vector<cf::ScanCandidate>& tp, Row& r) {
  r.det_pairs = r.det_false = r.det_nonpolyp = 0;
  for (const auto& m : reg.matching().pairs) {
    int hs = -2, hp = -3;
    for (const auto& c : reg.supine().candidates) if (c.id == m.supine_id) hs = hit(ts, c);
    for (const auto& c : reg.prone().candidates) if (c.id == m.prone_id) hp = hit(tp, c);
    if (hs == hp) (hs >= 0 ? r.det_pairs : r.det_nonpolyp) += 1;
    else r.det_false += 1;
  }
}

using Cuts = cf::CutList;

Row pair_row(const std::string& name, const fs::path& sup_run, const fs::path& pro_run, const fs::path& sup_truth,
             const fs::path& pro_truth, const Cuts& prone_cuts = {}, const Cuts& supine_cuts = {}, bool show = false) {
  const cf::ColonScan sup = cf::read_run_dir(sup_run), pro = cf::read_run_dir(pro_run);
  Row r{name, sup.lps.size()};
  cf::Stopwatch clock;
  cf::ColonRegistration reg(sup, pro);
  reg.run();
  r.seconds = clock.seconds();
  r.pieces = piece_counts(reg);
  if (sup_truth.empty()) {
    r.det_pairs = int(reg.matching().pairs.size());
    return r;
  }
  const cf::PhantomTruth ts = cf::read_phantom_truth(sup_truth), tp = cf::read_phantom_truth(pro_truth);
  const auto cs = cf::truth_candidates(ts, supine_cuts), cp = cf::truth_candidates(tp, prone_cuts);
  const cf::PairFigures f = cf::score_truth_pair(reg, cs, cp, tp);
  r.polyps = f.seen_in_both, r.matched = f.right, r.false_matches = f.wrong, r.missed = r.polyps - r.matched;
  r.along = f.along_median_mm(), r.around = median(f.around_deg), r.along_max = f.along_max_mm();
  std::vector<double> lps_along, lps_around;  // baseline: the nearest prone wall vertex of the supine polyp
  for (const auto& q : cs)
    for (const auto& p : cp)
      if (p.id == q.id) {
        const auto [s, t] = reg.locate(q.lps, cf::Direction::kProneToSupine);
        const int w = reg.vertex_at(false, s, t);
        if (w < 0) continue;
        const auto [la, lb] = cf::truth_error(tp, pro.lps[size_t(w)], p.lps);
        lps_along.push_back(la), lps_around.push_back(lb);
      }
  r.lps_along = median(lps_along), r.lps_around = median(lps_around);
  if (show) {
    const cf::CandidateMatching m = reg.match(cs, cp);
    for (const auto& q : cs)
      for (const auto& p : cp)
        if (p.id == q.id)
          show_polyp(reg, m, q, p, NAN, NAN, (reg.map_place(m, q.id, cf::Direction::kSupineToProne) - p.lps).norm());
  }
  count_detected(reg, cf::all_truth_candidates(ts), cf::all_truth_candidates(tp), r);
  return r;
}

int colonflat(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = cf::colonflat_main(args, out, err);
  if (code != 0) std::printf("  colonflat %s: exit %d: %s", args[0].c_str(), code, err.str().c_str());
  return code;
}

// Phantom and run folders of one seed and position (reused when already there).
bool prepare(const fs::path& work, int seed, const std::string& size, const std::string& position) {
  const fs::path ph = work / ("seed" + std::to_string(seed)) / (position + "_phantom");
  const fs::path run = work / ("seed" + std::to_string(seed)) / (position + "_run");
  if (!fs::exists(ph / "polyps.json")) {
    std::vector<std::string> a = {"phantom", "--seed", std::to_string(seed), "--size", size, "-o", ph.string(), "-q"};
    if (position == "prone") a.insert(a.end(), {"--position", "prone"});
    if (colonflat(a) != 0) return false;
  }
  if (!fs::exists(run / "flat.vtp") && colonflat({"run", (ph / "ct.nrrd").string(), "-o", run.string(), "-q"}) != 0)
    return false;
  return true;
}

void phantom_table(int first, int last, const std::string& size, const fs::path& work) {
  std::printf("Phantom pairs (size %s): colonflat phantom [--position prone] -> colonflat run -> registration\n",
              size.c_str());
  print_header();
  for (int seed = first; seed <= last; ++seed) {
    const fs::path d = work / ("seed" + std::to_string(seed));
    if (!prepare(work, seed, size, "supine") || !prepare(work, seed, size, "prone")) {
      std::printf("seed %d: pair not available (see the colonflat message above)\n", seed);
      continue;
    }
    print_row(pair_row("phantom seed " + std::to_string(seed), d / "supine_run", d / "prone_run",
                       d / "supine_phantom", d / "prone_phantom"));
  }
}

// A scan's mask cut (and moved); the run folder from it (`colonflat run MASK --from reconstruct`).
bool run_mask(const fs::path& mask, const fs::path& out) {
  return fs::exists(out / "flat.vtp") ||
         colonflat({"run", mask.string(), "--from", "reconstruct", "-o", out.string(), "-q"}) == 0;
}

// `colonflat register` on the two run folders (the command users run): its pairs of detected
// candidates, wall and process CPU seconds, printed under the row.
void register_cli(const fs::path& sup_run, const fs::path& pro_run, const fs::path& out, const Row& r) {
  fs::remove_all(out);
  cf::Stopwatch clock;
  const std::clock_t cpu = std::clock();
  if (colonflat({"register", sup_run.string(), pro_run.string(), "-o", out.string(), "--no-review", "-q"}) != 0) return;
  const double cpu_s = double(std::clock() - cpu) / CLOCKS_PER_SEC, wall = clock.seconds();
  std::ifstream in(out / "registration.json");
  const auto j = nlohmann::json::parse(in);
  std::printf("  colonflat register: %zu candidate pairs (bench: %d + %d + %d), %.1f s wall, %.1f s CPU\n",
              j["candidates"]["pairs"].size(), r.det_pairs, r.det_false, r.det_nonpolyp, wall, cpu_s);
}

// One phantom patient, both positions run from their true lumen masks, the masks cut along the
// phantom's centre line (lumen_cut.h) as real segmentations differ.
void cuts_table(int seed, const std::string& size, const fs::path& work, bool held_out, bool no_cli) {
  std::printf("Phantom seed %d (%s), both scans run from the lumen mask (--from reconstruct); masks cut\n", seed,
              size.c_str());
  const fs::path d = work / ("cuts_seed" + std::to_string(seed));
  for (const std::string position : {"supine", "prone"}) {
    const fs::path ph = d / (position + "_phantom");
    std::vector<std::string> a = {"phantom", "--seed", std::to_string(seed), "--size", size, "-o", ph.string(), "-q"};
    if (position == "prone") a.insert(a.end(), {"--position", "prone"});
    if (!fs::exists(ph / "polyps.json") && colonflat(a) != 0) return;
  }
  if (!run_mask(d / "supine_phantom" / "lumen_mask.nrrd", d / "supine_run")) return;
  const double L = cf::read_phantom_centreline(d / "prone_phantom" / "centerline.json").arc_mm.back();
  const auto cases = held_out ? cf::held_out_cut_cases(L) : cf::segmentation_cut_cases(L);
  print_header();
  for (size_t k = 0; k < cases.size(); ++k) {
    const std::string n = (held_out ? "h" : "") + std::to_string(k);
    fs::path sup_run = d / "supine_run";
    for (const std::string pos : {"supine", "prone"}) {
      const Cuts& cuts = pos == "supine" ? cases[k].supine : cases[k].prone;
      if (pos == "supine" && cuts.empty()) continue;
      const fs::path mask = d / (pos + "_cut" + n + ".nrrd"), ph = d / (pos + "_phantom");
      if (!fs::exists(mask))
        cf::cut_lumen_mask(ph / "lumen_mask.nrrd", cf::read_phantom_centreline(ph / "centerline.json"), cuts, mask);
      if (pos == "supine") sup_run = d / ("supine_run" + n);
      if (!run_mask(mask, d / (pos + "_run" + n))) return;
    }
    const Row r = pair_row(cases[k].name, sup_run, d / ("prone_run" + n), d / "supine_phantom", d / "prone_phantom",
                           cases[k].prone, cases[k].supine);
    print_row(r);
    if (!no_cli) register_cli(sup_run, d / ("prone_run" + n), d / ("register" + n), r);
  }
}

// Real anatomy (issue 27): the shared real lumen mask with 10 synthetic polyps on its wall
// (mask_pair.h), both scans cut by path distance through the lumen, the prone mask moved on the
// table (`shift` mm, `turn` degrees about the superior axis). along = |path distance of the mapped
// supine polyp - that of the polyp| (mm along the lumen's course).
// With `painted`: each mask painted into a CT (`colonflat phantom --from-mask`, the position's
// pools, a fully tagged stretch, small bowel) and run from the CT, segmentation included.
bool run_scan(const fs::path& mask, const fs::path& out, bool painted, const std::string& position) {
  if (!painted || fs::exists(out / "flat.vtp")) return run_mask(mask, out);
  const fs::path ct = out.string() + "_ct";
  return (fs::exists(ct / "ct.nrrd") || colonflat({"phantom", "--from-mask", mask.string(), "-o", ct.string(), "--position",
                                                   position, "-q"}) == 0) &&
         colonflat({"run", (ct / "ct.nrrd").string(), "-o", out.string(), "-q"}) == 0;
}

void real_table(const fs::path& mask_file, const fs::path& work, const RealMaskOptions& o) {
  const Eigen::Vector3d shift(o.table[0], o.table[1], o.table[2]);
  const double turn = o.turn_deg;
  cf::Stopwatch prep;
  cf::MaskImage::Pointer mask = cf::read_mask(mask_file);
  if (o.downsample > 1) mask = cf::downsample_mask(mask, o.downsample);
  cf::MaskCourse course(mask);
  const auto polyps = course.place_polyps(o.polyp_count, std::uint64_t(o.polyp_seed));
  const double L = course.length_mm();
  std::printf("Real mask %s: course %.0f mm, %zu polyps placed (%.1f s); prone moved (%.0f, %.0f, %.0f) mm, %.1f deg\n",
              mask_file.filename().c_str(), L, polyps.size(), prep.seconds(), shift.x(), shift.y(), shift.z(), turn);
  fs::create_directories(work);
  print_header();
  const auto cases = o.held_out ? cf::held_out_cut_cases(L) : cf::segmentation_cut_cases(L);
  for (size_t k = 0; k < cases.size(); ++k) {
    if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), int(k)) == o.only.end()) continue;
    const std::string n = (o.held_out ? "h" : "") + std::to_string(k);
    const cf::CutCase& c = cases[k];
    const fs::path sm = work / ("supine" + (c.supine.empty() ? std::string() : n) + ".nrrd"), pm = work / ("prone" + n + ".nrrd");
    if (!fs::exists(sm)) cf::write_mask(course.cut_and_move(c.supine, Eigen::Vector3d::Zero()), sm);
    if (!fs::exists(pm)) cf::write_mask(course.cut_and_move(c.prone, shift, turn), pm);
    const fs::path sr = work / ("supine_run" + (c.supine.empty() ? std::string() : n)), pr = work / ("prone_run" + n);
    if (!run_scan(sm, sr, o.painted, "supine") || !run_scan(pm, pr, o.painted, "prone")) return;
    const cf::ColonScan sup = cf::read_run_dir(sr), pro = cf::read_run_dir(pr);
    Row r{c.name, sup.lps.size()};
    cf::Stopwatch clock;
    cf::ColonRegistration reg(sup, pro);
    reg.run();
    r.seconds = clock.seconds(), r.pieces = piece_counts(reg);
    const auto cs = on_wall(seen_polyps(polyps, c.supine, course, {0, 0, 0}, 0), sup);
    const auto cp = on_wall(seen_polyps(polyps, c.prone, course, shift, turn), pro);
    r.polyps = 0;
    std::vector<double> along;
    const cf::CandidateMatching matching = reg.match(cs, cp);
    for (const auto& q : cs)
      for (const auto& p : cp)
        if (q.id == p.id) {  // the supine polyp mapped from the place it is matched (or shown) at
          ++r.polyps;
          const Eigen::Vector3d m = reg.map_place(matching, q.id, cf::Direction::kSupineToProne);
          const Eigen::Vector3d at = cf::MaskCourse::unmoved(m, course.centroid(), shift, turn);
          if (std::isfinite(m.sum())) along.push_back(std::abs(course.path_at(at) - polyps[size_t(q.id - 1)].path_mm));
          if (o.show)
            show_polyp(reg, matching, q, p, polyps[size_t(q.id - 1)].path_mm, along.empty() ? NAN : along.back(),
                       (at - polyps[size_t(q.id - 1)].lps).norm());
        }
    count_id_pairs(matching, r.matched, r.false_matches);
    r.missed = r.polyps - r.matched, r.along = median(along), r.along_max = largest(along);
    count_detected(reg, cs, cp, r);  // the polyps cut out of a scan are not there to hit
    print_row(r);
    if (o.show) show_pieces(reg, course, shift, turn);
    if (!o.no_cli) register_cli(sr, pr, work / ("register" + n), r);
  }
}

}  // namespace

int main(int argc, char** argv) {
  cf::bench::BenchCli cli("register_bench", "Supine-prone registration benchmark (see the file's header)");
  std::string phantoms, size = "full", work = "register_bench_work", synthetic_dir;
  std::vector<std::string> pair, truth;
  double twist_deg = 0;
  CLI::App& app = cli.app();
  app.add_option("--phantom", phantoms, "phantom pairs of seeds N or N-M");
  int cuts_seed = 0;
  std::string real_mask;  // the options of --real-mask
  RealMaskOptions real;
  app.add_flag("--painted", real.painted, "with --real-mask: paint each mask into a CT and run from the CT");
  app.add_flag("--no-cli", real.no_cli, "with --real-mask or --cuts: no `colonflat register` run per pair");
  app.add_flag("--show-pieces", real.show,
               "with --real-mask: each piece's own mm -> true path mm -> common s; with --real-mask or --pair: each polyp");
  app.add_option("--downsample", real.downsample, "with --real-mask: the mask at this many times its voxel size");
  app.add_flag("--held-out", real.held_out, "with --cuts or --real-mask: the held-out cut cases (held_out_cut_cases)");
  app.add_option("--polyp-seed", real.polyp_seed, "with --real-mask: seed of the polyps' places around the wall");
  app.add_option("--polyps", real.polyp_count, "with --real-mask: polyps spread along 8-92 % of the course");
  app.add_option("--cases", real.only, "with --real-mask: only these cases (0-6)");
  app.add_option("--real-mask", real_mask, "a real lumen mask: pairs with synthetic polyps, cut and moved (issue 27)");
  app.add_option("--table", real.table, "with --real-mask: prone table shift in LPS mm")->expected(3);
  app.add_option("--turn", real.turn_deg, "with --real-mask: prone turned about the superior axis (degrees)");
  app.add_option("--cuts", cuts_seed, "one phantom patient run from its masks, the prone mask cut (issue 27)");
  app.add_option("--size", size, "phantom size")->check(CLI::IsMember({"full", "small"}));
  app.add_option("--work", work, "work folder of the phantom pairs");
  app.add_option("--write-synthetic", synthetic_dir, "write a small synthetic pair as DIR/supine and DIR/prone");
  app.add_option("--twist", twist_deg, "with --write-synthetic: prone twist around the centre line (degrees)");
  app.add_option("--pair", pair, "one existing pair of run folders: SUP_RUN PRO_RUN")->expected(2);
  app.add_option("--truth", truth, "with --pair: the two phantom folders SUP_PHANTOM PRO_PHANTOM")->expected(2);
  return cli.run(argc, argv, [&] {
    if (!real_mask.empty()) real_table(real_mask, work, real);
    else if (cuts_seed > 0) cuts_table(cuts_seed, size, work, real.held_out, real.no_cli);
    else if (!phantoms.empty()) {
      const auto [first, last] = cf::bench::parse_range(phantoms);
      phantom_table(first, last, size, work);
    } else if (!synthetic_dir.empty()) {
      cf::SyntheticPairOptions o;
      o.twist_deg = twist_deg;
      const cf::SyntheticPair p = cf::make_synthetic_pair(o);
      cf::write_run_dir(p.supine, fs::path(synthetic_dir) / "supine"), cf::write_run_dir(p.prone, fs::path(synthetic_dir) / "prone");
    } else if (!pair.empty()) {
      print_header();
      print_row(pair_row("pair", pair[0], pair[1], truth.empty() ? "" : truth[0], truth.empty() ? "" : truth[1], {}, {}, real.show));
    } else {
      synthetic_table();
    }
    return 0;
  });
}
