// Runs the real throng executable and checks its exit codes and output.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "io/crowd_gltf.h"

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
  for (const Case& c :
       {Case{"frobnicate", "unknown command 'frobnicate'"},
        Case{"--backend gpu info", "--backend: gpu not in {auto,cpu,cuda}"},
        Case{"--threads -3 info", "--threads: must be at least 0, got -3"},
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

// --- Machine output and command-line papercuts -------------------------------

namespace {

struct Streams {
  int code;
  std::string out;  // stdout alone
  std::string err;  // stderr alone
};

// Runs throng with stdout and stderr kept apart (stderr through a file).
Streams run_split(const std::string& args) {
  char err_path[] = "/tmp/throng_cli_stderr_XXXXXX";
  const int fd = mkstemp(err_path);
  if (fd < 0) return {-1, "", "mkstemp failed"};
  close(fd);
  const std::string cmd = std::string(THRONG_EXE) + " " + args + " 2>" + err_path;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return {-1, "", "popen failed"};
  std::string out;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  const int status = pclose(p);
  std::ifstream in(err_path, std::ios::binary);
  const std::string err((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(err_path);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out, err};
}

// Whether this build has the renderer (`throng view` has options then).
bool has_renderer() { return run_split("view --help").out.find("--headless") != std::string::npos; }

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace

TEST(Cli, LogsGoToStderrNotStdout) {
  // export-default logs a line per clip at info level and prints nothing else.
  const auto dir = fresh_dir("throng_cli_logs_stderr");
  const Streams r = run_split("export-default " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("[info] wrote "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("motions.json"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

// `throng route`: one line per sampled agent on stdout, the file in the
// folder asked for (GeoJSON by default, CSV on request), logs on stderr.
TEST(Cli, RoutePrintsAndWritesTheSampledRoutes) {
  const auto dir = fresh_dir("throng_cli_route");
  Streams r = run_split("route maze --agents 30 --sample 4 --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::size_t lines = 0;
  for (std::size_t at = 0; (at = r.out.find("agent ", at)) != std::string::npos; ++at) ++lines;
  EXPECT_EQ(lines, 4u) << r.out;
  EXPECT_NE(r.err.find("routes.geojson"), std::string::npos) << r.err;
  std::ifstream in(dir / "routes.geojson");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["features"].size(), 4u);
  r = run_split("route maze --agents 30 --sample 2 --format csv --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "routes.csv"));
  EXPECT_NE(run_split("route maze --sample 0").code, 0);
  EXPECT_NE(run_split("route maze --format kml").code, 0);
  std::filesystem::remove_all(dir);
}

TEST(Cli, InfoJsonStdoutIsOnlyJson) {
  // Default log level: whatever info logs (e.g. "no usable GPU") stays off stdout.
  Streams r = run_split("info --json");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j;
  ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << "stdout:\n" << r.out;
  EXPECT_TRUE(j.contains("version"));
  EXPECT_EQ(r.err.find("{"), std::string::npos) << r.err;

  const auto dir = fresh_dir("throng_cli_info_json_file");
  ASSERT_EQ(run_split("export-default " + dir.string()).code, 0);
  r = run_split("info --json " + (dir / "walk.bvh").string());
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << "stdout:\n" << r.out;
  EXPECT_GT(j["frames"].get<int>(), 0);
  std::filesystem::remove_all(dir);
}

TEST(Cli, GlobalOptionsBeforeOrAfterTheCommand) {
  // The same value either side of the command's name.
  for (const char* args : {"--threads 3 info --json", "info --threads 3 --json", "info --json --threads 3"}) {
    const Streams r = run_split(args);
    ASSERT_EQ(r.code, 0) << args << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["threads"], 3) << args;
  }
  for (const char* args : {"--backend cpu info --json", "info --json --backend cpu"}) {
    const Streams r = run_split(args);
    ASSERT_EQ(r.code, 0) << args << ": " << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["backend"], "cpu") << args;
  }
  // --log-level after the command silences the export's info lines.
  const auto dir = fresh_dir("throng_cli_log_level_after");
  Streams r = run_split("export-default " + dir.string() + " --log-level warn");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  // Bad values are refused in either position, with the same message.
  r = run_split("info --threads -3");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "throng: error: --threads: must be at least 0, got -3 (see --help)\n");
  r = run_split("--threads -3 info");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "throng: error: --threads: must be at least 0, got -3 (see --help)\n");
  std::filesystem::remove_all(dir);
}

TEST(Cli, RunWithThreadsAfterTheScenario) {
  const auto dir = fresh_dir("throng_cli_run_threads_after");
  const Streams r = run_split(
      "run circle --threads 1 --agents 100 --seconds 5 --backend cpu --quiet --no-trajectories --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("circle: 100 agents, 50 steps (5.0 s simulated)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(", cpu x1\n"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "stats.json"));
  std::filesystem::remove_all(dir);
}

TEST(Cli, VersionFlagPrintsTheVersion) {
  const Streams flag = run_split("--version");
  const Streams command = run_split("version");
  EXPECT_EQ(flag.code, 0) << flag.err;
  EXPECT_EQ(command.code, 0) << command.err;
  EXPECT_EQ(flag.out.rfind("throng ", 0), 0u) << flag.out;
  EXPECT_EQ(flag.out, command.out);
  EXPECT_EQ(flag.err, "");
}

TEST(Cli, UnknownCommandSuggestsTheClosest) {
  Streams r = run_split("rnu");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(
      r.err.rfind(
          "throng: error: unknown command 'rnu' (did you mean 'run'?); the commands are run, animate, bench, info, ",
          0),
      0u)
      << r.err;
  for (const char* name : {"convert", "export-default", "match", "view", "version"})
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  // An option's value is not taken for the command.
  r = run_split("--threads 2 inf");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("throng: error: unknown command 'inf' (did you mean 'info'?); the commands are ", 0), 0u)
      << r.err;
  // Nothing close: no suggestion.
  r = run_split("bogus");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("throng: error: unknown command 'bogus'; the commands are run, ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
}

TEST(Cli, RangeErrorsNameTheFlagInPlainNumbers) {
  struct Case {
    const char* args;
    const char* message;
  };
  const Case cases[] = {
      {"run --agents 0", "--agents: must be at least 1, got 0"},
      {"run --steps 0", "--steps: must be at least 1, got 0"},
      {"run --seconds 0", "--seconds: must be greater than 0, got 0"},
      {"run --every -2", "--every: must be at least 1, got -2"},
      {"run --width 8", "--width: must be between 16 and 7680, got 8"},
      {"run --fps 300", "--fps: must be between 1 and 240, got 300"},
      {"run --render-speed 0", "--render-speed: must be between 0.01 and 1000, got 0"},
      {"run --camera-period -1", "--camera-period: must be greater than 0, got -1"},
      {"animate --characters 0", "--characters: must be between 1 and 10000000, got 0"},
      {"animate --duration 0", "--duration: must be greater than 0, got 0"},
      {"bench --thread-counts 2,0", "--thread-counts: must be at least 1, got 0"},
      {"run --agents many", "--agents: expected a number, got 'many'"},
  };
  for (const Case& c : cases) {
    const Streams r = run_split(c.args);
    EXPECT_EQ(r.code, 2) << c.args;
    EXPECT_EQ(r.err, std::string("throng: error: ") + c.message + " (see --help)\n") << c.args;
  }
  if (has_renderer()) {
    const Streams r = run_split("view --agents 0");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, "throng: error: --agents: must be between 1 and 16777216, got 0 (see --help)\n");
    const Streams w = run_split("view --width 100000");
    EXPECT_EQ(w.code, 2);
    EXPECT_EQ(w.err, "throng: error: --width: must be between 16 and 7680, got 100000 (see --help)\n");
  }
  // Joint-LOD thresholds mean nothing without joint LOD: refused, not ignored.
  const Streams l = run_split("run circle --no-lod --lod-thresholds 900,20");
  EXPECT_NE(l.code, 0);
  EXPECT_EQ(l.err, "throng: error: --lod-thresholds: needs joint LOD (it has no effect with --no-lod)\n");
}

TEST(Cli, RenderOptionsNeedRender) {
  for (const char* option : {"--render-mode joints", "--width 320", "--height 200", "--fps 12", "--render-speed 2",
                             "--render-seconds 1", "--camera orbit", "--camera-period 10"}) {
    const std::string flag = std::string(option).substr(0, std::string(option).find(' '));
    const Streams r = run_split(std::string("run circle --seconds 1 --quiet ") + option);
    EXPECT_EQ(r.code, 1) << option;
    EXPECT_EQ(r.err, "throng: error: " + flag + ": needs --render video|frames\n") << option;
  }
  // The demo renders unless told not to.
  Streams r = run_split("run --no-render --camera follow");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "throng: error: --camera: needs --render video|frames\n");
  if (!has_renderer()) return;
  r = run_split("view --camera orbit --frames 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "throng: error: --camera: needs --headless (with --render video|frames or --screenshot)\n");
  r = run_split("view --fps 10 --frames 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "throng: error: --fps: needs --headless (with --render video|frames or --screenshot)\n");
  r = run_split("view --headless --frames 1 --screenshot x.png --out somewhere");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "throng: error: --out: needs --render video|frames\n");
}

TEST(Cli, LodThresholdErrorsNameTheFlag) {
  const std::string sixteen = "--lod-thresholds 16,15,14,13,12,11,10,9,8,7,6,5,4,3,2,1";
  struct Case {
    std::string args;
    const char* message;
  };
  const Case cases[] = {
      {"--lod-thresholds 30,1000",
       "--lod-thresholds: thresholds must decrease (finest level first, e.g. 1000,30), got 1000 after 30"},
      {"--lod-thresholds 1000,0", "--lod-thresholds: thresholds must be positive square pixels, got 0"},
      {sixteen, "--lod-thresholds: at most 15 thresholds, got 16"},
  };
  for (const Case& c : cases) {
    Streams r = run_split("run circle --agents 50 --seconds 1 --quiet --no-trajectories " + c.args);
    EXPECT_EQ(r.code, 1) << c.args;
    EXPECT_EQ(r.err, std::string("throng: error: ") + c.message + "\n") << c.args;
    if (has_renderer()) {
      r = run_split("view --frames 1 " + c.args);
      EXPECT_EQ(r.code, 1) << c.args;
      EXPECT_EQ(r.err, std::string("throng: error: ") + c.message + "\n") << c.args;
    }
  }
}

TEST(Cli, TrajectoryFormatErrorsNameTheFlagOrTheKey) {
  Streams r = run_split("run circle --agents 5 --steps 1 --quiet --trajectory-format parquet");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err,
            "throng: error: --trajectory-format: unknown trajectory format 'parquet': expected csv, pedpy or sqlite\n");
  r = run_split("run circle --agents 5 --steps 1 --quiet --trajectory-format PedPy");
  EXPECT_EQ(r.err,
            "throng: error: --trajectory-format: unknown trajectory format 'PedPy': expected csv, pedpy or sqlite (did "
            "you mean 'pedpy'?)\n");
  const std::filesystem::path yaml = std::filesystem::temp_directory_path() / "throng_cli_bad_format.yaml";
  std::ofstream(yaml)
      << "groups:\n  - count: 2\n    spawn: {rect: {min: [0, 0], max: [2, 2]}}\n    goal: {point: [5, 1]}\n"
         "outputs:\n  trajectories: {format: hdf5}\n";
  r = run_split("run " + yaml.string() + " --quiet");
  EXPECT_EQ(r.code, 1);
  // The last line (the backend's note comes first: the scenario is read after it).
  EXPECT_TRUE(r.err.ends_with(
      "\nthrong: error: " + yaml.string() +
      ":6:26: outputs.trajectories.format: unknown trajectory format 'hdf5': expected csv, pedpy or sqlite\n"))
      << r.err;
  std::filesystem::remove(yaml);
}

TEST(Cli, ConvertChoosesTheWriterByExtension) {
  const auto dir = fresh_dir("throng_cli_convert_ext");
  ASSERT_EQ(run_split("--log-level warn export-default " + dir.string()).code, 0);
  const std::string in = (dir / "walk.bvh").string();
  Streams r = run_split("convert " + in + " " + (dir / "out.gltf").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err,
            "throng: error: " + (dir / "out.gltf").string() + ": unknown output extension '.gltf' (supported: .bvh)\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.gltf"));
  r = run_split("convert " + in + " " + (dir / "out").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "throng: error: " + (dir / "out").string() +
                       ": no extension to choose the output format by (supported: .bvh)\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  // The extension in any case.
  r = run_split("--log-level warn convert " + in + " " + (dir / "out.BVH").string());
  EXPECT_EQ(r.code, 0) << r.err;
  std::ifstream written(dir / "out.BVH");
  std::string first;
  std::getline(written, first);
  EXPECT_EQ(first, "HIERARCHY");
  std::filesystem::remove_all(dir);
}

// The acceptance size: 200 agents of the circle for 20 s at 24 fps is one
// .glb under 50 MB that parses back with every agent and frame; bad
// requests are refused before any work, naming the flag.
TEST(Cli, ExportCrowdWritesABoundedGlbThatParsesBack) {
  const auto dir = fresh_dir("throng_cli_export_crowd");
  const std::string glb = (dir / "crowd.glb").string();
  const Streams r = run_split("--log-level warn export-crowd circle --agents 200 --seconds 20 --out " + glb);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + glb + ": 200 agents x 22 joints, 481 frames at 24 fps"), std::string::npos) << r.out;
  const auto bytes = std::filesystem::file_size(glb);
  std::printf("  %s: %.1f MB\n", glb.c_str(), static_cast<double>(bytes) / 1e6);
  EXPECT_LT(bytes, 50u * 1000u * 1000u);
  const throng::io::CrowdGlb back(glb);
  EXPECT_EQ(back.agents(), 200);
  EXPECT_EQ(back.frames(), 481);
  EXPECT_DOUBLE_EQ(back.fps(), 24.0);

  Streams bad = run_split("export-crowd circle --agents 200 --seconds 20 --max-size 1 --out " + glb + ".x.glb");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("--max-size"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(glb + ".x.glb"));
  bad = run_split("export-crowd circle --out " + (dir / "crowd.gltf").string());
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("--out"), std::string::npos) << bad.err;
  bad = run_split("export-crowd " + dir.string());
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("is a folder"), std::string::npos) << bad.err;
  std::filesystem::remove_all(dir);
}
