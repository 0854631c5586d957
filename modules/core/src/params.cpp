#include "colonflat/core/params.h"

#include <cstdio>

namespace cf {

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string ParamInfo::range_text() const {
  const bool has_min = min && std::isfinite(*min) && *min > -2147483648.0;
  const bool has_max = max && std::isfinite(*max) && *max < 2147483647.0;
  if (!has_min && !has_max) return "";
  return "[" + (has_min ? format_number(*min) : std::string("-inf")) + ", " +
         (has_max ? format_number(*max) : std::string("inf")) + "]";
}

std::string ParamInfo::describe() const {
  std::ostringstream s;
  s << help;
  if (!unit.empty()) s << " [" << unit << "]";
  s << " (default " << (default_text.empty() ? "''" : default_text);
  if (!range_text().empty()) s << "; range " << range_text();
  s << ")";
  return s.str();
}

std::string param_option_name(const std::string& member) {
  std::string name = member;
  for (char& c : name)
    if (c == '_') c = '-';
  return name;
}

namespace {

// `|` would end a Markdown table cell.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string option_cell(const ParamInfo& p) {
  if (p.type == "flag") return "`--" + p.name + "` / `--no-" + p.name + "`";
  std::string value;
  if (p.type == "choice")
    for (const auto& c : p.choices) value += (value.empty() ? "" : "|") + c;
  else value = p.type == "text" ? "TEXT" : p.type == "int" ? "INT" : "FLOAT";
  return "`--" + p.name + " " + cell(value) + "`";
}

}  // namespace

std::string param_markdown(const std::vector<ParamInfo>& params) {
  std::string md = "| option | default | unit | range | meaning |\n|---|---|---|---|---|\n";
  for (const ParamInfo& p : params) {
    const std::string default_text = p.default_text.empty() ? "''" : p.default_text;
    md += "| " + option_cell(p) + " | " + cell(default_text) + " | " + cell(p.unit) + " | " + p.range_text() + " | " +
          cell(p.help) + " |\n";
  }
  return md;
}

}  // namespace cf
