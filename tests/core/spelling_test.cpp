#include "core/spelling.h"

#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

namespace throng {
namespace {

TEST(Spelling, EditDistanceOfKnownPairs) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("run", "run"), 0u);
  EXPECT_EQ(edit_distance("rnu", "run"), 1u);  // one swap of neighbours
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("flaw", "lawn"), 2u);
  // Optimal string alignment edits no substring twice: "ca" -> "abc" is 3,
  // where unrestricted Damerau-Levenshtein would say 2.
  EXPECT_EQ(edit_distance("ca", "abc"), 3u);
  for (const auto& [a, b] :
       std::vector<std::pair<std::string, std::string>>{{"agents", "agnets"}, {"spawn", "spwan"}, {"x", "xyz"}})
    EXPECT_EQ(edit_distance(a, b), edit_distance(b, a)) << a << " " << b;
}

TEST(Spelling, ClosestNameSuggestsOnlyNearMisses) {
  const std::vector<std::string> commands{"run", "animate", "bench", "info", "view", "version"};
  EXPECT_EQ(closest_name("rnu", commands), "run");
  EXPECT_EQ(closest_name("inf", commands), "info");
  EXPECT_EQ(closest_name("animtae", commands), "animate");
  EXPECT_EQ(closest_name("bogus", commands), "");
  EXPECT_EQ(closest_name("xyz", commands), "");  // 3 edits from "run": too far
  const std::vector<std::string_view> keys{"agents", "spawn", "goal"};
  EXPECT_EQ(closest_name("agnets", keys), "agents");
  EXPECT_EQ(closest_name("gaol", keys), "goal");
}

}  // namespace
}  // namespace throng
