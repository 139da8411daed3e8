// `throng info FILE.bvh --json` and `throng convert` run as a user runs them.
// The executable is the build's (THRONG_EXE, built before this test); the
// tests skip when ../shared is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "io/bvh_reader.h"
#include "motion/fk.h"
#include "tests/io/throng_exe.h"
#include "tests/shared_data.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

using testing::Result;
using testing::run;
using testing::throng_exe;

#define REQUIRE_EXE_AND_SHARED(exe, dir) \
  const fs::path exe = throng_exe();     \
  THRONG_NEED_SHARED_BVH(dir)

// Header facts read without the reader.
struct Header {
  int joints = 0;
  long frames = -1;
  double frame_time = -1;
};
Header read_header(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  Header h;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string first;
    words >> first;
    if (first == "ROOT" || first == "JOINT") ++h.joints;
    if (first == "Frames:") words >> h.frames;
    if (first == "Frame") {
      std::string time;
      words >> time >> h.frame_time;
      break;
    }
  }
  return h;
}

TEST(BvhCli, InfoJsonMatchesEveryHeader) {
  REQUIRE_EXE_AND_SHARED(exe, dir);
  int files = 0;
  for (const auto& e : fs::directory_iterator(*dir)) {
    if (e.path().extension() != ".bvh") continue;
    ++files;
    const Result r = run(exe, "info " + e.path().string() + " --json", false);
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = nlohmann::json::parse(r.out);
    const Header h = read_header(e.path());
    EXPECT_EQ(j["joints"].get<int>(), h.joints) << e.path();
    EXPECT_EQ(j["frames"].get<long>(), h.frames) << e.path();
    EXPECT_EQ(j["frame_time"].get<double>(), h.frame_time) << e.path();
    EXPECT_NEAR(j["duration"].get<double>(), h.frames * h.frame_time, 1e-9);
    EXPECT_TRUE(j["units"]["detected"].get<bool>());
    EXPECT_EQ(j["skeleton"].size(), static_cast<std::size_t>(h.joints));
    EXPECT_FALSE(j["roles"]["left_knee"].is_null());
    ASSERT_TRUE(j.contains("cycle"));
    if (e.path().filename().string().find("_walk_") != std::string::npos) {  // a walk has a gait cycle
      ASSERT_TRUE(j["cycle"].is_object()) << e.path();
      EXPECT_GT(j["cycle"].value("period_s", 0.0), 0.3) << j["cycle"];
    }
  }
  EXPECT_GT(files, 0);
}

TEST(BvhCli, InfoTextAndOptions) {
  REQUIRE_EXE_AND_SHARED(exe, dir);
  const std::string file = (*dir / "cmu_02_01_walk_mb.bvh").string();
  Result r = run(exe, "info " + file);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("joints       31 (7 end sites), 96 channels"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cmu (detected)"), std::string::npos) << r.out;
  r = run(exe, "info " + file + " --json --units cm --role left_knee=LeftFoot", false);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["units"]["unit"], "cm");
  EXPECT_FALSE(j["units"]["detected"].get<bool>());
  EXPECT_EQ(j["roles"]["left_knee"], "LeftFoot");
}

TEST(BvhCli, ConvertRoundTripsAndNormalises) {
  REQUIRE_EXE_AND_SHARED(exe, dir);
  const fs::path in = *dir / "cmu_131_02_start_walk_stop_max.bvh";  // mixed orders, CMU units
  const fs::path out = fs::temp_directory_path() / "throng_bvh_cli_convert.bvh";
  const Result r = run(exe, "convert " + in.string() + " " + out.string() + " --order YXZ --units m");
  ASSERT_EQ(r.code, 0) << r.out;
  const BvhFile a = read_bvh(in.string());
  BvhReadOptions metres;
  metres.unit = motion::LengthUnit::Metre;
  const BvhFile b = read_bvh(out.string(), metres);
  fs::remove(out);
  for (std::int32_t jn = 0; jn < b.skeleton.joint_count(); ++jn) EXPECT_EQ(b.rotation_order(jn), "YXZ");
  EXPECT_EQ(b.frame_time, a.frame_time);
  const auto ma = motion::forward_kinematics(a.skeleton, a.clip);
  const auto mb = motion::forward_kinematics(b.skeleton, b.clip);
  ASSERT_EQ(ma.positions.size(), mb.positions.size());
  double worst = 0;
  for (std::size_t i = 0; i < ma.positions.size(); ++i)
    worst = std::max(worst, static_cast<double>(glm::length(ma.positions[i] - mb.positions[i])));
  EXPECT_LT(worst, 1e-4);
}

std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

TEST(BvhCli, ErrorsAreOneLineWithNonZeroExit) {
  const fs::path exe = throng_exe();
  const fs::path bad = fs::path(THRONG_SOURCE_DIR) / "tests" / "data" / "bvh_bad" / "nan_value.bvh";
  const fs::path tmp = fs::temp_directory_path() / "throng_bvh_cli_out.bvh";
  // Exit status 1 for a bad file or value (throng::Error), 2 for a bad
  // command line (CLI11); the message names what is wrong.
  struct Case {
    std::string args;
    int code;
    std::string names;
  };
  const std::vector<Case> cases = {{"info /nonexistent/x.bvh", 1, "/nonexistent/x.bvh: cannot read"},
                                   {"info " + bad.string(), 1, "nan_value.bvh:26:"},
                                   {"info README.md", 1, "README.md: cannot describe this file type"},
                                   {"convert " + bad.string() + " " + tmp.string(), 1, "nan_value.bvh:26:"},
                                   {"convert a.bvh b.bvh --order QQQ", 1, "--order: unknown rotation order 'QQQ'"},
                                   {"convert a.bvh b.bvh --units parsec", 1, "--units: unknown unit 'parsec'"},
                                   {"info x.bvh --units furlong", 1, "--units: unknown unit 'furlong'"},
                                   {"info x.bvh --role elbow=X", 1, "--role: expected ROLE=JOINT"},
                                   {"convert onlyone.bvh", 2, "output is required"}};
  for (const Case& c : cases) {
    const Result r = run(exe, c.args);
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_EQ(r.code, c.code) << c.args << " printed:\n" << r.out;
    EXPECT_EQ(lines(r.out), 1u) << c.args << " printed:\n" << r.out;
    EXPECT_NE(r.out.find("error"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.rfind("throng: error: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find(c.names), std::string::npos) << c.args << " printed:\n" << r.out;
  }
  const Result r = run(exe, "info " + bad.string());
  EXPECT_NE(r.out.find("nan_value.bvh:26:"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(tmp));
}

}  // namespace
}  // namespace throng::io
