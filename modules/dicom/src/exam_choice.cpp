// Which series of an exam are the CT colonography scans, and why the others are not.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/dicom/exam.h"
#include "dicom_common.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

std::string mm(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(v < 10 ? 2 : 0) << v << " mm";
  return s.str();
}

// Why `s` is not a CT colonography scan; "" when it is one.
std::string rejection(const ExamSeries& s, const ExamRules& r) {
  if (s.modality != "CT") return "modality " + (s.modality.empty() ? std::string("missing") : s.modality) + ", not CT";
  if (dicom::upper(s.image_type).find("LOCALIZER") != std::string::npos)
    return "a localizer (ImageType " + s.image_type + ")";
  if (int(s.files.size()) < r.min_slices)
    return "only " + std::to_string(s.files.size()) + " slice(s) (a scan has at least " + std::to_string(r.min_slices) + ")";
  if (s.axis_cosine < r.min_axis_cosine) {
    const double deg = std::acos(std::clamp(s.axis_cosine, 0.0, 1.0)) * 180.0 / M_PI;
    return "not axial (slice normal " + std::to_string(int(std::lround(deg))) + " degrees from the head-feet axis)";
  }
  if (s.coverage_mm < r.min_coverage_mm)
    return "covers " + mm(s.coverage_mm) + " along the body, less than the " + mm(r.min_coverage_mm) +
           " a colon needs";
  if (s.posture().empty())
    return "PatientPosition " + (s.position.empty() ? std::string("missing") : "'" + s.position + "' unknown") +
           " (supine or prone?)";
  if (!s.same_folder) return "its files lie in several folders";
  return "";
}

// Of two scans of one posture: the thinner slices, then more slices, then the lower series number.
bool better(const ExamSeries& a, const ExamSeries& b) {
  if (std::abs(a.thickness_mm - b.thickness_mm) > 0.01) return a.thickness_mm < b.thickness_mm;
  if (a.files.size() != b.files.size()) return a.files.size() > b.files.size();
  return a.number < b.number;
}

// Why `other` (a scan of the same posture as `chosen`) is not the one used.
std::string second_choice(const ExamSeries& other, const ExamSeries& chosen) {
  const std::string head = "another " + chosen.posture() + " reconstruction: series " + std::to_string(chosen.number);
  if (std::abs(other.thickness_mm - chosen.thickness_mm) > 0.01)
    return head + " has thinner slices (" + mm(chosen.thickness_mm) + " against " + mm(other.thickness_mm) + ")";
  if (other.files.size() != chosen.files.size())
    return head + " has the same slice thickness and more slices (" + std::to_string(chosen.files.size()) + ")";
  return head + " is the same and comes first";
}

// Several patients or studies in one exam: refused with the list.
void check_one_exam(const fs::path& exam, const std::vector<ExamSeries>& series) {
  std::map<std::string, int> patients, studies;
  for (const auto& s : series) {
    ++patients[s.patient_id + (s.patient_name.empty() ? "" : " (" + s.patient_name + ")")];
    ++studies[s.study_uid];
  }
  auto list = [](const std::map<std::string, int>& m) {
    std::string out;
    for (const auto& [k, n] : m) out += (out.empty() ? "" : ", ") + k + ": " + std::to_string(n) + " series";
    return out;
  };
  if (patients.size() > 1)
    throw InputError(exam.string(), "holds " + std::to_string(patients.size()) + " patients (" + list(patients) +
                                        "); give one patient's exam");
  if (studies.size() > 1)
    throw InputError(exam.string(), "holds " + std::to_string(studies.size()) + " studies (" + list(studies) +
                                        "); give one study");
}

}  // namespace

std::string ExamSeries::posture() const {
  const std::string p = dicom::upper(position);
  if (p == "HFS" || p == "FFS") return "supine";
  if (p == "HFP" || p == "FFP") return "prone";
  if (p == "HFDR" || p == "HFDL" || p == "FFDR" || p == "FFDL") return "decubitus";
  return "";
}

std::string ExamSeries::label() const {
  std::ostringstream s;
  s << "series " << number << (description.empty() ? "" : " '" + description + "'") << " ("
    << (position.empty() ? modality : position) << ", " << files.size() << " slice" << (files.size() == 1 ? "" : "s");
  if (thickness_mm > 0) s << ", " << mm(thickness_mm);
  s << ")";
  return s.str();
}

ExamChoice choose_exam_scans(const fs::path& exam, const std::vector<ExamSeries>& series, const ExamRules& rules) {
  check_one_exam(exam, series);
  ExamChoice c;
  c.series = series;
  std::map<std::string, std::vector<const ExamSeries*>> by_posture;
  for (const auto& s : series) {
    const std::string why = rejection(s, rules);
    if (why.empty()) by_posture[s.posture()].push_back(&s);
    else c.not_used.emplace_back(s.uid, why);
  }
  std::map<std::string, const ExamSeries*> best;
  for (auto& [posture, list] : by_posture) {
    std::sort(list.begin(), list.end(), [](const ExamSeries* a, const ExamSeries* b) { return better(*a, *b); });
    best[posture] = list.front();
    for (std::size_t k = 1; k < list.size(); ++k) c.not_used.emplace_back(list[k]->uid, second_choice(*list[k], *list[0]));
  }
  if (best.empty()) {
    std::string reasons;
    for (const auto& [uid, why] : c.not_used) reasons += (reasons.empty() ? "" : "; ") + uid + ": " + why;
    throw InputError(exam.string(), "no CT colonography scan among its " + std::to_string(series.size()) +
                                        " series (" + reasons + ")");
  }
  for (const char* p : {"supine", "prone", "decubitus"})
    if (best.count(p) && !c.supine) c.supine = *best[p], c.first_posture = p;
  if (c.first_posture == "supine" && best.count("prone")) c.prone = *best["prone"];
  if (best.count("decubitus") && c.first_posture != "decubitus")
    c.not_used.emplace_back(best["decubitus"]->uid,
                            "a decubitus scan: the two-scan run pairs supine with prone");
  return c;
}

nlohmann::json ExamChoice::to_json() const {
  auto used = [](const ExamSeries& s, const std::string& as) {
    return nlohmann::json{{"as", as},           {"series_uid", s.uid},          {"series_number", s.number},
                          {"description", s.description}, {"patient_position", s.position}, {"slices", s.files.size()},
                          {"slice_thickness_mm", s.thickness_mm}, {"coverage_mm", s.coverage_mm},
                          {"folder", s.folder.string()}};
  };
  nlohmann::json j = {{"series_found", series.size()}, {"used", nlohmann::json::array()}, {"not_used", nlohmann::json::array()}};
  if (!series.empty()) j["study_uid"] = series.front().study_uid, j["patient_id"] = series.front().patient_id;
  if (supine) j["used"].push_back(used(*supine, two_scans() ? "supine" : first_posture));
  if (prone) j["used"].push_back(used(*prone, "prone"));
  for (const auto& [uid, why] : not_used) {
    nlohmann::json n = {{"series_uid", uid}, {"reason", why}};
    for (const auto& s : series)
      if (s.uid == uid) n["series_number"] = s.number, n["description"] = s.description;
    j["not_used"].push_back(n);
  }
  return j;
}

std::string ExamChoice::text() const {
  std::ostringstream out;
  out << "exam: " << series.size() << " series";
  if (!series.empty()) out << " of patient " << series.front().patient_id;
  out << "\n";
  if (supine) out << "  used (" << (two_scans() ? "supine" : first_posture) << "): " << supine->label() << "\n";
  if (prone) out << "  used (prone): " << prone->label() << "\n";
  for (const auto& [uid, why] : not_used)
    for (const auto& s : series)
      if (s.uid == uid) out << "  not used: " << s.label() << ": " << why << "\n";
  return out.str();
}

}  // namespace cf
