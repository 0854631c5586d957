#pragma once
// Declared parameters (the VMTK member table, in C++). A stage's parameters are declared ONCE, one
// line each, in a parameter list `<stage>_params.def` beside its header:
//
//   // member            default  unit  min   max   help
//   CF_REAL(max_loop_length, kInf, "mm", 1e-9, kInf, "cut only loops shorter than this")
//   CF_INT(target_genus,     0,    "",   0,    kIntMax, "stop when the total genus reaches this")
//   CF_TEXT(known_polyps,    "",   "JSON list of known polyps")
//   CF_CHOICE(method, "exact", ("exact", "paper"), "exact: ...; paper: ...")
//   CF_FLAG(strict,   false,   "fail when a cap still intersects the surface")
//
// From that list come the Options struct's fields with their defaults (core/params_as_fields.h)
// and the ParamTable (core/params_as_rows.h): the command line (--max-loop-length, --[no-]strict),
// --help, range checks, --params-in/--params-out JSON, the run report and the parameter table of
// the stage's docs page (`colonflat help --markdown STAGE`, scripts/update_param_docs.py).
// A ParamTable can also be written by hand:
//
//   ParamTable<Options> t;
//   t.real("max-loop-length", &Options::max_loop_length, "mm", "cut only loops shorter", 0.0);
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "colonflat/core/error.h"

namespace cf {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kIntMax = std::numeric_limits<int>::max();

struct ParamInfo {
  std::string name;          // CLI name without dashes; JSON key
  std::string type;          // "float", "int", "text", "choice", "flag"
  std::string unit;          // "mm", "HU", "" ...
  std::string help;
  std::string default_text;  // default value as shown in --help and docs
  std::optional<double> min, max;
  std::vector<std::string> choices;
  std::string describe() const;  // help line: "help [mm] (default 5; range [0, inf])"
  std::string range_text() const;  // "[0, inf]"; empty when unbounded
};

std::string format_number(double v);

// The option name of a parameter list's member: '_' -> '-' (max_loop_length -> max-loop-length).
std::string param_option_name(const std::string& member);

// The Markdown table of parameters for a docs page: option, default, unit, range, meaning.
std::string param_markdown(const std::vector<ParamInfo>& params);

template <class O>
class ParamTable {
 public:
  using options_type = O;
  ParamTable& real(const std::string& name, double O::*m, const std::string& unit, const std::string& help,
                   double min = -kInf, double max = kInf) {
    ParamInfo pi{name, "float", unit, help, format_number(O{}.*m), min, max, {}};
    add(pi,
        [m, pi](CLI::App& app, O& o) { app.add_option("--" + pi.name, o.*m, pi.describe())->type_name("FLOAT"); },
        [m](const O& o) { return std::isfinite(o.*m) ? nlohmann::json(o.*m) : nlohmann::json(format_number(o.*m)); },
        [m, name](const nlohmann::json& j, O& o) {
          if (j.is_number()) o.*m = j.get<double>();
          else if (j.is_string()) o.*m = parse_real(j.get<std::string>(), name);
          else throw UsageError("parameter '" + name + "' must be a number");
        },
        [m, pi](const O& o) { return check_range(pi, o.*m); });
    return *this;
  }
  ParamTable& integer(const std::string& name, int O::*m, const std::string& unit, const std::string& help,
                      int min = std::numeric_limits<int>::min(), int max = std::numeric_limits<int>::max()) {
    ParamInfo pi{name, "int", unit, help, std::to_string(O{}.*m), double(min), double(max), {}};
    add(pi, [m, pi](CLI::App& app, O& o) { app.add_option("--" + pi.name, o.*m, pi.describe())->type_name("INT"); },
        [m](const O& o) { return nlohmann::json(o.*m); },
        [m, name](const nlohmann::json& j, O& o) {
          if (!j.is_number_integer()) throw UsageError("parameter '" + name + "' must be an integer");
          o.*m = j.get<int>();
        },
        [m, pi](const O& o) { return check_range(pi, double(o.*m)); });
    return *this;
  }
  ParamTable& text(const std::string& name, std::string O::*m, const std::string& help) {
    ParamInfo pi{name, "text", "", help, O{}.*m, std::nullopt, std::nullopt, {}};
    // A text naming a file (its help says "file" or "JSON") shows FILE in --help.
    const bool is_file = help.find("file") != std::string::npos || help.find("JSON") != std::string::npos;
    add(pi,
        [m, pi, is_file](CLI::App& app, O& o) {
          app.add_option("--" + pi.name, o.*m, pi.describe())->type_name(is_file ? "FILE" : "TEXT");
        },
        [m](const O& o) { return nlohmann::json(o.*m); },
        [m, name](const nlohmann::json& j, O& o) {
          if (!j.is_string()) throw UsageError("parameter '" + name + "' must be a string");
          o.*m = j.get<std::string>();
        },
        [](const O&) { return std::string(); });
    return *this;
  }
  ParamTable& choice(const std::string& name, std::string O::*m, const std::vector<std::string>& choices,
                     const std::string& help) {
    ParamInfo pi{name, "choice", "", help, O{}.*m, std::nullopt, std::nullopt, choices};
    add(pi,
        [m, pi](CLI::App& app, O& o) {
          std::string tn;
          for (const auto& c : pi.choices) tn += (tn.empty() ? "" : "|") + c;
          app.add_option("--" + pi.name, o.*m, pi.describe())->type_name(tn);
        },
        [m](const O& o) { return nlohmann::json(o.*m); },
        [m, name](const nlohmann::json& j, O& o) {
          if (!j.is_string()) throw UsageError("parameter '" + name + "' must be a string");
          o.*m = j.get<std::string>();
        },
        [m, pi](const O& o) {
          for (const auto& c : pi.choices)
            if (c == o.*m) return std::string();
          std::string all;
          for (const auto& c : pi.choices) all += (all.empty() ? "" : ", ") + c;
          return "--" + pi.name + " must be one of " + all + " (got '" + o.*m + "')";
        });
    return *this;
  }
  ParamTable& flag(const std::string& name, bool O::*m, const std::string& help) {
    ParamInfo pi{name, "flag", "", help, (O{}.*m) ? "on" : "off", std::nullopt, std::nullopt, {}};
    add(pi,
        [m, pi](CLI::App& app, O& o) {
          // Two plain flags (CLI11's "!--no-x" form shows parser leftovers like "{false}" in --help).
          app.add_flag_function("--" + pi.name, [&o, m](std::int64_t) { o.*m = true; }, pi.describe());
          app.add_flag_function("--no-" + pi.name, [&o, m](std::int64_t) { o.*m = false; }, "turn --" + pi.name + " off");
        },
        [m](const O& o) { return nlohmann::json(o.*m); },
        [m, name](const nlohmann::json& j, O& o) {
          if (!j.is_boolean()) throw UsageError("parameter '" + name + "' must be true or false");
          o.*m = j.get<bool>();
        },
        [](const O&) { return std::string(); });
    return *this;
  }

  // Adds every parameter as --name to `app`, bound to `o`.
  void add_to(CLI::App& app, O& o) const {
    for (const auto& e : entries_) e.bind(app, o);
  }
  nlohmann::json to_json(const O& o) const {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& e : entries_) j[e.info.name] = e.get(o);
    return j;
  }
  // Sets the parameters present in `j`; unknown keys are an error (a typo must not pass silently).
  void from_json(const nlohmann::json& j, O& o, const std::string& where) const {
    if (!j.is_object()) throw UsageError(where + ": parameters must be a JSON object");
    for (auto it = j.begin(); it != j.end(); ++it) {
      const Entry* e = find(it.key());
      if (!e) throw UsageError(where + ": unknown parameter '" + it.key() + "'");
      e->set(it.value(), o);
    }
  }
  // Throws UsageError naming the first parameter out of its range.
  void validate(const O& o) const {
    for (const auto& e : entries_) {
      const std::string why = e.check(o);
      if (!why.empty()) throw UsageError(why);
    }
  }
  std::vector<ParamInfo> info() const {
    std::vector<ParamInfo> v;
    for (const auto& e : entries_) v.push_back(e.info);
    return v;
  }

 private:
  struct Entry {
    ParamInfo info;
    std::function<void(CLI::App&, O&)> bind;
    std::function<nlohmann::json(const O&)> get;
    std::function<void(const nlohmann::json&, O&)> set;
    std::function<std::string(const O&)> check;
  };
  void add(ParamInfo pi, std::function<void(CLI::App&, O&)> bind, std::function<nlohmann::json(const O&)> get,
           std::function<void(const nlohmann::json&, O&)> set, std::function<std::string(const O&)> check) {
    entries_.push_back({std::move(pi), std::move(bind), std::move(get), std::move(set), std::move(check)});
  }
  const Entry* find(const std::string& name) const {
    for (const auto& e : entries_)
      if (e.info.name == name) return &e;
    return nullptr;
  }
  static double parse_real(const std::string& s, const std::string& name) {
    if (s == "inf" || s == "+inf" || s == "infinity") return kInf;
    if (s == "-inf") return -kInf;
    throw UsageError("parameter '" + name + "' must be a number (got '" + s + "')");
  }
  static std::string check_range(const ParamInfo& pi, double v) {
    if (std::isnan(v)) return "--" + pi.name + " must be a number (got nan)";
    if (pi.min && v < *pi.min)
      return "--" + pi.name + " must be >= " + format_number(*pi.min) + " (got " + format_number(v) + ")";
    if (pi.max && v > *pi.max)
      return "--" + pi.name + " must be <= " + format_number(*pi.max) + " (got " + format_number(v) + ")";
    return "";
  }
  std::vector<Entry> entries_;
};

}  // namespace cf
