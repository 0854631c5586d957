#include "colonflat/register/review.h"

#include <vtkImageData.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/error.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/tool.h"
#include "colonflat/register/resources.h"
#include "colonflat/report/ct_views.h"
#include "colonflat/report/report_data.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

constexpr double kDegPerRad = 57.29577951308232;
double round1(double v) { return std::round(v * 10) / 10; }

// One scan's side of the review: its run, the registered scan, and what its views need.
struct ReviewScan {
  std::string name;  // "supine" / "prone"
  const RunData* run = nullptr;
  const ColonScan* scan = nullptr;
  Direction from = Direction::kSupineToProne;  // a map out of this scan
  ImagePtr colon;
  std::optional<ColonImageLayout> layout;
  std::unique_ptr<EndoluminalRenderer> endo;
};

class ReviewBuilder {
 public:
  ReviewBuilder(const ColonRegistration& reg, const RunData& sup, const RunData& pro, const ReviewOptions& opts,
                const fs::path& dir, OutputTransaction& tx)
      : reg_(reg), opts_(opts), dir_(dir), tx_(tx) {
    const auto set = [](ReviewScan& s, const char* name, const RunData& run, const ColonScan& scan, Direction from) {
      s.name = name, s.run = &run, s.scan = &scan, s.from = from;
    };
    set(scans_[0], "supine", sup, reg.supine(), Direction::kSupineToProne);
    set(scans_[1], "prone", pro, reg.prone(), Direction::kProneToSupine);
    for (const ReviewScan& s : scans_)
      for (const std::string& w : s.run->warnings) result.warnings.push_back(s.name + ": " + w);
  }

  // Colon images, their layouts and the endoluminal renderers of both scans; the images folder.
  void prepare() {
    files_dir_ = tx_.stage(dir_ / "report_files");
    fs::create_directories(files_dir_);
    for (ReviewScan& s : scans_) {
      std::vector<std::string> warnings;
      s.colon = colon_image_of(*s.run);
      std::string problem;
      if (auto made = colon_image_layout(*s.run, s.colon, &problem)) s.layout.emplace(*made);
      else if (s.colon) warnings.push_back("colon image layout does not match the flat map (" + problem + "): no crops");
      if (opts_.views.endoluminal) s.endo = make_endoluminal_renderer(*s.run, opts_.views.endoluminal_pixels, warnings);
      for (const auto& w : warnings) result.warnings.push_back(s.name + ": " + w);
    }
  }

  // Title, the side-by-side image with its marks, what each scan's cards need (CT geometry,
  // colon-image pixel, known polyps, link to the scan's own report).
  void add_header() {
    data_["title"] = "ColonFlat supine-prone review";
    data_["version"] = colonflat_version();
    data_["out_dir"] = fs::absolute(dir_).lexically_normal().string();
    const SideBySideMarks marks = side_by_side_marks(reg_, opts_.image);
    nlohmann::json mj = nlohmann::json::array();
    for (const SideBySideMark& m : marks.marks)
      mj.push_back({{"scan", m.supine ? "supine" : "prone"}, {"key", "P" + std::to_string(m.id)}, {"x", m.x},
                    {"y", m.row}, {"r", m.radius}});
    data_["image"] = {{"file", opts_.side_by_side_file}, {"width", marks.width}, {"height", marks.height}, {"marks", mj}};
    for (const ReviewScan& s : scans_) data_["scans"][s.name] = scan_json(s);
    const auto& c = reg_.supine_coordinates();
    data_["registration"] = {{"supine_length_mm", round1(c.profile.length_mm())},
                             {"prone_length_mm", round1(reg_.prone_coordinates().profile.length_mm())},
                             {"prone_reversed", reg_.prone_reversed()},
                             {"along_from", c.from_rectum ? "rectum" : "start of the supine map"},
                             {"file", "registration.json"}};
    data_["alignment"] = alignment_json();
  }

  // Where the two colons could be aligned: pieces per scan, shared landmarks, anchors, and the
  // stretches of the supine axis without support (shown striped on the side-by-side image).
  nlohmann::json alignment_json() const {
    const AlignmentSupport& s = reg_.support();
    nlohmann::json gaps = nlohmann::json::array(), marks = nlohmann::json::array();
    for (const auto& [a, b] : s.unsupported) gaps.push_back({round1(a), round1(b)});
    for (const auto& l : reg_.shared_landmarks())
      if (l.consistent) marks.push_back(l.name);
    int candidate_anchors = 0;
    for (const auto& a : reg_.anchors()) candidate_anchors += a.kind == "candidate";
    return {{"supported_fraction", std::round(s.supported_fraction * 1000) / 1000},
            {"unaligned_mm", gaps},
            {"pieces", {{"supine", reg_.pieces().supine.size()}, {"prone", reg_.pieces().prone.size()}}},
            {"shared_landmarks", marks},
            {"candidate_anchors", candidate_anchors},
            {"max_unsupported_mm", reg_.options().max_unsupported_mm}};
  }

  // One row per candidate pair: both scans' cards with registered positions and the pair's figures.
  void add_pairs() {
    nlohmann::json rows = nlohmann::json::array();
    for (const CandidateMatch& m : reg_.matching().pairs) {
      const ReportFinding* a = candidate(scans_[0], m.supine_id);
      const ReportFinding* b = candidate(scans_[1], m.prone_id);
      if (!a || !b) throw Error("review: candidate pair S" + std::to_string(m.supine_id) + "/P" +
                                std::to_string(m.prone_id) + " is not in the runs' candidate lists");
      rows.push_back({{"supine", own_card(scans_[0], *a)}, {"prone", own_card(scans_[1], *b)},
                      {"along_mm", round1(m.along_mm)}, {"around_deg", round1(m.around_deg)},
                      {"size_ratio", std::round(m.size_ratio * 100) / 100}, {"score", std::round(m.score * 1000) / 1000},
                      {"anchor_mm", std::isfinite(m.anchor_mm) ? nlohmann::json(round1(m.anchor_mm)) : nlohmann::json(nullptr)}});
    }
    data_["pairs"] = rows;
    result.pairs = int(rows.size());
  }

  // One row per candidate seen in one scan only: its card and the other scan's views where it maps.
  void add_singles() {
    nlohmann::json rows = nlohmann::json::array();
    const auto add = [&](ReviewScan& own, ReviewScan& other, const std::vector<int>& ids, const std::vector<int>& unaligned) {
      for (int id : ids) {
        const ReportFinding* f = candidate(own, id);
        if (!f) throw Error("review: " + own.name + " candidate P" + std::to_string(id) + " is not in its run's list");
        const bool no_support = std::find(unaligned.begin(), unaligned.end(), id) != unaligned.end();
        rows.push_back({{"scan", own.name}, {"finding", own_card(own, *f)}, {"probe", probe_card(own, other, *f)},
                        {"unaligned", no_support}});
      }
    };
    add(scans_[0], scans_[1], reg_.matching().supine_only, reg_.matching().supine_unaligned);
    add(scans_[1], scans_[0], reg_.matching().prone_only, reg_.matching().prone_unaligned);
    data_["singles"] = rows;
    result.singles = int(rows.size());
  }

  void write_page() {
    data_["warnings"] = result.warnings;
    const std::string html = report_page_html("ColonFlat supine-prone review", register_resources::kReviewHtml, data_,
                                              register_resources::kReviewCss, register_resources::kReviewJs);
    std::ofstream(tx_.stage(dir_ / "report.html")) << html;
  }

  ReviewResult result;

 private:
  nlohmann::json scan_json(const ReviewScan& s) const {
    const RunData& run = *s.run;
    nlohmann::json j = {{"run_dir", fs::absolute(run.dir).lexically_normal().string()},
                        {"candidates_file", run.candidates_file}};
    if (has_ct(run) || run.mask) j["ct"] = with_view_volume(run, [](const auto* volume) { return ct_geometry_json(volume); });
    if (j.contains("ct")) j["ct"]["is_mask"] = run.volume_is_mask;
    j["image"] = {{"pixel_size_mm", colon_image_pixel_size(run)}};
    nlohmann::json known = nlohmann::json::array();
    for (const ReportFinding& k : run.known) known.push_back(finding_json(run, k, nullptr));
    j["known"] = known;
    const fs::path report = run.dir / "report.html";
    const auto staged = tx_.targets();
    if (fs::exists(report) || std::find(staged.begin(), staged.end(), report) != staged.end())
      j["report"] = fs::relative(fs::absolute(report), fs::absolute(dir_)).generic_string();
    return j;
  }

  const ReportFinding* candidate(const ReviewScan& s, int id) const {
    for (const ReportFinding& f : s.run->candidates)
      if (f.id == id) return &f;
    return nullptr;
  }

  // (s, angle) of an LPS point of `own`, and where the registration maps it in the other scan.
  nlohmann::json registered(const ReviewScan& own, const std::array<double, 3>& lps) const {
    const auto [s, theta] = reg_.locate(Eigen::Vector3d(lps[0], lps[1], lps[2]), own.from);
    return registered_at(own, s, theta);
  }

  // The same for a candidate of `own`: at the place it was matched at (candidate_place()).
  nlohmann::json registered_candidate(const ReviewScan& own, int id) const {
    const auto [s, theta] = reg_.candidate_place(id, own.from);
    return registered_at(own, s, theta);
  }

  nlohmann::json registered_at(const ReviewScan& own, double s, double theta) const {
    if (std::isnan(s)) return nullptr;
    double s2 = 0, theta2 = 0;
    reg_.map_coordinates(own.from, s, theta, s2, theta2);
    return {{"s_mm", round1(s)}, {"angle_deg", round1(theta * kDegPerRad)},
            {"maps_to", {{"s_mm", round1(s2)}, {"angle_deg", round1(theta2 * kDegPerRad)}}}};
  }

  // A finding's card data with its images (file names prefixed by the scan).
  nlohmann::json card_with_images(ReviewScan& s, ReportFinding f, const std::string& file_key,
                                  const ReportOptions& views) {
    const std::string key = f.key;
    f.key = file_key;
    nlohmann::json fj = finding_json(*s.run, f, s.layout ? &*s.layout : nullptr);
    result.images += write_finding_images(*s.run, f, views, files_dir_, s.colon, s.endo.get(), fj);
    if (fj.contains("endoluminal")) ++result.endoluminal_views;
    fj["key"] = key;
    fj["scan"] = s.name;
    return fj;
  }

  nlohmann::json own_card(ReviewScan& s, const ReportFinding& f) {
    nlohmann::json fj = card_with_images(s, f, s.name + "_" + f.key, opts_.views);
    fj["registered"] = registered_candidate(s, f.id);
    return fj;
  }

  // The other scan's views at the registered position of `f`, with the nearest candidate there.
  nlohmann::json probe_card(ReviewScan& own, ReviewScan& other, const ReportFinding& f) {
    const auto [s, theta] = reg_.candidate_place(f.id, own.from);
    const int v = std::isnan(s) ? -1 : reg_.map_vertex(own.from, s, theta);
    if (v < 0) return {{"not_registered", true}};
    ReportFinding probe;
    probe.key = f.key;
    probe.size_mm = f.size_mm;
    const Eigen::Vector3d& p = other.scan->lps[size_t(v)];
    probe.lps_mm = {p.x(), p.y(), p.z()};
    probe.flat_vertex = run_vertex(other, v);
    // A wider field of view than the finding's own: the registration is off by up to ~10 mm / 20 deg.
    ReportOptions views = opts_.views;
    views.min_fov_mm = std::max(views.min_fov_mm, opts_.check_min_fov_mm);
    views.max_fov_mm = std::max(views.max_fov_mm, views.min_fov_mm);
    nlohmann::json pj = card_with_images(other, probe, other.name + "_at_" + own.name + "_" + f.key, views);
    pj.erase("score");
    pj["probe_of"] = {{"scan", own.name}, {"key", f.key}};
    pj["registered"] = registered(other, probe.lps_mm);
    pj["nearest_candidate"] = nearest_candidate(other, pj["registered"]);
    return pj;
  }

  // The other scan's candidate nearest to a registered position (along, around), or null.
  nlohmann::json nearest_candidate(const ReviewScan& s, const nlohmann::json& at) const {
    if (at.is_null()) return nullptr;
    nlohmann::json best = nullptr;
    double best_cost = std::numeric_limits<double>::infinity();
    for (const ReportFinding& c : s.run->candidates) {
      const auto [cs, ct] = reg_.candidate_place(c.id, s.from);
      if (std::isnan(cs)) continue;
      const double along = std::abs(cs - at["s_mm"].get<double>());
      const double around = std::abs(std::remainder(ct * kDegPerRad - at["angle_deg"].get<double>(), 360.0));
      const double cost = along * along + around * around;
      if (cost < best_cost) best_cost = cost, best = {{"key", c.key}, {"along_mm", round1(along)}, {"around_deg", round1(around)}};
    }
    return best;
  }

  // The run's flat vertex of the registered scan's vertex `v` (the same index when both hold the
  // same map, else the nearest by LPS position).
  int run_vertex(const ReviewScan& s, int v) const {
    if (!s.run->flat) return -1;
    const auto& pos = s.run->flat->position;
    const Eigen::Vector3d& p = s.scan->lps[size_t(v)];
    const auto d2 = [&](std::size_t i) {
      return (pos[i][0] - p.x()) * (pos[i][0] - p.x()) + (pos[i][1] - p.y()) * (pos[i][1] - p.y()) +
             (pos[i][2] - p.z()) * (pos[i][2] - p.z());
    };
    if (pos.size() == s.scan->lps.size() && d2(size_t(v)) < 1e-6) return v;
    std::size_t best = 0;
    for (std::size_t i = 1; i < pos.size(); ++i)
      if (d2(i) < d2(best)) best = i;
    return int(best);
  }

  const ColonRegistration& reg_;
  const ReviewOptions& opts_;
  fs::path dir_, files_dir_;
  OutputTransaction& tx_;
  ReviewScan scans_[2];
  nlohmann::json data_ = nlohmann::json::object();
};

// Test-only fault injection: COLONFLAT_TEST_FAIL=review fails after the images are written.
void maybe_inject_fault() {
  const char* fail = std::getenv("COLONFLAT_TEST_FAIL");
  if (fail && std::string(fail) == "review") throw Error("review: failure injected by COLONFLAT_TEST_FAIL=review (test only)");
}

}  // namespace

ReviewResult stage_review(const ColonRegistration& reg, const RunData& supine, const RunData& prone,
                          const ReviewOptions& opts, const fs::path& dir, OutputTransaction& tx, std::ostream* log) {
  Stopwatch clock;
  ProgressScope scope(log, "review");
  ReviewBuilder b(reg, supine, prone, opts, dir, tx);
  b.prepare();
  phase_done("colon images and endoluminal renderers");
  b.add_header();
  b.add_pairs();
  phase_done(std::to_string(b.result.pairs) + " candidate pairs");
  b.add_singles();
  phase_done(std::to_string(b.result.singles) + " one-scan-only candidates with the other scan there");
  maybe_inject_fault();
  b.write_page();
  phase_done("page");
  for (const auto& p : scope.phases()) b.result.phases.emplace_back(p["phase"].get<std::string>(), p["time_s"].get<double>());
  b.result.seconds = clock.seconds();
  return b.result;
}

}  // namespace cf
