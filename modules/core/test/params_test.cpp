// Declared parameters: defaults, ranges, choices, JSON round-trips and CLI binding.
#include <gtest/gtest.h>

#include "colonflat/core/params.h"

namespace cf {
namespace {

struct Opts {
  double length = 5.0;      // mm
  int count = 3;
  std::string method = "exact";
  bool verbose = false;
  double limit = kInf;      // mm
};

ParamTable<Opts> table() {
  ParamTable<Opts> t;
  t.real("length", &Opts::length, "mm", "a length", 0.0, 100.0)
      .integer("count", &Opts::count, "", "a count", 0, 10)
      .choice("method", &Opts::method, {"exact", "paper"}, "the method")
      .flag("verbose", &Opts::verbose, "talk more")
      .real("limit", &Opts::limit, "mm", "a limit", 0.0);
  return t;
}

// The declaration carries defaults and units from Options{} into the help text.
TEST(Params, InfoCarriesDefaultsAndUnits) {
  auto info = table().info();
  ASSERT_EQ(info.size(), 5u);
  EXPECT_EQ(info[0].default_text, "5");
  EXPECT_EQ(info[0].unit, "mm");
  EXPECT_NE(info[0].describe().find("[mm] (default 5; range [0, 100])"), std::string::npos) << info[0].describe();
  EXPECT_EQ(info[4].default_text, "inf");
}

// Values out of range are rejected with a message naming the option and the value.
TEST(Params, RangeViolationsAreRejected) {
  Opts o;
  o.length = -1;
  try {
    table().validate(o);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--length must be >= 0 (got -1)");
  }
  o = Opts{};
  o.count = 11;
  EXPECT_THROW(table().validate(o), UsageError);
  o = Opts{};
  o.method = "magic";
  EXPECT_THROW(table().validate(o), UsageError);
  EXPECT_NO_THROW(table().validate(Opts{}));
}

// JSON round-trip keeps every value, infinity included; unknown keys are refused.
TEST(Params, JsonRoundTripAndUnknownKeys) {
  Opts o;
  o.length = 7.5;
  o.method = "paper";
  o.verbose = true;
  auto j = table().to_json(o);
  EXPECT_EQ(j["limit"], "inf");
  Opts back;
  table().from_json(j, back, "test");
  EXPECT_EQ(back.length, 7.5);
  EXPECT_EQ(back.method, "paper");
  EXPECT_TRUE(back.verbose);
  EXPECT_TRUE(std::isinf(back.limit));
  EXPECT_THROW(table().from_json({{"lenght", 3}}, back, "test"), UsageError);
  EXPECT_THROW(table().from_json({{"count", 2.5}}, back, "test"), UsageError);
}

// The CLI binds each parameter as --name and parses typed values.
TEST(Params, CliBinding) {
  Opts o;
  CLI::App app;
  table().add_to(app, o);
  app.parse(std::vector<std::string>{"--no-verbose", "paper", "--method", "4", "--count", "2.5", "--length"});
  EXPECT_EQ(o.length, 2.5);
  EXPECT_EQ(o.count, 4);
  EXPECT_EQ(o.method, "paper");
  EXPECT_FALSE(o.verbose);
}

// Options declared from a parameter list (core/params_as_fields.h, params_as_rows.h).
struct ListedOpts {
#define COLONFLAT_PARAMS "colonflat/testing/params_example.def"
#include "colonflat/core/params_as_fields.h"
};

ParamTable<ListedOpts> listed_table() {
  ParamTable<ListedOpts> t;
#define COLONFLAT_PARAMS "colonflat/testing/params_example.def"
#include "colonflat/core/params_as_rows.h"
  return t;
}

// One line of a parameter list gives the field with its default and the table row with the
// option name (member with '-'), unit, help, range and choices.
TEST(Params, ListDeclaresFieldDefaultAndTableRow) {
  const ListedOpts defaults;
  EXPECT_TRUE(std::isinf(defaults.max_loop_length));
  EXPECT_EQ(defaults.target_genus, 2);
  EXPECT_EQ(defaults.known_polyps, "");
  EXPECT_EQ(defaults.method, "exact");
  EXPECT_TRUE(defaults.check_caps);
  const auto info = listed_table().info();
  ASSERT_EQ(info.size(), 5u);
  EXPECT_EQ(info[0].name, "max-loop-length");
  EXPECT_EQ(info[0].describe(), "cut only loops shorter than this [mm] (default inf; range [1e-09, inf])");
  EXPECT_EQ(info[1].describe(), "stop at this genus (default 2; range [0, inf])");
  EXPECT_EQ(info[2].name, "known-polyps");
  EXPECT_EQ(info[3].choices, (std::vector<std::string>{"exact", "paper"}));
  EXPECT_EQ(info[4].default_text, "on");
  ListedOpts o;
  o.method = "other";
  EXPECT_THROW(listed_table().validate(o), UsageError);
  o = ListedOpts{};
  o.max_loop_length = 0;
  try {
    listed_table().validate(o);
    ADD_FAILURE() << "a length of 0 passed";
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "--max-loop-length must be >= 1e-09 (got 0)");
  }
  CLI::App app;
  listed_table().add_to(app, o);
  app.parse(std::vector<std::string>{"1", "--target-genus", "--no-check-caps"});  // CLI11: reversed
  EXPECT_EQ(o.target_genus, 1);
  EXPECT_FALSE(o.check_caps);
}

// The docs table: one row per parameter with option, default, unit, range and help; `|` escaped.
TEST(Params, MarkdownTable) {
  const std::string md = param_markdown(listed_table().info());
  EXPECT_EQ(md,
            "| option | default | unit | range | meaning |\n|---|---|---|---|---|\n"
            "| `--max-loop-length FLOAT` | inf | mm | [1e-09, inf] | cut only loops shorter than this |\n"
            "| `--target-genus INT` | 2 |  | [0, inf] | stop at this genus |\n"
            "| `--known-polyps TEXT` | '' |  |  | JSON file of known polyps |\n"
            "| `--method exact\\|paper` | exact |  |  | which method |\n"
            "| `--check-caps` / `--no-check-caps` | on |  |  | check every cap |\n");
}

}  // namespace
}  // namespace cf
