// `throng verify` end to end: the real executable runs RiMEA 3.0 tests from
// its embedded scenario files and writes report.md, report.json and a PNG
// chart per test; the figures the guideline judges are asserted here from
// report.json, and a failing test makes the exit status 1.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/io/throng_exe.h"

namespace {

namespace fs = std::filesystem;
using throng::io::testing::run;
using throng::io::testing::throng_exe;

// True when THRONG_SANITIZED is set (CI's ASan+UBSan run, several times slower).
bool sanitized() {
  const char* v = std::getenv("THRONG_SANITIZED");
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

class Verify : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("throng_verify_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // Runs `throng verify ARGS --out DIR` and reads DIR/report.json.
  nlohmann::json verify(const std::string& args, int expected_code) {
    const auto r = run(throng_exe(), "verify " + args + " --out " + dir_.string());
    EXPECT_EQ(r.code, expected_code) << r.out;
    std::ifstream in(dir_ / "report.json");
    EXPECT_TRUE(in.good()) << "no report.json: " << r.out;
    return in.good() ? nlohmann::json::parse(in) : nlohmann::json();
  }
  // The report's entry for RiMEA test `number`.
  static const nlohmann::json& test(const nlohmann::json& report, int number) {
    for (const nlohmann::json& t : report.at("tests"))
      if (t.at("number") == number) return t;
    throw std::runtime_error("test " + std::to_string(number) + " is not in the report");
  }
  // Every check of the test passed; prints them.
  static void expect_pass(const nlohmann::json& t) {
    EXPECT_EQ(t.at("status"), "pass") << t.dump(2);
    for (const nlohmann::json& c : t.at("checks")) {
      std::printf("  test %d: %s: %s\n", t.at("number").get<int>(), c.at("criterion").get<std::string>().c_str(),
                  c.at("measured").get<std::string>().c_str());
      EXPECT_TRUE(c.at("pass").get<bool>()) << c.dump();
    }
  }
  // The test's chart is a PNG file (its signature) of some size.
  void expect_png(const nlohmann::json& t) {
#if defined(THRONG_HAVE_RENDER)
    const fs::path png = dir_ / t.at("plot").get<std::string>();
    std::ifstream in(png, std::ios::binary);
    std::string head(8, '\0');
    in.read(head.data(), 8);
    EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8)) << png;
    EXPECT_GT(fs::file_size(png), 5000u) << png;
#else
    EXPECT_FALSE(t.contains("plot"));
#endif
  }
  fs::path dir_;
};

TEST_F(Verify, ListsEveryRimeaTestAndWhichDoNotApply) {
  const auto r = run(throng_exe(), "verify --list", false);
  ASSERT_EQ(r.code, 0) << r.out;
  int lines = 0, not_applicable = 0;
  for (std::size_t at = 0; (at = r.out.find('\n', at)) != std::string::npos; ++at) ++lines;
  for (std::size_t at = 0; (at = r.out.find("(not applicable)", at)) != std::string::npos; ++at) ++not_applicable;
  EXPECT_EQ(lines, 15) << r.out;
  EXPECT_EQ(not_applicable, 5) << r.out;  // 2, 3, 8, 13 and 14 need stairs or floors
}

TEST_F(Verify, BadSelectionsAreErrorsNamingTheOption) {
  auto r = run(throng_exe(), "verify --only 16 --out " + dir_.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("--only: no RiMEA 3.0 test 16"), std::string::npos) << r.out;
  r = run(throng_exe(), "verify --model fast --out " + dir_.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("--model"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "report.json"));
}

// The room-sized tests under the collision-free speed model: every check
// passes, with the figures the guideline names.
TEST_F(Verify, CollisionFreeSpeedPassesTheRoomTests) {
  const nlohmann::json report = verify("--model collision_free_speed --only 1,2,5,6,7,10,12", 0);
  EXPECT_EQ(report.at("model"), "collision_free_speed");
  ASSERT_EQ(report.at("tests").size(), 7u);
  EXPECT_EQ(test(report, 2).at("status"), "not applicable");
  for (int n : {1, 5, 6, 7, 10, 12}) {
    expect_pass(test(report, n));
    expect_png(test(report, n));
  }
  const double t1 = test(report, 1).at("figures").at("travel_time_s");
  EXPECT_GE(t1, 26.0);
  EXPECT_LE(t1, 34.0);
  EXPECT_EQ(test(report, 10).at("figures").at("by_assigned_exit"), 23);
  const nlohmann::json& f12 = test(report, 12).at("figures");
  EXPECT_GE(f12.at("outlet_flow_p_s").get<double>(), f12.at("exit_flow_p_s").get<double>() - 0.05);
  std::ifstream md(dir_ / "report.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("**6 passed, 0 failed, 1 not applicable.**"), std::string::npos) << text;
}

// The crowd-sized tests (1000 agents leaving rooms, 500 round a corner;
// the fundamental diagram over seven densities, some 2 minutes). Under the
// sanitizers only test 9.
TEST_F(Verify, CollisionFreeSpeedPassesTheCrowdTests) {
  const nlohmann::json report =
      verify(std::string("--model collision_free_speed --only ") + (sanitized() ? "9" : "4,9,11,15"), 0);
  const nlohmann::json& t9 = test(report, 9);
  expect_pass(t9);
  expect_png(t9);
  const double ratio = t9.at("figures").at("ratio");
  EXPECT_GE(ratio, 1.6);
  EXPECT_LE(ratio, 2.4);
  if (sanitized()) return;
  expect_pass(test(report, 4));
  expect_pass(test(report, 11));
  for (const nlohmann::json& p : test(report, 4).at("figures").at("points")) {
    if (p.at("target_p_m2").get<double>() > 5.0) continue;
    EXPECT_NEAR(p.at("speed_m_s").get<double>(), p.at("weidmann_m_s").get<double>(), 0.3) << p.dump();
  }
  EXPECT_GT(test(report, 11).at("figures").at("exit_2").get<int>(), 0);
  const nlohmann::json& t15 = test(report, 15);
  expect_pass(t15);
  expect_png(t15);
  const double corner = t15.at("figures").at("corner").at("last_arrival_s");
  EXPECT_LT(corner, t15.at("figures").at("long").at("last_arrival_s").get<double>());
  EXPECT_GT(corner, t15.at("figures").at("short").at("last_arrival_s").get<double>());
}

// Without --model the files run as written (the engine's default model).
// A failing test makes the exit status 1 and says what was measured: the
// priority model leaves people in the rooms of test 10 (its corridor is
// 1 m wide); should that model come to pass it, pick another failing case.
TEST_F(Verify, DefaultModelRunsTheFilesAndAFailureExitsNonZero) {
  const nlohmann::json passing = verify("--only 1,7", 0);
  EXPECT_EQ(passing.at("model"), "as the files say (the default model)");
  expect_pass(test(passing, 1));
  expect_pass(test(passing, 7));
  fs::remove_all(dir_);
  const nlohmann::json failing = verify("--model priority --only 10", 1);
  const nlohmann::json& t10 = test(failing, 10);
  EXPECT_EQ(t10.at("status"), "fail");
  EXPECT_LT(t10.at("figures").at("by_assigned_exit").get<int>(), 23);
}

}  // namespace
