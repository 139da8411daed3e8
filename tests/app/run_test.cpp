// `throng run` end to end: the real executable writes valid trajectories.csv
// and stats.json, prints a summary, reports bad scenarios on one line, and
// leaves complete files when interrupted with Ctrl-C (SIGINT).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/render/video_probe.h"
#include "tests/shared_data.h"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code = -1;  // exit status, or 128 + signal
  std::string out;
};

// Starts `throng args...` with stdout and stderr into `log`, leading a new
// process group (pgid = pid); returns the pid.
// file_size_limit > 0: no file of the run may grow past it (RLIMIT_FSIZE,
// inherited by the encoder), a full disk as far as the writers can tell.
pid_t start(const std::vector<std::string>& args, const fs::path& log, rlim_t file_size_limit = 0) {
  const pid_t pid = fork();
  if (pid == 0) {
    // A process group of its own, as a shell gives a foreground job: a
    // test can signal the whole group the way a terminal's Ctrl-C does.
    setpgid(0, 0);
    if (file_size_limit > 0) {
      signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead of killing
      const rlimit limit{file_size_limit, file_size_limit};
      setrlimit(RLIMIT_FSIZE, &limit);
    }
    std::FILE* f = std::fopen(log.c_str(), "w");
    if (f != nullptr) {
      dup2(fileno(f), STDOUT_FILENO);
      dup2(fileno(f), STDERR_FILENO);
    }
    std::vector<char*> argv{const_cast<char*>(THRONG_EXE)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(THRONG_EXE, argv.data());
    _exit(127);
  }
  return pid;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Outcome finish(pid_t pid, const fs::path& log) {
  int status = 0;
  waitpid(pid, &status, 0);
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  o.out = slurp(log);
  return o;
}

class RunCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("throng_run_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Outcome run(std::vector<std::string> args) { return finish(start(args, dir_ / "log.txt"), dir_ / "log.txt"); }
  fs::path dir_;
};

bool sanitized() {
  const char* v = std::getenv("THRONG_SANITIZED");
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string part;
  while (std::getline(ss, part, sep)) out.push_back(part);
  return out;
}

// Parses trajectories.csv: rows per frame, checking every field.
std::map<long, int> read_trajectories(const fs::path& csv, long agents) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "frame,time,agent,x,y,heading,speed");
  std::map<long, int> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = split(line, ',');
    EXPECT_EQ(f.size(), 7u) << line;
    if (f.size() != 7) break;
    std::size_t used = 0;
    const long frame = std::stol(f[0], &used);
    EXPECT_EQ(used, f[0].size());
    EXPECT_NEAR(std::stod(f[1]), 0.1 * static_cast<double>(frame), 1e-6) << line;
    const long agent = std::stol(f[2]);
    EXPECT_TRUE(agent >= 0 && agent < agents) << line;
    for (int k = 3; k < 7; ++k) EXPECT_TRUE(std::isfinite(std::stod(f[static_cast<std::size_t>(k)]))) << line;
    EXPECT_LE(std::stod(f[6]), 2.0) << line;  // speed within the model's maximum
    ++rows[frame];
  }
  return rows;
}

TEST_F(RunCommand, WritesValidTrajectoriesAndStatsAndPrintsASummary) {
  const Outcome o = run({"--threads", "2", "run", "circle", "--agents", "50", "--steps", "120", "--every", "10",
                         "--out", dir_.string(), "--quiet"});
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("circle: 50 agents, 120 steps"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("collision_free_speed model, double_buffer"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("arrived"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("obstacle penetrations 0"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("stuck agents (at rest over 5 s with the way ahead free): 0"), std::string::npos) << o.out;

  const std::map<long, int> rows = read_trajectories(dir_ / "trajectories.csv", 50);
  std::map<long, int> want;
  for (long f = 0; f <= 120; f += 10) want[f] = 50;  // agents stop at their goals and stay
  EXPECT_EQ(rows, want);

  const nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "stats.json"));
  for (const char* section : {"run", "timings", "crowd", "stuck_agents", "density_histogram", "fundamental_diagram",
                              "trajectories", "scenario"})
    EXPECT_TRUE(stats.contains(section)) << section;
  EXPECT_EQ(stats["run"]["steps"], 120);
  EXPECT_EQ(stats["run"]["agents"], 50);
  EXPECT_EQ(stats["run"]["threads"], 2);
  EXPECT_EQ(stats["run"]["model"], "collision_free_speed");  // the built-in circle keeps the default model
  EXPECT_FALSE(stats["run"]["interrupted"].get<bool>());
  EXPECT_EQ(stats["crowd"]["agents"], 50);
  EXPECT_EQ(stats["crowd"]["obstacle_penetrations"]["max"], 0);
  const nlohmann::json& stuck = stats["stuck_agents"];
  EXPECT_EQ(stuck["threshold_s"], 5.0);
  EXPECT_EQ(stuck["speed_below"], 0.1);
  EXPECT_EQ(stuck["agents"], 0);
  EXPECT_EQ(stuck["max_at_once"], 0);
  EXPECT_TRUE(stuck["first_time_s"].is_null());
  EXPECT_TRUE(stuck["examples"].is_array() && stuck["examples"].empty());
  EXPECT_EQ(stats["trajectories"]["rows"], 13 * 50);
  for (const char* stage : {"sim.bin", "sim.sense", "sim.steer", "sim.move", "emit.trajectories", "sim.metrics"})
    EXPECT_TRUE(stats["timings"]["stages"].contains(stage)) << stage;
  EXPECT_GT(stats["timings"]["step_ms"].get<double>(), 0.0);
  // The kernels' estimate of the memory a step moves: every agent's
  // position is copied once a step (two arrays of 8 bytes), and more.
  const auto agents = stats["crowd"]["agents"].get<double>();
  EXPECT_GT(stats["timings"]["step_bytes"].get<double>(), 16.0 * agents);
  EXPECT_GT(stats["timings"]["stages"]["sim.sense"]["bytes_per_step"].get<double>(), 0.0);
  EXPECT_EQ(stats["scenario"]["source"], "builtin:circle");
}

// The README's demo: `throng run` with no scenario runs the circle to the
// end and prints its summary (with fewer agents under the sanitizers).
TEST_F(RunCommand, TheDefaultDemoRunsTheCircleToTheEnd) {
  std::vector<std::string> args = {"run", "--out", dir_.string()};
  if (sanitized()) args.insert(args.end(), {"--agents", "200"});
  const Outcome o = run(args);
  ASSERT_EQ(o.code, 0) << o.out;
  const std::string n = sanitized() ? "200" : "1000";
  EXPECT_NE(o.out.find("circle: " + n + " agents"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("arrived " + n + "/" + n), std::string::npos) << o.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "stats.json"));
  EXPECT_TRUE(stats["run"]["all_arrived"].get<bool>());
  EXPECT_TRUE(stats.contains("locomotion"));
  const fs::path video = dir_ / "crowd.mp4";
#if defined(THRONG_HAVE_RENDER)
  // A build with the renderer writes the demo's video and says where: as
  // many frames as it says it drew, and as the run's length gives at the
  // rate it announced, each decodable.
  EXPECT_NE(o.out.find("rendering video"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(video.string()), std::string::npos) << o.out;
  ASSERT_TRUE(fs::exists(video)) << o.out;
  EXPECT_GT(fs::file_size(video), 1000u);
  // "throng run: rendering video (skinned, 640x360, 24 fps, 50x speed) into DIR"
  char mode[32] = {};
  int width = 0, height = 0;
  double fps = 0, speed = 0;
  const auto announced = o.out.find("throng run: rendering video (");
  ASSERT_NE(announced, std::string::npos) << o.out;
  ASSERT_EQ(std::sscanf(o.out.c_str() + announced, "throng run: rendering video (%31[^,], %dx%d, %lf fps, %lfx speed)",
                        mode, &width, &height, &fps, &speed),
            5)
      << o.out;
  // "DIR/crowd.mp4 (N frames, 640x360 at 24 fps)" in the summary.
  long said = -1;
  const auto wrote = o.out.find(video.string() + " (");
  ASSERT_NE(wrote, std::string::npos) << o.out;
  ASSERT_EQ(std::sscanf(o.out.c_str() + wrote + video.string().size(), " (%ld frames", &said), 1) << o.out;
  // A video frame every `per_video`-th animation frame, the first included.
  const nlohmann::json& l = stats["locomotion"];
  const long per_video = std::lround(l["fps"].get<double>() * speed / fps);
  ASSERT_GE(per_video, 1);
  const long expected = (l["frames"].get<long>() - 1) / per_video + 1;
  EXPECT_EQ(said, expected) << o.out;
  const throng::testing::VideoProbe p = throng::testing::probe_video(video.string());
  EXPECT_EQ(p.codec, "h264") << p;
  EXPECT_EQ(p.width, width) << p;
  EXPECT_EQ(p.height, height) << p;
  EXPECT_GT(p.frames, 0) << p;
  EXPECT_EQ(p.frames, expected) << p;
  EXPECT_NEAR(p.duration, static_cast<double>(expected) / fps, 1.5 / fps) << p;
  // The first and the last frame are pictures of the scene, not a cleared
  // (or black) frame buffer.
  for (const long frame : {0L, expected - 1}) {
    const std::vector<std::uint8_t> rgb = throng::testing::decode_frame_rgb(video.string(), frame);
    EXPECT_EQ(rgb.size(), 3u * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) << "frame " << frame;
    EXPECT_GT(throng::testing::distinct_colours_rgb(rgb), 200u) << "frame " << frame;
  }
#else
  EXPECT_FALSE(fs::exists(video)) << o.out;
#endif
}

// The locomotion stage: every agent animated from its simulated velocity and
// heading; stats.json's "locomotion" section holds the stage's timings, the
// joint-LOD histogram, the cache counters and foot skating, measured only
// where the feet are synthesised: none under the overview camera's joint
// LOD, every sampled agent with --no-lod, the feet locked (well under 1 cm
// per contact on the circle); the same on 1 and 2 threads.
TEST_F(RunCommand, AnimatesEveryAgentWithPlantedFeetAndTheSameOnAnyThreadCount) {
  const std::string agents = sanitized() ? "120" : "400";
  const auto run_with = [&](const std::string& threads) {
    const fs::path out = dir_ / ("threads_" + threads);
    const Outcome o = run({"--threads", threads, "run", "circle", "--agents", agents, "--seconds", "12",
                           "--no-trajectories", "--out", out.string()});
    EXPECT_EQ(o.code, 0) << o.out;
    // Seen by the overview camera, characters are too small for joint LOD to synthesise their legs.
    EXPECT_NE(o.out.find("foot skating: no contacts measured (" + agents + " agents sampled"), std::string::npos)
        << o.out;
    return nlohmann::json::parse(slurp(out / "stats.json"));
  };
  const nlohmann::json one = run_with("1");
  ASSERT_TRUE(one.contains("locomotion")) << one.dump(1);
  const nlohmann::json& l = one["locomotion"];
  EXPECT_EQ(l["characters"].get<long>(), std::stol(agents));
  EXPECT_EQ(l["frames"].get<long>(), 121);  // the initial state and 120 steps
  EXPECT_GT(l["frame_ms"]["median"].get<double>(), 0.0);
  EXPECT_TRUE(l["kernels"].contains("anim.locomote") || l["kernels"].contains("anim.from_map")) << l["kernels"].dump();
  EXPECT_TRUE(l["kernels"].contains("anim.pose")) << l["kernels"].dump();
  // Joint-LOD histogram: characters per count of joints synthesised, summing to agents x frames.
  long histogram = 0;
  for (const auto& c : l["lod"]["joints_synthesised_histogram"]) histogram += c.get<long>();
  EXPECT_EQ(histogram, 121 * std::stol(agents));
  for (const char* key : {"hits", "misses", "evictions", "bytes"}) EXPECT_TRUE(l["cache"].contains(key)) << key;
  EXPECT_GT(l["cache"]["hits"].get<long>() + l["cache"]["misses"].get<long>(), 0);
  const auto& skate = l["foot_skating_cm"];
  EXPECT_EQ(skate["contacts"].get<int>(), 0) << skate.dump();
  EXPECT_EQ(skate["agents_measured"].get<int>(), 0) << skate.dump();
  EXPECT_TRUE(skate["mean"].is_null()) << skate.dump();
  EXPECT_TRUE(one["timings"]["stages"].contains("anim.locomotion"));

  // Every joint synthesised (no LOD): the feet that skate are all measured.
  const Outcome full = run({"run", "circle", "--agents", agents, "--seconds", "12", "--no-lod", "--no-trajectories",
                            "--out", (dir_ / "full").string()});
  ASSERT_EQ(full.code, 0) << full.out;
  const nlohmann::json all = nlohmann::json::parse(slurp(dir_ / "full" / "stats.json"))["locomotion"];
  EXPECT_EQ(all["joints_synthesised_per_character"].get<double>(), all["joints"].get<double>());
  const auto& feet = all["foot_skating_cm"];
  EXPECT_GT(feet["contacts"].get<int>(), 50) << feet.dump();
  EXPECT_EQ(feet["agents_measured"].get<long>(), std::stol(agents)) << feet.dump();  // every agent
  EXPECT_LT(feet["mean"].get<double>(), 0.5) << feet.dump();
  EXPECT_LT(feet["p95"].get<double>(), 1.5) << feet.dump();
  EXPECT_NE(full.out.find("foot skating: mean"), std::string::npos) << full.out;

  const nlohmann::json two = run_with("2");
  for (const char* key : {"lod", "cache", "foot_skating_cm", "joints_synthesised_per_character"})
    EXPECT_EQ(one["locomotion"][key], two["locomotion"][key]) << key;
}

// A scenario's own motion set: CMU subject 16's walk and jog (43 joints,
// real motion capture) animate every agent, and stats.json has their foot
// skating; a clip that is not there is an error naming it.
TEST_F(RunCommand, AScenarioAnimatesItsOwnMotionCaptureClips) {
  THRONG_NEED_SHARED_BVH(bvh);
  const fs::path scenario = dir_ / "cmu.yaml";
  std::ofstream(scenario) << "name: cmu\nduration: 40\ngroups:\n"
                             "  - {count: 100, radius: 0.25, spawn: {ring: {center: [0, 0], spacing: 1.0}},\n"
                             "     goal: {mirror: [0, 0]}, on_arrival: stop}\n"
                             "motion:\n  clips:\n"
                          << "    - {file: " << (*bvh / "cmu_16_15_walk_daz.bvh").string() << ", name: walk}\n"
                          << "    - {file: " << (*bvh / "cmu_16_36_run_jog_daz.bvh").string() << ", name: jog}\n"
                          << "  up_axis: auto\n  units: auto\n";
  const Outcome o = run({"run", scenario.string(), "--no-lod", "--no-trajectories", "--out", (dir_ / "out").string()});
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("walk: cycle of"), std::string::npos) << o.out;
  const nlohmann::json l = nlohmann::json::parse(slurp(dir_ / "out" / "stats.json"))["locomotion"];
  EXPECT_EQ(l["joints"].get<int>(), 43) << l.dump(1);
  const auto& feet = l["foot_skating_cm"];
  std::printf("CMU walk + jog: %s\n", feet.dump().c_str());
  EXPECT_GT(feet["contacts"].get<int>(), 100) << feet.dump();
  EXPECT_EQ(feet["agents_measured"].get<int>(), 100) << feet.dump();  // every agent
  // Under the collision-free speed model: mean 0.57 cm, p95 3.17 cm (the
  // bound was 3 cm while the priority model was the default).
  EXPECT_LT(feet["mean"].get<double>(), 1.0) << feet.dump();
  EXPECT_LT(feet["p95"].get<double>(), 4.0) << feet.dump();

  std::ofstream(dir_ / "missing.yaml") << "groups:\n  - {count: 2, spawn: {ring: {center: [0, 0], spacing: 1.0}}, "
                                          "goal: {mirror: [0, 0]}}\nmotion: [no_such_walk.bvh]\n";
  const Outcome missing = run({"run", (dir_ / "missing.yaml").string(), "--out", (dir_ / "m").string()});
  EXPECT_EQ(missing.code, 1) << missing.out;
  EXPECT_NE(missing.out.find("no_such_walk.bvh"), std::string::npos) << missing.out;
}

// Locomotion through streams (--animation streams): far agents read shared
// speed-bucket streams; stats.json says so, with the error of sharing
// against exact synthesis and the streamed feet's skating; a video draws
// them. Streams cannot give every joint (--no-lod) nor joints to draw.
TEST_F(RunCommand, AnimatesThroughStreamsWhenAsked) {
  const fs::path out = dir_ / "streams";
  const Outcome o = run({"run", "circle", "--agents", "300", "--seconds", "12", "--animation", "streams",
                         "--no-trajectories", "--out", out.string()});
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("locomotion (streams)"), std::string::npos) << o.out;
  const nlohmann::json l = nlohmann::json::parse(slurp(out / "stats.json"))["locomotion"];
  EXPECT_EQ(l["path"], "streams");
  EXPECT_EQ(l["frames"].get<long>(), 121);
  EXPECT_TRUE(l["kernels"].contains("anim.loco_streams_refs")) << l["kernels"].dump();
  EXPECT_FALSE(l["kernels"].contains("anim.stream_resolve")) << "no palette per streamed agent";
  const auto& st = l["streams"];
  std::printf("streams: %s\nfeet: %s\n", st.dump().c_str(), l["foot_skating_cm"].dump().c_str());
  EXPECT_GT(st["streams_in_use"].get<int>(), 0);
  const auto& e = st["sharing_error_cm"];
  EXPECT_GT(e["agents"].get<long>(), 0);
  EXPECT_LT(e["p95"].get<double>(), 3.0) << e.dump();
  // Streamed feet are measured from the streams' palettes under any camera.
  const auto& feet = l["foot_skating_cm"];
  EXPECT_GT(feet["contacts"].get<int>(), 50) << feet.dump();
  EXPECT_LT(feet["mean"].get<double>(), 2.0) << feet.dump();

  const Outcome exact = run({"run", "circle", "--agents", "300", "--seconds", "1", "--animation", "exact",
                             "--no-trajectories", "--out", (dir_ / "exact").string()});
  ASSERT_EQ(exact.code, 0) << exact.out;
  EXPECT_EQ(nlohmann::json::parse(slurp(dir_ / "exact" / "stats.json"))["locomotion"]["path"], "exact");

  const Outcome no_lod =
      run({"run", "circle", "--animation", "streams", "--no-lod", "--no-render", "--out", (dir_ / "x").string()});
  EXPECT_EQ(no_lod.code, 1) << no_lod.out;
  EXPECT_NE(no_lod.out.find("--no-lod needs --animation exact"), std::string::npos) << no_lod.out;
  const Outcome unanimated =
      run({"run", "circle", "--animation", "streams", "--no-animate", "--out", (dir_ / "y").string()});
  EXPECT_EQ(unanimated.code, 1) << unanimated.out;
  EXPECT_NE(unanimated.out.find("--animation"), std::string::npos) << unanimated.out;
#if defined(THRONG_HAVE_RENDER)
  const Outcome video =
      run({"--threads", "2", "run", "circle", "--agents", "300", "--seconds", "3", "--animation", "streams", "--render",
           "frames", "--width", "320", "--height", "180", "--no-trajectories", "--out", (dir_ / "frames").string()});
  ASSERT_EQ(video.code, 0) << video.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "frames" / "stats.json"));
  EXPECT_GT(stats["render"]["frames"].get<long>(), 10);
  EXPECT_GE(stats["render"]["median_character_px"].get<double>(), 30.0) << stats["render"];
  const Outcome joints = run({"run", "circle", "--animation", "streams", "--render", "frames", "--render-mode",
                              "joints", "--out", (dir_ / "z").string()});
  EXPECT_EQ(joints.code, 1) << joints.out;
  EXPECT_NE(joints.out.find("--render-mode joints needs --animation exact"), std::string::npos) << joints.out;
#endif
}

TEST_F(RunCommand, NoAnimateSkipsTheLocomotionStage) {
  const Outcome o = run({"run", "circle", "--agents", "50", "--seconds", "1", "--no-animate", "--out", dir_.string()});
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_FALSE(nlohmann::json::parse(slurp(dir_ / "stats.json")).contains("locomotion"));
  const Outcome both = run({"run", "circle", "--no-animate", "--render", "video", "--out", dir_.string()});
  EXPECT_EQ(both.code, 1) << both.out;
  EXPECT_NE(both.out.find("throng: error:"), std::string::npos) << both.out;
  EXPECT_NE(both.out.find("--render"), std::string::npos) << both.out;
  EXPECT_NE(both.out.find("--no-animate"), std::string::npos) << both.out;
}

TEST_F(RunCommand, CheckEveryWritesASoakReportAndSection) {
  const Outcome o = run({"run", "corridor", "--agents", "50", "--steps", "30", "--check-every", "10", "--no-animate",
                         "--no-trajectories", "--quiet", "--out", dir_.string()});
  ASSERT_EQ(o.code, 0) << o.out;
  EXPECT_NE(o.out.find("soak checks: 4, every 10 steps"), std::string::npos) << o.out;
  std::ifstream report(dir_ / "soak.jsonl");
  int lines = 0;
  for (std::string line; std::getline(report, line); ++lines)
    EXPECT_EQ(nlohmann::json::parse(line)["step"], 10 * lines);
  EXPECT_EQ(lines, 4);  // steps 0, 10, 20, 30
  const nlohmann::json soak = nlohmann::json::parse(slurp(dir_ / "stats.json"))["soak"];
  EXPECT_TRUE(soak["passed"]) << soak.dump();
  EXPECT_EQ(soak["steps"], 30);
  EXPECT_GT(soak["rss_mib"]["end"].get<double>(), 0.0);
}

TEST_F(RunCommand, ABadScenarioFileIsOneLineWithItsPosition) {
  const fs::path bad = dir_ / "bad.yaml";
  std::ofstream(bad)
      << "name: bad\ngroups:\n  - count: ten\n    spawn: {rect: {min: [0, 0], max: [5, 5]}}\n    goal: [9, 9]\n";
  const Outcome o = run({"--backend", "cpu", "run", bad.string(), "--out", dir_.string()});
  EXPECT_EQ(o.code, 1);
  EXPECT_EQ(o.out, "throng: error: " + bad.string() + ":3:12: groups[0].count: expected a number, got 'ten'\n");

  const fs::path blocked = dir_ / "blocked.yaml";
  std::ofstream(blocked) << "world:\n  obstacles:\n    - circle: {center: [9, 9], radius: 2}\ngroups:\n"
                            "  - count: 5\n    spawn: {rect: {min: [0, 0], max: [5, 5]}}\n    goal: [9, 9]\n";
  const Outcome g = run({"--backend", "cpu", "run", blocked.string(), "--out", dir_.string()});
  EXPECT_EQ(g.code, 1);
  EXPECT_NE(g.out.find(blocked.string() +
                       ":7:11: groups[0].goal: goal (9, 9) of agent 0 lies inside obstacle world.obstacles[0]"),
            std::string::npos)
      << g.out;
}

TEST_F(RunCommand, UnknownNamesAndBadOptionsAreErrors) {
  Outcome o = run({"run", "circel"});
  EXPECT_EQ(o.code, 1);
  EXPECT_NE(
      o.out.find("no built-in scenario 'circel' (built-ins: bottleneck, circle, corridor, crossing, maze, plaza)"),
      std::string::npos)
      << o.out;
  o = run({"run", dir_.string()});  // a folder is not a scenario
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find(dir_.string() + ": is a folder, not a scenario file"), std::string::npos) << o.out;
  // Command lines CLI11 rejects exit with 2 (src/app/main.cpp), naming the option.
  o = run({"run", "circle", "--steps", "5", "--seconds", "3"});
  EXPECT_NE(o.code, 0);
  EXPECT_NE(o.out.find("error"), std::string::npos);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--steps excludes --seconds"), std::string::npos) << o.out;
  o = run({"run", "circle", "--scheduler", "three_colour"});
  EXPECT_NE(o.code, 0);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--scheduler: three_colour not in"), std::string::npos) << o.out;
  o = run({"run", "circle", "--agents", "0"});
  EXPECT_NE(o.code, 0);
  EXPECT_EQ(o.code, 2) << o.out;
  EXPECT_NE(o.out.find("--agents: must be at least 1, got 0"), std::string::npos) << o.out;
}

// Ctrl-C: the run ends after the current frame, the CSV ends on a complete
// frame, stats.json is valid and says so, and the exit status is 130.
TEST_F(RunCommand, InterruptLeavesCompleteFiles) {
  const fs::path log = dir_ / "log.txt";
  const fs::path out = dir_ / "out";
  const pid_t pid = start(
      {"--threads", "1", "run", "circle", "--agents", "400", "--every", "1", "--out", out.string(), "--quiet"}, log);
  // Wait for a few frames to be written.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    if (fs::file_size(out / "trajectories.csv.partial", ec) > 3 * 400 * 30 && !ec) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(kill(pid, SIGINT), 0);
  const Outcome o = finish(pid, log);
  ASSERT_EQ(o.code, 130) << o.out;
  EXPECT_NE(o.out.find("(interrupted)"), std::string::npos) << o.out;
  const std::string csv = slurp(out / "trajectories.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  const std::map<long, int> rows = read_trajectories(out / "trajectories.csv", 400);
  ASSERT_GE(rows.size(), 3u);
  for (const auto& [frame, n] : rows) EXPECT_EQ(n, 400) << "frame " << frame;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out / "stats.json"));
  EXPECT_TRUE(stats["run"]["interrupted"].get<bool>());
  EXPECT_FALSE(stats["run"]["all_arrived"].get<bool>());
  EXPECT_EQ(stats["run"]["steps"].get<long>(), rows.rbegin()->first);
  EXPECT_FALSE(fs::exists(out / "stats.json.partial"));
}

// The same with the SQLite format: every frame is a transaction, so the
// database holds whole frames only, each listed in frame_data, and no
// journal is left behind.
TEST_F(RunCommand, InterruptLeavesAReadableSqliteDatabaseOfCompleteFrames) {
  const fs::path log = dir_ / "log.txt";
  const fs::path out = dir_ / "out";
  const pid_t pid = start({"--threads", "1", "run", "circle", "--agents", "400", "--every", "1", "--trajectory-format",
                           "sqlite", "--no-animate", "--out", out.string(), "--quiet"},
                          log);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    if (fs::file_size(out / "trajectories.sqlite.partial", ec) > 400 * 40 * 20 && !ec) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(kill(pid, SIGINT), 0);
  const Outcome o = finish(pid, log);
  ASSERT_EQ(o.code, 130) << o.out;
  EXPECT_FALSE(fs::exists(out / "trajectories.sqlite-journal"));
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2((out / "trajectories.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  auto one = [db](const char* sql) {
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &s, nullptr), SQLITE_OK) << sql;
    const long v = sqlite3_step(s) == SQLITE_ROW ? static_cast<long>(sqlite3_column_int64(s, 0)) : -1;
    sqlite3_finalize(s);
    return v;
  };
  const long frames = one("SELECT count(*) FROM frame_data");
  EXPECT_GE(frames, 3);
  EXPECT_EQ(one("SELECT count(DISTINCT frame) FROM trajectory_data"), frames);
  EXPECT_EQ(one("SELECT count(*) FROM trajectory_data"), 400 * frames);
  EXPECT_EQ(one("SELECT max(frame) FROM frame_data"), frames - 1);
  EXPECT_EQ(one("SELECT value FROM metadata WHERE key = 'version'"), 2);
  EXPECT_EQ(one("SELECT count(*) FROM geometry"), 1);
  sqlite3_close(db);
  const nlohmann::json stats = nlohmann::json::parse(slurp(out / "stats.json"));
  EXPECT_TRUE(stats["run"]["interrupted"].get<bool>());
  EXPECT_EQ(stats["trajectories"]["format"], "sqlite");
  EXPECT_EQ(stats["trajectories"]["path"], (out / "trajectories.sqlite").string());
  EXPECT_EQ(stats["trajectories"]["frames"].get<long>(), frames);
  EXPECT_EQ(stats["trajectories"]["geometry"]["wkt"], (out / "geometry.wkt").string());
  EXPECT_EQ(slurp(out / "geometry.wkt").rfind("POLYGON ((", 0), 0u);
  EXPECT_TRUE(nlohmann::json::parse(slurp(out / "geometry.geojson")).contains("features"));
}

// A terminal's Ctrl-C signals the whole foreground process group: throng
// and the encoder it feeds. The encoder must not die of it: throng ends the
// run after the frame, closes the pipe, the encoder finishes the file, and
// every output is complete, with exit status 130.
TEST_F(RunCommand, CtrlCToTheProcessGroupDuringAVideoRunKeepsEveryFile) {
#if !defined(THRONG_HAVE_RENDER)
  GTEST_SKIP() << "this build has no renderer: no video to interrupt";
#else
  const fs::path log = dir_ / "log.txt";
  const fs::path out = dir_ / "out";
  const pid_t pid = start({"--threads", "1", "run", "circle", "--agents", "200", "--render", "video", "--width", "160",
                           "--height", "90", "--out", out.string(), "--quiet"},
                          log);
  // Wait until the encoder has written part of the file (under its
  // temporary name until the video is finished).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    std::error_code ec;
    if (fs::file_size(out / "crowd.mp4.partial", ec) > 0 && !ec &&
        fs::file_size(out / "trajectories.csv.partial", ec) > 200 * 40 * 3 && !ec)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(kill(-pid, SIGINT), 0);  // the group, as a terminal does
  const Outcome o = finish(pid, log);
  ASSERT_EQ(o.code, 130) << o.out;
  EXPECT_NE(o.out.find("(interrupted)"), std::string::npos) << o.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out / "stats.json"));
  EXPECT_TRUE(stats["run"]["interrupted"].get<bool>());
  EXPECT_FALSE(fs::exists(out / "stats.json.partial"));
  EXPECT_FALSE(fs::exists(out / "crowd.mp4.partial"));
  const std::map<long, int> rows = read_trajectories(out / "trajectories.csv", 200);
  ASSERT_GE(rows.size(), 2u);
  for (const auto& [frame, n] : rows) EXPECT_EQ(n, 200) << "frame " << frame;
  const throng::testing::VideoProbe v = throng::testing::probe_video((out / "crowd.mp4").string());
  EXPECT_EQ(v.codec, "h264") << v;
  EXPECT_GT(v.frames, 0) << v;
  EXPECT_GT(v.duration, 0.0) << v;
#endif
}

// Ctrl-C to the process group while the world is built and the crowd placed
// (half a million agents take seconds): set-up stops at its next check,
// stats.json says the run was interrupted before its first step, exit 130.
TEST_F(RunCommand, CtrlCDuringSetUpEndsItWithStatsAndStatus130) {
  const fs::path log = dir_ / "log.txt";
  const fs::path out = dir_ / "out";
  const pid_t pid = start(
      {"run", "plaza", "--agents", "500000", "--steps", "100000", "--no-animate", "--out", out.string(), "--quiet"},
      log);
  // The start line comes before set-up; signal as soon as it is there.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline && slurp(log).find("up to 100000 steps") == std::string::npos)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(kill(-pid, SIGINT), 0);
  const Outcome o = finish(pid, log);
  ASSERT_EQ(o.code, 130) << o.out;
  EXPECT_NE(o.out.find("interrupted while"), std::string::npos) << o.out;
  EXPECT_EQ(o.out.find("ready in"), std::string::npos) << "set-up finished before the signal:\n" << o.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out / "stats.json"));
  EXPECT_TRUE(stats["run"]["interrupted"].get<bool>());
  EXPECT_EQ(stats["run"]["steps"].get<long>(), 0);
  EXPECT_FALSE(stats["run"]["interrupted_during"].get<std::string>().empty());
  EXPECT_EQ(stats["scenario"]["name"], "plaza");
  EXPECT_FALSE(fs::exists(out / "stats.json.partial"));
}

// Set-up costs what the world holds, not how far it reaches: a walkable
// square 2000 km across with one wall and ten agents routed round it (over
// the roadmap: their goal is behind the wall). The
// limit only catches a hang (it took 0.2 s on a 2-core machine; the
// benchmark row path/huge_world_setup measures it).
TEST_F(RunCommand, AHugeNearlyEmptyWorldSetsUpQuickly) {
  const fs::path scene = dir_ / "huge.yaml";
  std::ofstream(scene) << "name: huge\n"
                          "world:\n"
                          "  walkable: {rect: {min: [-1000000, -1000000], max: [1000000, 1000000]}}\n"
                          "  obstacles:\n"
                          "    - rect: {min: [0, -5], max: [1, 5]}\n"
                          "groups:\n"
                          "  - name: g\n"
                          "    count: 10\n"
                          "    radius: 0.25\n"
                          "    spawn: {rect: {min: [-10, -2], max: [-5, 2]}}\n"
                          "    goal: {point: [10, 0]}\n";
  const fs::path log = dir_ / "log.txt";
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = start(
      {"run", scene.string(), "--seconds", "30", "--no-animate", "--out", (dir_ / "out").string(), "--quiet"}, log);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (waitpid(pid, &status, WNOHANG) == 0) {
    kill(-pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "a 2000 km world with one wall did not finish in 120 s:\n" << slurp(log);
  }
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << slurp(log);
  const nlohmann::json stats = nlohmann::json::parse(slurp(dir_ / "out" / "stats.json"));
  EXPECT_EQ(stats["crowd"]["obstacle_penetrations"]["max"].get<long>(), 0);
  EXPECT_EQ(stats["run"]["steps"].get<long>(), 300);
}

// A request beyond the memory budget is refused before any work starts, with
// the figures; --max-memory is a global option (before or after the command).
TEST_F(RunCommand, RequestsBeyondTheMemoryBudgetAreRefusedUpFront) {
  const auto t0 = std::chrono::steady_clock::now();
  Outcome o = run({"--max-memory", "1G", "animate", "--characters", "10000000", "--out", dir_.string()});
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(
      o.out.find(
          "--characters: about 7.15 GiB for 10000000 characters exceeds the memory budget of 1 GiB (--max-memory)"),
      std::string::npos)
      << o.out;
  o = run({"run", "plaza", "--agents", "2000000", "--max-memory", "500M", "--out", dir_.string()});
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("--agents: about 1.79 GiB for 2000000 agents exceeds the memory budget of 500 MiB"),
            std::string::npos)
      << o.out;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(60)) << "the refusal came after the work";
  o = run({"run", "circle", "--max-memory", "lots"});
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("--max-memory: expected a size such as 512M, 8G or 1.5GiB, got 'lots'"), std::string::npos)
      << o.out;
}

// A disk that fills up mid-run (every file capped at 300 KB): the run fails
// with a message, and every file it leaves is either whole or named
// `.partial`: no truncated trajectories.csv or crowd.mp4 under its final name.
TEST_F(RunCommand, AFullDiskLeavesNoUnmarkedPartialFile) {
#if !defined(THRONG_HAVE_RENDER)
  const std::vector<std::string> render;
#else
  const std::vector<std::string> render = {"--render", "video", "--width", "160", "--height", "90"};
#endif
  const fs::path log = dir_ / "log.txt";
  const fs::path out = dir_ / "out";
  std::vector<std::string> args = {"--threads", "1", "run",   "circle",     "--agents", "400",
                                   "--every",   "1", "--out", out.string(), "--quiet"};
  args.insert(args.end(), render.begin(), render.end());
  const Outcome o = finish(start(args, log, 300 * 1024), log);
  EXPECT_EQ(o.code, 1) << o.out;
  EXPECT_NE(o.out.find("File too large"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("trajectories.csv is incomplete: kept as " + (out / "trajectories.csv.partial").string()),
            std::string::npos)
      << o.out;
  EXPECT_TRUE(fs::exists(out / "trajectories.csv.partial"));
  for (const char* whole : {"trajectories.csv", "crowd.mp4", "stats.json"})
    EXPECT_FALSE(fs::exists(out / whole)) << whole;
  for (const fs::directory_entry& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    const bool marked = name.size() > 8 && name.substr(name.size() - 8) == ".partial";
    EXPECT_TRUE(marked || name == "geometry.wkt" || name == "geometry.geojson") << "unexpected file " << name;
  }
}

// The first picture a newcomer makes: 300 agents on the circle, rendered
// with the defaults. The camera follows the crowd without letting the
// characters shrink to dots: stats.json's median character height in the
// frames (a 1.75 m person at each agent in the picture) is at least 30 px.
TEST_F(RunCommand, RenderedCharactersAreLargeEnoughToSee) {
#if !defined(THRONG_HAVE_RENDER)
  GTEST_SKIP() << "this build has no renderer";
#else
  const fs::path out = dir_ / "out";
  const Outcome o = run({"--threads", "2", "run", "circle", "--agents", "300", "--seconds", "3", "--render", "frames",
                         "--width", "320", "--height", "180", "--no-trajectories", "--out", out.string()});
  ASSERT_EQ(o.code, 0) << o.out;
  const nlohmann::json stats = nlohmann::json::parse(slurp(out / "stats.json"));
  EXPECT_GT(stats["render"]["frames"].get<long>(), 10);
  EXPECT_GE(stats["render"]["median_character_px"].get<double>(), 30.0) << stats["render"];
  EXPECT_NE(o.out.find("characters in the picture: a median"), std::string::npos) << o.out;
#endif
}

}  // namespace
