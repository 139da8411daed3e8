// A recorded run: what `throng run`, `export-crowd` and `animate` produce for
// fixed scenarios and seeds, compared bit for bit with a recording kept in
// tests/data/recorded_run.txt. A change that means to keep behaviour (a
// refactor, a reorganised kernel) must leave every figure as it was:
// trajectories, the joint positions of every animated agent, stats.json.
//
// The recording holds digests (64-bit FNV-1a) of what is compared, one line
// per item, so that a mismatch names the item: a run's trajectories, one
// section of its stats.json, the joints of one agent in an export.
//
// A change that means to alter behaviour (a new default, a model fix)
// records anew, and says so in its commit:
//   THRONG_RECORD_RUN=tests/data/recorded_run.txt build/release/tests/app_tests --gtest_filter='RecordedRun.*'
// (THRONG_RECORD_EXE=/path/to/throng records with another build of it.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io/crowd_gltf.h"
#include "tests/io/throng_exe.h"

namespace {

namespace fs = std::filesystem;
using throng::io::testing::Result;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// 64-bit FNV-1a: a digest that any changed bit changes (no security needed).
class Digest {
 public:
  void add(const void* data, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ b[i]) * 0x100000001b3ull;
  }
  void add(const std::string& s) { add(s.data(), s.size()); }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, h_);
    return buf;
  }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

// Item name -> digest, in a stable order.
using Record = std::map<std::string, std::string>;

const char* exe() {
  const char* other = std::getenv("THRONG_RECORD_EXE");
  return other != nullptr && *other != '\0' ? other : THRONG_EXE;
}

// `throng args...` as io::testing::run runs it (CPU backend, warnings only), with its output.
Result run_throng(const std::vector<std::string>& args) {
  std::string line;
  for (const std::string& arg : args) line += (line.empty() ? "" : " ") + arg;
  return throng::io::testing::run(exe(), line);
}

// stats.json without what depends on the machine: timings, thread counts,
// the backend. Everything else is a figure of the run.
void drop_machine_figures(nlohmann::json& j) {
  if (!j.is_object()) return;
  for (auto it = j.begin(); it != j.end();) {
    const std::string& k = it.key();
    const bool timing = k == "kernels" || k == "frame_ms" || k == "wall_seconds" || k == "threads" || k == "backend" ||
                        k == "timings" || k == "characters_per_second" ||
                        (k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0);
    if (timing) {
      it = j.erase(it);
    } else {
      drop_machine_figures(*it);
      ++it;
    }
  }
}

// One digest per top-level section of stats.json; `dir`, the folder the
// test writes to, is replaced by a fixed name where a path names it.
void record_stats(const std::string& prefix, const fs::path& stats, const fs::path& dir, Record& out) {
  nlohmann::json j = nlohmann::json::parse(slurp(stats));
  drop_machine_figures(j);
  for (auto it = j.begin(); it != j.end(); ++it) {
    std::string text = it->dump();
    for (auto at = text.find(dir.string()); at != std::string::npos; at = text.find(dir.string(), at))
      text.replace(at, dir.string().size(), "DIR");
    Digest d;
    d.add(text);
    out[prefix + " stats." + it.key()] = d.hex();
  }
}

void record_file(const std::string& item, const fs::path& file, Record& out) {
  Digest d;
  d.add(slurp(file));
  out[item] = d.hex();
}

// One digest per agent over every key of its joints' world positions and
// rotations, as a DCC tool evaluates the file.
void record_glb_joints(const std::string& prefix, const fs::path& glb, Record& out) {
  const throng::io::CrowdGlb crowd(glb.string());
  std::vector<glm::vec3> positions;
  std::vector<glm::quat> rotations;
  std::vector<float> scales;
  for (throng::Index a = 0; a < crowd.agents(); ++a) {
    Digest d;
    for (std::int32_t f = 0; f < crowd.frames(); ++f) {
      crowd.joint_frames(a, f, positions, rotations, scales);
      d.add(positions.data(), positions.size() * sizeof(glm::vec3));
      d.add(rotations.data(), rotations.size() * sizeof(glm::quat));
    }
    out[prefix + " joints agent " + std::to_string(a)] = d.hex();
  }
}

// A scenario file from examples/ with a `model:` line after its `dt:` line.
fs::path example_with_model(const std::string& example, const std::string& model_line, const fs::path& dir) {
  std::istringstream in(slurp(fs::path(THRONG_SOURCE_DIR) / "examples" / example));
  std::ostringstream text;
  for (std::string line; std::getline(in, line);) {
    text << line << '\n';
    if (line.rfind("dt:", 0) == 0) text << model_line << '\n';
  }
  const fs::path file = dir / example;
  std::ofstream(file) << text.str();
  return file;
}

Record read_record(const fs::path& file) {
  Record r;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    const auto space = line.rfind(' ');
    if (space != std::string::npos) r[line.substr(0, space)] = line.substr(space + 1);
  }
  return r;
}

class RecordedRun : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("throng_recorded_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `throng run` with trajectories every frame; digests its outputs.
  void run(const std::string& name, std::vector<std::string> args, Record& out) {
    const fs::path d = dir_ / name;
    args.insert(args.begin(), "run");
    for (const char* a : {"--every", "1", "--quiet", "--out"}) args.emplace_back(a);
    args.push_back(d.string());
    const Result r = run_throng(args);
    ASSERT_EQ(r.code, 0) << r.out;
    record_file(name + " trajectories.csv", d / "trajectories.csv", out);
    record_stats(name, d / "stats.json", dir_, out);
  }

  fs::path dir_;
};

TEST_F(RecordedRun, RunsExportsAndAnimationsMatchTheRecording) {
  Record now;
  // The four models, both schedulers, animated (locomotion, LOD, cache).
  run("corridor_priority",
      {example_with_model("corridor.yaml", "model: {type: priority}", dir_).string(), "--agents", "60", "--seconds",
       "20", "--seed", "5"},
      now);
  run("bottleneck_cfs",
      {example_with_model("bottleneck.yaml", "model: {type: collision_free_speed}", dir_).string(), "--agents", "80",
       "--seconds", "30", "--seed", "2", "--scheduler", "four_colour"},
      now);
  run("crossing_ttc",
      {example_with_model("crossing.yaml", "model: {type: ttc}", dir_).string(), "--agents", "60", "--seconds", "15",
       "--seed", "3"},
      now);
  run("circle_social_force",
      {example_with_model("circle.yaml", "model: {type: social_force}", dir_).string(), "--agents", "40", "--seconds",
       "10", "--seed", "4"},
      now);
  run("maze_roadmap", {"maze", "--agents", "30", "--seconds", "20", "--seed", "6"}, now);

  // Joint positions of every exported agent.
  const fs::path glb = dir_ / "crowd.glb";
  const Result exported = run_throng({"export-crowd", "plaza", "--agents", "12", "--seconds", "4", "--fps", "24",
                                      "--seed", "7", "--out", glb.string()});
  ASSERT_EQ(exported.code, 0) << exported.out;
  record_glb_joints("export plaza", glb, now);

  // The formation animation (no simulation): its stats.json.
  const fs::path anim = dir_ / "animate";
  const Result animated =
      run_throng({"animate", "formation", "--duration", "4", "--characters", "30", "--out", anim.string()});
  ASSERT_EQ(animated.code, 0) << animated.out;
  record_stats("animate formation", anim / "stats.json", dir_, now);

  const fs::path recording = fs::path(THRONG_SOURCE_DIR) / "tests" / "data" / "recorded_run.txt";
  if (const char* to = std::getenv("THRONG_RECORD_RUN"); to != nullptr && *to != '\0') {
    std::ofstream f(to);
    f << "# tests/app/recorded_run_test.cpp: item, FNV-1a 64 digest. Record anew only for an intended change of "
         "behaviour.\n";
    for (const auto& [item, digest] : now) f << item << ' ' << digest << '\n';
    GTEST_SKIP() << "recorded " << now.size() << " items to " << to << " with " << exe();
  }
  const Record then = read_record(recording);
  ASSERT_FALSE(then.empty()) << "no recording at " << recording;
  for (const auto& [item, digest] : then) {
    const auto it = now.find(item);
    if (it == now.end()) {
      ADD_FAILURE() << item << ": recorded, not produced now";
    } else {
      EXPECT_EQ(it->second, digest) << item << " differs from the recording";
    }
  }
  for (const auto& [item, digest] : now)
    EXPECT_TRUE(then.count(item) == 1) << item << ": produced now, not in the recording (" << digest << ")";
}

}  // namespace
