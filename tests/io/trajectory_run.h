// One short run written in every trajectory format at once, for the tests
// that read the files back (run_outputs_test.cpp, sqlite_trajectories_test.cpp),
// and its CSV read as the reference positions.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "io/run_outputs.h"
#include "io/scenario_yaml.h"
#include "io/walkable_area.h"

namespace throng::io::testing {

// A 10 m square room with a pillar; 12 agents walk east for 23 steps of
// 0.1 s, written every 5 steps: frame rate 2, steps 0..20 on the stride and
// the last step 23 off it.
inline constexpr const char* kRoom = R"(planning: none
dt: 0.1
world:
  walkable: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]]}
  obstacles:
    - rect: {min: [4, 6], max: [6, 8]}
groups:
  - count: 12
    spawn: {rect: {min: [1, 1], max: [3, 4]}}
    goal: {point: [9, 2.5]}
)";
inline constexpr std::int64_t kEvery = 5, kSteps = 23, kAgents = 12;

struct RoomRun {
  std::filesystem::path dir;
  std::string wkt;       // the walkable area stored in the SQLite file
  nlohmann::json stats;  // the last writer's section is the sqlite one
  std::string path(TrajectoryFormat f) const { return (dir / trajectory_file_name(f)).string(); }
};

// Runs the room into `dir` (emptied first), csv, pedpy and sqlite together.
inline RoomRun run_room(const std::filesystem::path& dir) {
  RoomRun r{dir, {}, {}};
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const LoadedScenario loaded = parse_scenario(kRoom, "room.yaml");
  const std::unique_ptr<sim::Simulation> sim = build_simulation(loaded);
  sim::FrameLoop loop(*sim);
  r.wkt = to_wkt(walkable_area(*sim));
  for (TrajectoryFormat f : {TrajectoryFormat::Csv, TrajectoryFormat::Pedpy, TrajectoryFormat::Sqlite})
    loop.emplace<TrajectoryWriter>(TrajectoryOutput{f, r.path(f), kEvery, 0.1, r.wkt});
  sim::RunControl control;
  control.max_steps = kSteps;
  control.stop_when_arrived = false;
  loop.run(control);
  loop.finish(r.stats);
  return r;
}

using StepAgent = std::pair<std::int64_t, std::int64_t>;  // (step, agent index)
using Positions = std::map<StepAgent, std::pair<double, double>>;

// trajectories.csv: frame,time,agent,x,y,heading,speed.
inline Positions read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, TrajectoryWriter::kHeader);
  Positions out;
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    std::int64_t frame = 0, agent = 0;
    double time = 0, x = 0, y = 0;
    row >> frame >> time >> agent >> x >> y;
    EXPECT_FALSE(row.fail()) << line;
    out[{frame, agent}] = {x, y};
  }
  return out;
}

}  // namespace throng::io::testing
