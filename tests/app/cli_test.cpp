// Runs the real throng executable and checks its exit codes and output.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>

namespace {

struct Result {
  int code;
  std::string out;  // stdout and stderr together
};

Result run(const std::string& args) {
  const std::string cmd = std::string(THRONG_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace

TEST(Cli, VersionAndHelp) {
  auto r = run("version");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out.rfind("throng ", 0), 0u) << r.out;
  for (const char* sub : {"run", "bench", "info", "version"}) {
    r = run(std::string(sub) + " --help");
    EXPECT_EQ(r.code, 0) << sub;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << sub << ": " << r.out;
  }
}

// A command line CLI11 rejects exits with 2 (src/app/main.cpp), naming the
// option or value; a crash (128 + signal, or -1 here) does not pass.
TEST(Cli, BadArgumentsGiveOneLineErrorAndNonZeroExit) {
  struct Case {
    const char* args;
    const char* names;
  };
  for (const Case& c : {Case{"frobnicate", "A subcommand is required"}, Case{"--backend gpu info", "--backend: gpu not in {auto,cpu,cuda}"},
                        Case{"--threads -3 info", "--threads: Value -3 not in range"},
                        Case{"bench --no-such-flag", "not expected: --no-such-flag"}, Case{"", "A subcommand is required"}}) {
    const auto r = run(c.args);
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_EQ(r.code, 2) << "'" << c.args << "' printed:\n" << r.out;
    EXPECT_EQ(lines(r.out), 1u) << "'" << c.args << "' printed:\n" << r.out;
    EXPECT_NE(r.out.find("error"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.rfind("throng: error: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find(c.names), std::string::npos) << "'" << c.args << "' printed:\n" << r.out;
  }
}

TEST(Cli, InfoJson) {
  const auto r = run("--backend cpu --log-level off info --json");
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["backend"], "cpu");
  EXPECT_GE(j["hardware_threads"].get<int>(), 1);
}

TEST(Cli, BenchQuickWritesJsonRows) {
  const auto path = std::filesystem::temp_directory_path() / "throng_cli_bench.json";
  const auto r = run("--backend cpu bench --quick --filter 'core/saxpy/cpu/n=1000/' --json " + path.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(path);
  const auto j = nlohmann::json::parse(in);
  ASSERT_TRUE(j["benchmarks"].is_array());
  ASSERT_GE(j["benchmarks"].size(), 1u);
  for (const auto& row : j["benchmarks"]) {
    EXPECT_EQ(row["name"], "core/saxpy");
    EXPECT_EQ(row["N"], 1000);
    EXPECT_GE(row["threads"].get<int>(), 1);
    EXPECT_GT(row["median_ns"].get<double>(), 0);
    EXPECT_GT(row["items_per_second"].get<double>(), 0);
  }
  std::filesystem::remove(path);
}

TEST(Cli, AnimateWritesStatsJson) {
  const auto dir = std::filesystem::temp_directory_path() / "throng_cli_animate";
  std::filesystem::remove_all(dir);
  const Result r = run("--threads 2 animate formation --duration 0.5 --characters 300 --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("foot skating"), std::string::npos) << r.out;
  std::ifstream in(dir / "stats.json");
  ASSERT_TRUE(in) << r.out;
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["characters"], 300);
  EXPECT_EQ(j["frames"], 30);
  for (const char* key : {"mean", "p95"}) EXPECT_TRUE(j["foot_skating_cm"][key].is_number()) << key;
  EXPECT_GT(j["foot_skating_cm"]["contacts"].get<int>(), 0);
  EXPECT_LT(j["formation"]["max_drift_from_ring_m"].get<double>(), 0.01);
  EXPECT_GT(j["cache"]["hits"].get<long long>() + j["cache"]["misses"].get<long long>(), 0);
  EXPECT_TRUE(j["lod"]["joints_synthesised_histogram"].is_array());
  bool pose_timed = false;
  for (const auto& t : j["timings"]) pose_timed = pose_timed || t["name"] == "anim.pose";
  EXPECT_TRUE(pose_timed);
  std::filesystem::remove_all(dir);
}

TEST(Cli, AnimateRejectsUnknownScenarios) {
  const Result r = run("animate no_such_scenario");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.code, 1) << r.out;  // throng::Error
  EXPECT_NE(r.out.find("no such file or built-in scenario 'no_such_scenario'"), std::string::npos) << r.out;
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_NE(r.out.find("throng: error:"), std::string::npos) << r.out;
}
