// What `colonflat run` tells a person: run_report.txt (a table) and the closing summary lines.
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "run_plan.h"

namespace cf {
namespace {

const nlohmann::json* stage_record(const nlohmann::json& report, const std::string& stage) {
  for (const auto& s : report.at("stages"))
    if (s.value("stage", "") == stage && s.contains("result")) return &s;
  return nullptr;
}

const nlohmann::json* stage_result(const nlohmann::json& report, const std::string& stage) {
  const nlohmann::json* s = stage_record(report, stage);
  return s ? &(*s)["result"] : nullptr;
}

// OUTDIR/<file> of a stage's output port, or "" when it was not written.
std::string output_file(const nlohmann::json& report, const std::string& stage, const std::string& port,
                        const std::string& outdir) {
  const nlohmann::json* s = stage_record(report, stage);
  if (!s || !s->contains("outputs") || !(*s)["outputs"].contains(port)) return "";
  return outdir + "/" + (*s)["outputs"][port].get<std::string>();
}

std::string number(const nlohmann::json& v, int precision = 1) {
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (!v.is_number()) return v.is_null() ? "?" : v.dump();
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v.get<double>();
  return s.str();
}

// A few scalar results of a stage, "key value" pairs, for the table's last column.
std::string key_results(const nlohmann::json& result) {
  static const char* keys[] = {"lumen_volume_ml", "segments",      "faces",    "genus_before", "genus_after",
                               "segment_count",   "flat_vertices", "candidates"};
  std::string s;
  for (const char* k : keys) {
    if (!result.contains(k)) continue;
    const auto& v = result[k];
    const std::string text = v.is_array() ? std::to_string(v.size()) : number(v, 1);
    s += (s.empty() ? "" : ", ") + std::string(k) + " " + text;
  }
  return s;
}

// The share of the wall the image shows: flatten's "coverage": {"fraction_shown"} over the whole
// colon, else the mean of its segments' coverage (a number or {"fraction"}).
std::string coverage_text(const nlohmann::json& flat) {
  const auto whole = flat.find("coverage");
  if (whole != flat.end() && whole->is_object() && whole->contains("fraction_shown") &&
      (*whole)["fraction_shown"].is_number()) {
    std::ostringstream t;
    t << std::fixed << std::setprecision(1) << 100.0 * (*whole)["fraction_shown"].get<double>() << " % of the wall shown";
    return t.str();
  }
  if (!flat.contains("segments") || !flat["segments"].is_array()) return "";
  double sum = 0;
  int n = 0;
  for (const auto& s : flat["segments"]) {
    if (!s.contains("coverage")) continue;
    const auto& c = s["coverage"];
    if (c.is_number()) sum += c.get<double>(), ++n;
    else if (c.is_object() && c.contains("fraction") && c["fraction"].is_number()) sum += c["fraction"].get<double>(), ++n;
  }
  if (!n) return "";
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << 100.0 * sum / n << " %";
  return t.str();
}

}  // namespace

std::string run_report_text(const nlohmann::json& r) {
  std::ostringstream t;
  t << "ColonFlat " << r.value("version", "") << " run on " << r.value("input", "") << " (units mm, LPS)\n\n";
  t << std::left << std::setw(13) << "stage" << std::right << std::setw(9) << "time s" << std::setw(11)
    << "peak MiB" << "  results\n";
  for (const auto& s : r.at("stages"))
    t << std::left << std::setw(13) << s.value("stage", "") << std::right << std::setw(9) << number(s["time_s"], 2)
      << std::setw(11) << number(s["peak_memory_mib"], 0) << "  " << key_results(s.value("result", nlohmann::json{}))
      << "\n";
  for (const auto& f : r.value("after_stages", nlohmann::json::array()))
    t << std::left << std::setw(13) << f.value("step", "") << std::right << std::setw(9)
      << number(f.value("time_s", nlohmann::json()), 2) << std::setw(11) << "" << "  after the stages\n";
  t << std::left << std::setw(13) << "total" << std::right << std::setw(9) << number(r["total_time_s"], 2)
    << std::setw(11) << number(r["peak_memory_mib"], 0) << "\n";
  if (r.contains("not_run")) t << "\nnot run: " << r["not_run"].get<std::string>() << "\n";
  return t.str();
}

std::string run_summary_text(const nlohmann::json& r, const std::string& outdir) {
  std::ostringstream t;
  t << "colonflat run: done in " << number(r["total_time_s"], 1) << " s, peak " << number(r["peak_memory_mib"], 0)
    << " MiB; results in " << outdir << "/\n";
  if (const auto* seg = stage_result(r, "segment"))
    if (seg->contains("lumen_volume_ml")) t << "  lumen          " << number((*seg)["lumen_volume_ml"], 0) << " mL\n";
  if (const auto* dn = stage_result(r, "denoise")) {
    t << "  genus          " << number(dn->value("genus_before", nlohmann::json())) << " -> "
      << number(dn->value("genus_after", nlohmann::json()));
    if (dn->contains("totals")) t << " (" << number((*dn)["totals"].value("loops", nlohmann::json())) << " loops cut)";
    t << "\n";
  }
  if (const auto* fl = stage_result(r, "flatten")) {
    t << "  segments       " << number(fl->value("segment_count", nlohmann::json()));
    const std::string cov = coverage_text(*fl);
    if (!cov.empty()) t << ", coverage " << cov;
    t << "\n";
  }
  if (const auto* rd = stage_result(r, "render")) {
    t << "  candidates     " << number(rd->value("candidates", nlohmann::json())) << " ("
      << output_file(r, "render", "candidates", outdir) << ")\n";
    t << "  image          " << output_file(r, "render", "colon_image", outdir) << "\n";
  }
  t << "  report         " << outdir << "/run_report.txt\n";
  if (std::filesystem::exists(std::filesystem::path(outdir) / "report.html"))
    t << "  review page    " << outdir << "/report.html\n";
  return t.str();
}

}  // namespace cf
