// Re-planning (sim/replanning.h): an agent on a planned route, pushed into
// a pocket from which it cannot see its next waypoint (a scripted push: its
// position rewritten mid-run), gets a new route and reaches its goal; the
// same push without re-planning leaves it pinned in the pocket's corner.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "io/scenario_yaml.h"
#include "path/route_planner.h"
#include "sim/simulation.h"

namespace throng::sim {
namespace {

// A 20 m x 10 m room split by a wall with a gap at its top (y 8-10), and a
// pocket open to the south (x 4-8, y 3-6.2) west of the wall. One agent walks
// from (2, 1) to (17, 2): its route goes up and through the gap.
constexpr const char* kRoom = R"(
name: pocket
dt: 0.1
duration: 120
model: {type: MODEL}
world:
  walkable: {rect: {min: [0, 0], max: [20, 10]}}
  obstacles:
    - rect: {min: [9.8, 0], max: [10.2, 8]}
    - rect: {min: [4, 6], max: [8, 6.2]}
    - rect: {min: [4, 3], max: [4.2, 6]}
    - rect: {min: [7.8, 3], max: [8, 6]}
groups:
  - count: 1
    radius: 0.25
    speed: 1.3
    spawn: {points: [[2, 1]]}
    goal: {point: [17, 2]}
)";

struct Outcome {
  bool arrived = false;
  Index replanned = 0;
  glm::vec2 end{0.0f};
};

Outcome pushed_into_the_pocket(const char* model, bool replan) {
  std::string text = kRoom;
  text.replace(text.find("MODEL"), 5, model);
  const io::LoadedScenario loaded = io::parse_scenario(text, "pocket.yaml");
  const path::RoadmapRoutePlanner own;
  SimulationOptions options;
  options.planner = &own;  // planned routes, but nobody to plan again
  std::unique_ptr<Simulation> sim = replan ? io::build_simulation(loaded) : io::build_simulation(loaded, options);
  EXPECT_GT(sim->crowd().waypoint_count.to_vector()[0], 1) << "the route goes round the wall";
  sim->run(10);
  // The push: into the pocket's north-east corner, the gap hidden behind it.
  const glm::vec2 inside(7.4f, 5.6f);
  sim->crowd().position.write(0, std::span<const glm::vec2>(&inside, 1));
  while (!sim->all_arrived() && sim->time() < 120.0) sim->step();
  return {sim->all_arrived(), sim->replanned_count(), sim->positions()[0]};
}

TEST(Replanning, AnAgentPushedOffItsRouteReachesItsGoal) {
  for (const char* model : {"priority", "collision_free_speed"}) {
    SCOPED_TRACE(model);
    const Outcome with = pushed_into_the_pocket(model, true), without = pushed_into_the_pocket(model, false);
    std::printf("  %s: re-planned %lld time(s), arrived %d; without re-planning arrived %d, ended at (%.2f, %.2f)\n",
                model, static_cast<long long>(with.replanned), with.arrived, without.arrived,
                static_cast<double>(without.end.x), static_cast<double>(without.end.y));
    EXPECT_TRUE(with.arrived);
    EXPECT_GE(with.replanned, 1);
    EXPECT_FALSE(without.arrived) << "the push must strand an agent that cannot plan again";
  }
}

}  // namespace
}  // namespace throng::sim
