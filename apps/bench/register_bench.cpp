// Supine-prone registration benchmark (Release):
//   register_bench              synthetic full-length pairs (1.5 m, 0.7 mm vertices; known
//                               correspondence): match rate, errors, false matches, time.
//   register_bench --phantom 1-5 [--size full|small] --work DIR
//                               phantom pairs: `colonflat phantom --seed N [--position prone]`,
//                               `colonflat run` on both CTs, `colonflat register`-equivalent, scored
//                               against the phantom truth (polyp ids, centre lines). Needs
//                               `colonflat phantom --position prone` (reported when missing).
//   register_bench --cuts SEED [--size full|small] --work DIR
//                               one phantom patient run from its true lumen masks, the prone mask
//                               with stretches cut out (collapse, 25 % tagged dropped, split +3,
//                               rectum cut short; issue 27), scored as --phantom.
//   register_bench --write-synthetic DIR [--twist DEG]
//                               writes a small synthetic pair as run folders DIR/supine, DIR/prone.
//   register_bench --pair SUP_RUN PRO_RUN [--truth SUP_PHANTOM PRO_PHANTOM]
//                               one existing pair of run folders (scored when truth is given).
// Columns: polyps >= 6 mm; matched = truth polyps paired with themselves when the two truth lists
// are matched through the registration; false = pairs joining different polyps; along / around =
// median error of the registered position of each polyp (mm along the true prone centre line,
// degrees around it); det_pairs / det_false = the same for the runs' detected candidates
// (a candidate is a polyp's when within diameter/2 + 5 mm; det_false = a pair of a polyp's
// candidate with another polyp's or a non-polyp one; det_np = pairs of two non-polyp candidates,
// e.g. the same fold tip or noise site seen in both scans); time = registration wall time;
// lps_along / lps_around = baseline without registration: the prone wall point nearest to the
// supine polyp's LPS position (small when the prone colon barely moves in patient coordinates).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_cli.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/pipeline/dispatch.h"
#include "colonflat/register/register.h"
#include "colonflat/testdata/lumen_cut.h"
#include "colonflat/testdata/synthetic_pair.h"

namespace {
namespace fs = std::filesystem;
constexpr double kPi = 3.141592653589793;

using cf::bench::load_average;

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Row {
  std::string name;
  size_t vertices = 0;
  int polyps = 0, matched = 0, false_matches = 0, det_pairs = -1, det_false = -1, det_nonpolyp = 0;
  std::string pieces = "-";  // colon bands supine / prone (piecewise layout, pieces.h)
  int missed = 0;            // polyps seen in both scans and not paired
  double along = NAN, around = NAN, seconds = 0;
  double lps_along = NAN, lps_around = NAN;  // baseline: the same LPS point taken in the other scan
};

void print_header() {
  std::printf("load average %.2f\n", load_average());
  std::printf("%-28s %9s %7s %6s %7s %5s %6s %9s %10s %9s %9s %6s %7s %11s %12s\n", "pair", "vertices", "pieces", "polyps",
              "matched", "false", "missed", "along_mm", "around_deg", "det_pairs", "det_false", "det_np", "time_s",
              "lps_along", "lps_around");
}

void print_row(const Row& r) {
  std::printf("%-28s %9zu %7s %6d %7d %5d %6d %9.1f %10.1f %9d %9d %6d %7.2f %11.1f %12.1f\n", r.name.c_str(),
              r.vertices, r.pieces.c_str(), r.polyps, r.matched, r.false_matches, r.missed, r.along, r.around, r.det_pairs,
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
  r.along = median(along), r.around = median(around);
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

struct TruthPolyp {
  int id = 0;
  Eigen::Vector3d lps{0, 0, 0};
  double diameter = 0;
  double arc = 0;  // mm along the phantom centre line from the rectum
};

struct Truth {
  std::vector<TruthPolyp> polyps;
  std::vector<Eigen::Vector3d> centreline;
  std::vector<double> arc;
};

Eigen::Vector3d vec3(const nlohmann::json& a) { return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()}; }

Truth read_truth(const fs::path& dir) {
  Truth t;
  std::ifstream pin(dir / "polyps.json"), cin(dir / "centerline.json");
  const auto pj = nlohmann::json::parse(pin), cj = nlohmann::json::parse(cin);
  for (const auto& e : pj)
    t.polyps.push_back({e.value("id", 0), vec3(e.contains("position_lps_mm") ? e["position_lps_mm"] : e["center_lps_mm"]),
                        e.value("diameter_mm", 0.0), e.value("centreline_mm", e.value("arclength_mm", 0.0))});
  for (const auto& p : cj["points"]) t.centreline.push_back(vec3(p["p_lps_mm"])), t.arc.push_back(p["arclength_mm"].get<double>());
  return t;
}

// Nearest centre-line sample of a point.
size_t nearest_sample(const Truth& t, const Eigen::Vector3d& p) {
  size_t best = 0;
  for (size_t i = 1; i < t.centreline.size(); ++i)
    if ((t.centreline[i] - p).squaredNorm() < (t.centreline[best] - p).squaredNorm()) best = i;
  return best;
}

// Along (mm) and around (deg) distance of `mapped` from `truth` measured on the true centre line.
std::pair<double, double> truth_error(const Truth& t, const Eigen::Vector3d& mapped, const Eigen::Vector3d& truth) {
  const size_t a = nearest_sample(t, mapped), b = nearest_sample(t, truth);
  const size_t n = t.centreline.size();
  const Eigen::Vector3d tangent = (t.centreline[std::min(n - 1, b + 1)] - t.centreline[b > 0 ? b - 1 : 0]).normalized();
  Eigen::Vector3d ra = mapped - t.centreline[b], rb = truth - t.centreline[b];
  ra -= ra.dot(tangent) * tangent, rb -= rb.dot(tangent) * tangent;
  const double angle = std::acos(std::clamp(ra.normalized().dot(rb.normalized()), -1.0, 1.0)) * 180 / kPi;
  return {std::abs(t.arc[a] - t.arc[b]), angle};
}

// The truth polyp a detected candidate stands for (-1 = none).
int hit(const Truth& t, const cf::ScanCandidate& c) {
  for (const auto& q : t.polyps)
    if ((q.lps - c.lps).norm() <= q.diameter / 2 + 5) return q.id;
  return -1;
}

using Cuts = std::vector<std::pair<double, double>>;

// Truth polyps >= 6 mm, those inside a stretch cut out of the scan's mask left out (not seen).
std::vector<cf::ScanCandidate> as_candidates(const Truth& t, const Cuts& cuts = {}) {
  std::vector<cf::ScanCandidate> out;
  for (const auto& q : t.polyps) {
    bool cut = false;
    for (const auto& [a, b] : cuts) cut |= q.arc >= a - q.diameter && q.arc < b + q.diameter;
    if (q.diameter >= 6 && !cut) out.push_back({q.id, q.lps, q.diameter, 1});
  }
  return out;
}

Row pair_row(const std::string& name, const fs::path& sup_run, const fs::path& pro_run, const fs::path& sup_truth,
             const fs::path& pro_truth, const Cuts& prone_cuts = {}) {
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
  const Truth ts = read_truth(sup_truth), tp = read_truth(pro_truth);
  const auto cs = as_candidates(ts), cp = as_candidates(tp, prone_cuts);
  r.polyps = 0;
  for (const auto& q : cs)
    for (const auto& p : cp) r.polyps += p.id == q.id;
  count_id_pairs(reg.match(cs, cp), r.matched, r.false_matches);
  r.missed = r.polyps - r.matched;
  std::vector<double> along, around, lps_along, lps_around;
  for (const auto& q : cs)
    for (const auto& p : cp)
      if (p.id == q.id) {
        const Eigen::Vector3d mapped = reg.map_lps(q.lps, cf::Direction::kSupineToProne);
        if (!std::isfinite(mapped.sum())) continue;
        const auto [a, b] = truth_error(tp, mapped, p.lps);
        along.push_back(a), around.push_back(b);
        const auto [s, t] = reg.locate(q.lps, cf::Direction::kProneToSupine);  // nearest prone wall vertex
        const int w = reg.vertex_at(false, s, t);
        if (w < 0) continue;
        const auto [la, lb] = truth_error(tp, pro.lps[size_t(w)], p.lps);
        lps_along.push_back(la), lps_around.push_back(lb);
      }
  r.along = median(along), r.around = median(around);
  r.lps_along = median(lps_along), r.lps_around = median(lps_around);
  r.det_pairs = r.det_false = 0;
  for (const auto& m : reg.matching().pairs) {
    int hs = -2, hp = -3;
    for (const auto& c : sup.candidates) if (c.id == m.supine_id) hs = hit(ts, c);
    for (const auto& c : pro.candidates) if (c.id == m.prone_id) hp = hit(tp, c);
    if (hs == hp) (hs >= 0 ? r.det_pairs : r.det_nonpolyp) += 1;
    else r.det_false += 1;
  }
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

// One phantom patient, both positions run from their true lumen masks; the prone mask with
// stretches cut out (lumen_cut.h) as real segmentations differ: a collapse, a fully tagged stretch
// left out, the colon split into 3 more pieces, the rectum cut short by the catheter.
void cuts_table(int seed, const std::string& size, const fs::path& work) {
  std::printf("Phantom seed %d (%s), both scans run from the lumen mask (--from reconstruct); prone mask cut\n", seed,
              size.c_str());
  const fs::path d = work / ("cuts_seed" + std::to_string(seed));
  for (const std::string position : {"supine", "prone"}) {
    const fs::path ph = d / (position + "_phantom");
    std::vector<std::string> a = {"phantom", "--seed", std::to_string(seed), "--size", size, "-o", ph.string(), "-q"};
    if (position == "prone") a.insert(a.end(), {"--position", "prone"});
    if (!fs::exists(ph / "polyps.json") && colonflat(a) != 0) return;
  }
  auto run_mask = [&](const fs::path& mask, const fs::path& out) {
    return fs::exists(out / "flat.vtp") || colonflat({"run", mask.string(), "--from", "reconstruct", "-o", out.string(), "-q"}) == 0;
  };
  if (!run_mask(d / "supine_phantom" / "lumen_mask.nrrd", d / "supine_run")) return;
  const cf::PhantomCentreline cl = cf::read_phantom_centreline(d / "prone_phantom" / "centerline.json");
  const double L = cl.arc_mm.back();
  const std::vector<std::pair<std::string, Cuts>> cases = {
      {"uncut", {}},
      {"collapse 20 mm at 45 %", {{0.45 * L, 0.45 * L + 20}}},
      {"tagged 25 % dropped", {{0.40 * L, 0.65 * L}}},
      {"split +3 (15 mm each)", {{0.25 * L, 0.25 * L + 15}, {0.5 * L, 0.5 * L + 15}, {0.75 * L, 0.75 * L + 15}}},
      {"rectum cut 60 mm", {{0, 60}}}};
  print_header();
  for (size_t k = 0; k < cases.size(); ++k) {
    const fs::path mask = d / ("prone_cut" + std::to_string(k) + ".nrrd"), run = d / ("prone_run" + std::to_string(k));
    if (!fs::exists(mask)) cf::cut_lumen_mask(d / "prone_phantom" / "lumen_mask.nrrd", cl, cases[k].second, mask);
    if (!run_mask(mask, run)) continue;
    print_row(pair_row(cases[k].first, d / "supine_run", run, d / "supine_phantom", d / "prone_phantom", cases[k].second));
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
  app.add_option("--cuts", cuts_seed, "one phantom patient run from its masks, the prone mask cut (issue 27)");
  app.add_option("--size", size, "phantom size")->check(CLI::IsMember({"full", "small"}));
  app.add_option("--work", work, "work folder of the phantom pairs");
  app.add_option("--write-synthetic", synthetic_dir, "write a small synthetic pair as DIR/supine and DIR/prone");
  app.add_option("--twist", twist_deg, "with --write-synthetic: prone twist around the centre line (degrees)");
  app.add_option("--pair", pair, "one existing pair of run folders: SUP_RUN PRO_RUN")->expected(2);
  app.add_option("--truth", truth, "with --pair: the two phantom folders SUP_PHANTOM PRO_PHANTOM")->expected(2);
  return cli.run(argc, argv, [&] {
    if (cuts_seed > 0) {
      cuts_table(cuts_seed, size, work);
    } else if (!phantoms.empty()) {
      const auto [first, last] = cf::bench::parse_range(phantoms);
      phantom_table(first, last, size, work);
    } else if (!synthetic_dir.empty()) {
      cf::SyntheticPairOptions o;
      o.twist_deg = twist_deg;
      const cf::SyntheticPair pair_data = cf::make_synthetic_pair(o);
      cf::write_run_dir(pair_data.supine, fs::path(synthetic_dir) / "supine");
      cf::write_run_dir(pair_data.prone, fs::path(synthetic_dir) / "prone");
    } else if (!pair.empty()) {
      print_header();
      print_row(pair_row("pair", pair[0], pair[1], truth.empty() ? "" : truth[0], truth.empty() ? "" : truth[1]));
    } else {
      synthetic_table();
    }
    return 0;
  });
}
