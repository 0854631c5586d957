// The one reader of candidate lists (contract 2): render's candidates.json, the phantom's truth
// lists, the polyps.json fallback, and its one-line errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "colonflat/core/candidate_list.h"
#include "colonflat/core/error.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

std::string error_of(const nlohmann::json& doc) {
  try {
    candidate_list_from_json(doc, "cands.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Render's document: ids, LPS positions, sizes and scores come through as written.
TEST(CoreCandidateList, ReadsRenderCandidates) {
  const auto doc = nlohmann::json::parse(R"({"units": "mm", "candidates": [
      {"id": 4, "center_lps_mm": [1.5, -2, 3], "size_mm": 8.5, "score": 0.8},
      {"id": 7, "position_lps_mm": [10, 20, 30], "center_lps_mm": [0, 0, 0], "size_mm": 6, "score": 0.7}]})");
  const auto list = candidate_list_from_json(doc, "c.json");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].id, 4);
  EXPECT_EQ(list[0].lps_mm, (std::array<double, 3>{1.5, -2, 3}));
  EXPECT_DOUBLE_EQ(list[0].size_mm, 8.5);
  ASSERT_TRUE(list[0].score.has_value());
  EXPECT_DOUBLE_EQ(*list[0].score, 0.8);
  EXPECT_EQ(list[1].lps_mm, (std::array<double, 3>{10, 20, 30}));  // position_lps_mm wins
}

// Phantom truth: a plain list or {"polyps": [...]} with diameters and no score; ids default to
// the place in the list.
TEST(CoreCandidateList, ReadsTruthLists) {
  const auto plain = nlohmann::json::parse(R"([{"position": [1, 2, 3], "diameter_mm": 10}, {"center": [4, 5, 6]}])");
  const auto list = candidate_list_from_json(plain, "p.json");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].id, 1);
  EXPECT_EQ(list[1].id, 2);
  EXPECT_DOUBLE_EQ(list[0].size_mm, 10);
  EXPECT_DOUBLE_EQ(list[1].size_mm, 0);
  EXPECT_FALSE(list[0].score.has_value());
  const auto wrapped = nlohmann::json{{"polyps", plain}};
  EXPECT_EQ(candidate_list_from_json(wrapped, "p.json").size(), 2u);
}

// Malformed documents and entries are refused naming the file and the entry.
TEST(CoreCandidateList, MalformedEntriesAreRefused) {
  EXPECT_NE(error_of(nlohmann::json::parse(R"({"candidates": [{"id": 1, "center": [0, 0, 0]}, {"id": 2}]})"))
                .find("cands.json: candidate 2 has no position_lps_mm"),
            std::string::npos);
  EXPECT_NE(error_of(nlohmann::json::parse(R"([{"position_lps_mm": [0, 0]}])")).find("candidate 1"), std::string::npos);
  EXPECT_NE(error_of(nlohmann::json::parse(R"([{"position_lps_mm": [0, "a", 0]}])")).find("candidate 1"), std::string::npos);
  nlohmann::json nan_entry = nlohmann::json::array();
  nan_entry.push_back({{"position_lps_mm", {0.0, std::numeric_limits<double>::infinity(), 0.0}}});
  EXPECT_NE(error_of(nan_entry).find("candidate 1"), std::string::npos);
  EXPECT_NE(error_of(nlohmann::json::parse(R"([3])")).find("candidate 1"), std::string::npos);
  EXPECT_NE(error_of(nlohmann::json::parse(R"({"units": "mm"})")).find("no \"candidates\" list"), std::string::npos);
  EXPECT_NE(error_of(nlohmann::json::parse(R"("text")")).find("expected a candidate list"), std::string::npos);
}

// candidates.json is preferred, polyps.json (runs before the rename) is the fallback, and a run
// folder without either gives an empty path; read_candidate_list reads the file found.
TEST(CoreCandidateList, FindsCandidatesJsonThenPolypsJson) {
  testing::TempDir tmp;
  EXPECT_TRUE(find_candidate_file(tmp.path()).empty());
  std::ofstream(tmp / "polyps.json") << R"([{"center_lps_mm": [1, 2, 3]}])";
  EXPECT_EQ(find_candidate_file(tmp.path()), tmp / "polyps.json");
  std::ofstream(tmp / "candidates.json") << R"({"candidates": [{"id": 9, "position_lps_mm": [7, 8, 9], "score": 1}]})";
  EXPECT_EQ(find_candidate_file(tmp.path()), tmp / "candidates.json");
  const auto list = read_candidate_list(find_candidate_file(tmp.path()));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].id, 9);
  std::ofstream(tmp / "candidates.json") << "{ broken";
  EXPECT_THROW(read_candidate_list(tmp / "candidates.json"), InputError);
}

}  // namespace
}  // namespace cf
