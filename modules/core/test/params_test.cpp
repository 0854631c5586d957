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

}  // namespace
}  // namespace cf
