#include "core/timing.h"

#include <gtest/gtest.h>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "core/parallel.h"

namespace throng {

TEST(Timing, CountsTotalsAndMedian) {
  auto& t = KernelTimings::global();
  t.reset();
  for (double ms : {5.0, 1.0, 3.0}) t.record("a", ms);
  t.record("b", 100.0);
  const auto s = t.stats();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "b");  // largest total first
  EXPECT_EQ(s[1].count, 3);
  EXPECT_DOUBLE_EQ(s[1].total_ms, 9.0);
  EXPECT_DOUBLE_EQ(s[1].median_ms, 3.0);
  EXPECT_DOUBLE_EQ(s[1].min_ms, 1.0);
  EXPECT_DOUBLE_EQ(s[1].max_ms, 5.0);
  t.record("a", 7.0);
  EXPECT_DOUBLE_EQ(t.stats()[1].median_ms, 4.0);  // even count: mean of the middle two
}

TEST(Timing, ParallelForRecordsByDescription) {
  auto& t = KernelTimings::global();
  t.reset();
  for (int i = 0; i < 4; ++i)
    parallel_for(
        "test.sleepy", 2, [](Index) { std::this_thread::sleep_for(std::chrono::milliseconds(2)); }, 1);
  const auto s = t.stats();
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].name, "test.sleepy");
  EXPECT_EQ(s[0].count, 4);
  EXPECT_GE(s[0].min_ms, 2.0);  // lower bound only: a timer cannot run early
}

TEST(Timing, JsonAndTable) {
  auto& t = KernelTimings::global();
  t.reset();
  t.record("stage.bin", 2.5);
  const auto j = nlohmann::json::parse(t.json());
  ASSERT_TRUE(j.is_array());
  EXPECT_EQ(j[0]["name"], "stage.bin");
  EXPECT_EQ(j[0]["count"], 1);
  EXPECT_DOUBLE_EQ(j[0]["median_ms"].get<double>(), 2.5);
  EXPECT_NE(t.table().find("stage.bin"), std::string::npos);
}

// Bytes counted beside the launches: summed per description, by prefix,
// reported in the JSON with a rate in the table, and forgotten on reset.
TEST(Timing, CountsBytesByDescriptionAndPrefix) {
  auto& t = KernelTimings::global();
  t.reset();
  const std::vector<float> four(4);
  const std::vector<glm::vec2> three(3);
  const Span<const float> f(four);
  const Span<const glm::vec2> v(three);
  EXPECT_EQ(bytes_of(f, v, v), 4 * 4 + 2 * 3 * 8);
  EXPECT_EQ(bytes_of(), 0);
  count_traffic("sim.a", f, v);  // 16 + 24
  count_traffic("sim.a", f);     // + 16
  t.count_bytes("sim.b.c", 100);
  t.count_bytes("other", 7);
  t.record("sim.a", 0.5);
  EXPECT_EQ(t.bytes_under("sim.a"), 56);
  EXPECT_EQ(t.bytes_under("sim."), 156);
  EXPECT_EQ(t.bytes_under(""), 163);
  EXPECT_EQ(t.bytes_under("nothing"), 0);
  const auto j = nlohmann::json::parse(t.json());
  bool found = false;
  for (const auto& row : j)
    if (row["name"] == "sim.a") {
      found = true;
      EXPECT_EQ(row["bytes"].get<std::int64_t>(), 56);
      EXPECT_EQ(row["count"].get<std::int64_t>(), 1);  // bytes alone count no launch
    }
  EXPECT_TRUE(found);
  EXPECT_NE(t.table().find("GB/s"), std::string::npos);
  EXPECT_NE(t.table().find("0.00"), std::string::npos);  // 56 bytes in 0.5 ms
  t.reset();
  EXPECT_EQ(t.bytes_under(""), 0);
}

TEST(Timing, RingKeepsBoundedSamples) {
  auto& t = KernelTimings::global();
  t.reset();
  const std::size_t n = KernelTimings::kMaxSamples + 100;
  for (std::size_t i = 0; i < n; ++i) t.record("many", 1.0);
  EXPECT_EQ(t.stats()[0].count, static_cast<std::int64_t>(n));
  EXPECT_DOUBLE_EQ(t.stats()[0].total_ms, static_cast<double>(n));
}

}  // namespace throng
