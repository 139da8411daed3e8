// State machine and paths files: the shipped default machine, errors with
// file:line:column, and `throng match` run as a user runs it.
#include "io/state_machine_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"
#include "io/paths_yaml.h"
#include "motion/default_set.h"
#include "path/state_machine.h"
#include "tests/io/throng_exe.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::string& yaml) {
  try {
    const path::StateMachineSpec spec = parse_state_machine(yaml, "m.yaml");
    path::MotionGraph::build(spec, motion::default_skeleton());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(StateMachineYaml, DefaultMachineHasTheRequiredStates) {
  const path::StateMachineSpec spec = default_state_machine_spec();
  const path::MotionGraph m = path::MotionGraph::build(spec, motion::default_skeleton());
  for (const char* s : {"idle", "walk_forward", "run_forward", "walk_left", "walk_right", "run_left", "run_right"})
    EXPECT_GE(m.state_index(s), 0) << s;
  EXPECT_EQ(m.k(), 64);
  EXPECT_NEAR(m.segment_length(), 1.44f, 1e-4f);
  EXPECT_EQ(m.spec().transition_frames, 8);
  auto s = [&](const char* n) { return m.state_index(n); };
  EXPECT_FALSE(m.allowed(s("walk_left"), s("run_right")));
  EXPECT_TRUE(m.allowed(s("run_left"), s("walk_forward")));
  EXPECT_TRUE(m.allowed(s("idle"), s("walk_forward")));
  // The shipped file is the one compiled in.
  const fs::path file = fs::path(THRONG_SOURCE_DIR) / "data" / "motion" / "default_machine.yaml";
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), std::string(default_state_machine_yaml()));
}

TEST(StateMachineYaml, ErrorsCarryFileLineAndColumn) {
  const std::string head = "clips:\n  walk: {default: walk}\nstates:\n";
  EXPECT_NE(error_of(head + "  w:\n    segments: [{clip: walk, start: 0}]\n    colour: red\n").find("m.yaml:6:5"),
            std::string::npos);
  EXPECT_NE(error_of(head + "  w:\n    segments: [{clip: jog}]\n").find("m.yaml:5:16"), std::string::npos);
  EXPECT_NE(error_of(head + "  w:\n    segments: [{clip: walk, start: -3}]\n").find("m.yaml:5:36"), std::string::npos);
  EXPECT_NE(error_of("clips:\n  walk: {default: walk}\nstates: [1, 2\n").find("m.yaml:"), std::string::npos);
  EXPECT_NE(
      error_of("clips:\n  a: {gait: walk, speed: 9}\nstates:\n  w:\n    segments: [{clip: a}]\n").find("m.yaml:2:"),
      std::string::npos);
  EXPECT_NE(error_of("clips:\n  a: {default: moonwalk}\nstates:\n  w:\n    segments: [{clip: a}]\n").find("moonwalk"),
            std::string::npos);
  EXPECT_NE(error_of(head + "  w:\n    segments: [{clip: walk}]\nedges:\n  - [w, nowhere]\n").find("m.yaml:7:5"),
            std::string::npos);
  EXPECT_NE(error_of(head + "  w:\n    segments: [{clip: walk, frames: 30}]\n").find("m.yaml:5:"), std::string::npos);
  EXPECT_NE(error_of("points_per_segment: 1.5\n" + head + "  w:\n    segments: [{clip: walk}]\n").find("m.yaml:1:21"),
            std::string::npos);
  EXPECT_EQ(error_of(head + "  w:\n    segments: [{clip: walk}]\n"), "");
}

TEST(PathsYaml, ReadsPathsAndRejectsBadOnes) {
  const PathsFile f = parse_paths(
      "radius: 0.3\nworld:\n  bounds: [[0, 0], [20, 10]]\n  circles: [{center: [5, 5], radius: 1}]\n"
      "paths:\n  - {name: a, points: [[1, 1], [4, 1]], speed: 1.35, marks: [{from: 0.5, to: 1.5, state: "
      "run_forward}]}\n"
      "  - {from: [1, 1], to: [19, 9]}\n",
      "p.yaml");
  EXPECT_FLOAT_EQ(f.radius, 0.3f);
  ASSERT_EQ(f.paths.size(), 2u);
  EXPECT_EQ(f.paths[0].points.size(), 2u);
  EXPECT_EQ(f.paths[0].marks.size(), 1u);
  EXPECT_TRUE(f.paths[1].planned);
  EXPECT_EQ(f.circles.size(), 1u);
  auto error = [](const std::string& y) {
    try {
      parse_paths(y, "p.yaml");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("paths:\n  - {points: [[1, 1]]}\n").find("p.yaml:2:14"), std::string::npos);
  EXPECT_NE(error("paths:\n  - {from: [1, 1], to: [2, 2]}\n").find("needs a 'world'"), std::string::npos);
  EXPECT_NE(error("paths:\n  - {points: [[1, .nan], [2, 2]]}\n").find("p.yaml:2:"), std::string::npos);
  EXPECT_NE(error("paths:\n  - {points: [[1, 1], [2, 2]], marks: [{from: 2, to: 1, state: x}]}\n").find("p.yaml:2:"),
            std::string::npos);
  EXPECT_NE(error("speed: 3\npaths: []\n").find("unknown key 'speed'"), std::string::npos);
}

// Every prefix of the shipped files (a truncated download) and many
// single-byte changes either read or give an Error that says where (file
// position or key); none
// crashes or hangs (the seeds of fuzz/io/fuzz_state_machine_yaml.cpp and
// fuzz_paths_yaml.cpp, run as a test).
template <class Read>
void truncations_and_flips(const std::string& text, std::size_t prefix_stride, std::size_t flip_stride, Read&& read) {
  auto attempt = [&](const std::string& t) {
    try {
      read(t);
    } catch (const Error& e) {
      EXPECT_TRUE(e.location().line > 0 || !e.location().file.empty() || !e.location().field.empty()) << e.what();
    }
  };
  for (std::size_t n = 0; n < text.size(); n += prefix_stride) attempt(text.substr(0, n));
  std::string flipped = text;
  for (std::size_t i = 0; i < text.size(); i += flip_stride) {
    for (char c : {'\0', ':', '9', '\n'}) {
      flipped[i] = c;
      attempt(flipped);
    }
    flipped[i] = text[i];
  }
}

TEST(StateMachineYaml, TruncationsAndByteFlipsNeverCrash) {
  const std::string text(default_state_machine_yaml());
  truncations_and_flips(text, 211, 149, [](const std::string& t) {
    path::MotionGraph::build(parse_state_machine(t, "m.yaml"), motion::default_skeleton());
  });
}

TEST(PathsYaml, TruncationsAndByteFlipsNeverCrash) {
  std::ifstream in(fs::path(THRONG_SOURCE_DIR) / "examples" / "match" / "paths.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  ASSERT_FALSE(ss.str().empty());
  truncations_and_flips(ss.str(), 5, 3, [](const std::string& t) { parse_paths(t, "p.yaml"); });
}

// ---- the command ------------------------------------------------------------------

// The command's output, appended to `out`; returns the exit code.
int run(const fs::path& exe, const std::string& args, std::string& out) {
  const testing::Result r = testing::run(exe, args);
  out += r.out;
  return r.code;
}

TEST(MatchCommand, RandomPathsAndAPathsFile) {
  const fs::path exe = testing::throng_exe();
  const fs::path dir = fs::temp_directory_path() / ("throng_match_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string out;
  ASSERT_EQ(run(exe, "match --random 6 --seed 3 --bvh 1 --out " + dir.string(), out), 0) << out;
  EXPECT_NE(out.find("dynamic program"), std::string::npos) << out;
  std::ifstream in(dir / "match.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["dp"]["illegal_transitions"], 0);
  EXPECT_EQ(j["paths"].size() + j["unplanned"].get<std::size_t>(), 6u);
  EXPECT_GT(j["playback"]["deviation_mean_m"].get<double>(), 0.0);
  EXPECT_LT(j["playback"]["deviation_mean_m"].get<double>(), 0.2);
  EXPECT_TRUE(fs::exists(dir / (j["paths"][0]["name"].get<std::string>() + ".bvh")));

  const fs::path paths = dir / "paths.yaml";
  std::ofstream(paths) << "world:\n  bounds: [[0, 0], [30, 20]]\n  circles: [{center: [15, 10], radius: 3}]\n"
                          "paths:\n  - {name: around, from: [2, 10], to: [28, 10], speed: 1.35}\n"
                          "  - {name: line, points: [[0, 0], [12, 0]], speed: 2.7}\n";
  out.clear();
  ASSERT_EQ(run(exe, "match " + paths.string() + " --out " + dir.string(), out), 0) << out;
  std::ifstream in2(dir / "match.json");
  const nlohmann::json k = nlohmann::json::parse(in2);
  ASSERT_EQ(k["paths"].size(), 2u);
  EXPECT_GT(k["paths"][0]["length_m"].get<double>(), 26.0);  // goes around the disc
  out.clear();
  std::ofstream(paths) << "paths:\n  - {name: bad, points: [[0, 0]]}\n";
  const int bad_path = run(exe, "match " + paths.string() + " --out " + dir.string(), out);
  EXPECT_NE(bad_path, 0);
  EXPECT_EQ(bad_path, 1) << out;  // throng::Error, not a crash
  EXPECT_NE(out.find("paths.yaml:2:"), std::string::npos) << out;
  EXPECT_NE(out.find("needs at least 2 points"), std::string::npos) << out;
  out.clear();
  const int nothing = run(exe, "match --out " + dir.string(), out);
  EXPECT_NE(nothing, 0);
  EXPECT_EQ(nothing, 1) << out;
  EXPECT_NE(out.find("throng: error:"), std::string::npos) << out;
  EXPECT_NE(out.find("give a paths file or --random N"), std::string::npos) << out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace throng::io
