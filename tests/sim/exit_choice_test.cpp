// Exit choice: the nearest exit in a straight line, or the quickest way out
// (walking time plus the wait behind those nearer the door; exit_choice.h).
// A hand-computed queue, then a crowd of 400 with two doors 10 m and 14 m
// away: the nearest sends everyone to the near door; the quickest uses both
// and empties the room at least 20% sooner, under the default model and the
// collision-free speed model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "io/scenario_yaml.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

ExitSpec door(glm::vec2 point, float width) {
  ExitSpec e;
  e.point = point;
  e.width = width;
  return e;
}

GoalSpec two_exits(ExitSpec a, ExitSpec b, ExitChoice choice) {
  GoalSpec g;
  g.kind = GoalSpec::Kind::Exits;
  g.exits = {a, b};
  g.choice = choice;
  return g;
}

// Three agents at x = 2, 3, 4 on the line between a 0.1 m door at x = 0
// (0.13 P/s) and a wide one at x = 12, all at 1.3 m/s; the walk beyond the
// nearest door (A) counts twice. In order of distance: the first has no
// queue (A: 1.5 s); the second waits for one (A: 2.3 + 7.7 = 10.0 s against
// B: (3 + 2 x 6) / 1.3 = 11.5 s); the third for two (A: 3.1 + 15.4 = 18.5 s
// against B: (4 + 2 x 4) / 1.3 = 9.2 s) and takes B.
TEST(ExitChoice, QuickestWeighsTheQueueAhead) {
  ScenarioSpec s = test::open_field(0, {0, 0}, {1, 1}, {0, 0});
  s.planning = PlanningKind::None;
  GroupSpec& g = s.groups[0];
  g.spawn.kind = Region::Kind::points;
  g.spawn.points = {{4, 0}, {2, 0}, {3, 0}};
  g.count = 3;
  g.speed = {1.3f, 0.0f, 1.3f, 1.3f};
  g.goal = two_exits(door({0, 0}, 0.1f), door({12, 0}, 2.0f), ExitChoice::Quickest);
  Simulation sim(s);
  // Spawning aims everyone at the nearest exit; the first step chooses.
  for (glm::vec2 goal : sim.crowd().goal.to_vector()) EXPECT_EQ(goal, glm::vec2(0, 0));
  sim.step();
  const std::vector<glm::vec2> goals = sim.crowd().goal.to_vector();
  EXPECT_EQ(goals[1], glm::vec2(0, 0));
  EXPECT_EQ(goals[2], glm::vec2(0, 0));
  EXPECT_EQ(goals[0], glm::vec2(12, 0));
}

// With navigation fields the quickest exit is weighed by the walk, not the
// straight line: in a 20 x 10 m hall an agent at (2, 1) has door A at
// (10, 1), 8 m away in a straight line but behind a wall from (6, 0) to
// (6, 9) (a walk of about 18 m round its north end), and door B at (2, 10),
// 9 m away in plain view. Straight distances send it to A; the fields to B.
TEST(ExitChoice, QuickestWeighsTheWalkWithNavigationFields) {
  for (PlanningKind planning : {PlanningKind::None, PlanningKind::Field}) {
    const std::string yaml = std::string("name: hall\nplanning: ") + to_string(planning) +
                             "\nworld:\n  walkable: {rect: {min: [0, 0], max: [20, 10]}}\n"
                             "  obstacles:\n    - rect: {min: [6, 0], max: [6.2, 9]}\n"
                             "groups:\n  - count: 1\n    radius: 0.25\n    spawn: {points: [[2, 1]]}\n"
                             "    goal: {exits: [{point: [10, 1], width: 1}, {point: [2, 9.8], width: 1}], choice: "
                             "quickest}\n";
    const auto sim = io::build_simulation(io::parse_scenario(yaml, "hall.yaml"));
    sim->step();
    const glm::vec2 goal = sim->crowd().goal.to_vector()[0];
    EXPECT_EQ(goal, planning == PlanningKind::Field ? glm::vec2(2, 9.8f) : glm::vec2(10, 1)) << to_string(planning);
  }
}

// A 36 m x 24 m room with 1.2 m doors in its south wall at (16, 0) and its
// north wall at (16, 24); 400 agents in a strip 32 m x 3.8 m centred at
// (16, 10): 10 m from the south door, 14 m from the north one, and every
// agent nearer the south door.
ScenarioSpec room(ExitChoice choice, ModelKind model) {
  ScenarioSpec s = test::straight_spec("two_exits", model, 0.1f, 900.0f);
  s.world.has_walkable = true;
  s.world.walkable.outer = {{-2, 0},  {15.4f, 0},  {15.4f, -2}, {16.6f, -2}, {16.6f, 0},  {34, 0},
                            {34, 24}, {16.6f, 24}, {16.6f, 26}, {15.4f, 26}, {15.4f, 24}, {-2, 24}};
  GroupSpec g;
  g.count = test::sanitized() ? 150 : 400;
  g.radius = 0.25f;
  g.speed = {1.3f, 0.15f, 0.9f, 1.7f};
  g.spawn.kind = Region::Kind::rect;
  g.spawn.min = {0.0f, 8.1f};
  g.spawn.max = {32.0f, 11.9f};
  g.goal = two_exits(door({16, 0}, 1.2f), door({16, 24}, 1.2f), choice);
  g.arrival = ArrivalBehaviour::Despawn;
  s.groups = {g};
  return s;
}

struct Evacuation {
  Index agents = 0, arrived = 0, south = 0, north = 0;
  float last = 0.0f;  // s: the last arrival
};

Evacuation evacuate(const ScenarioSpec& s) {
  Simulation sim(s);
  while (!sim.all_arrived() && sim.time() < s.duration) sim.step();
  Evacuation e;
  e.agents = sim.agent_count();
  e.arrived = sim.arrived_count();
  // A despawned agent stays where it left: at the door it took.
  for (glm::vec2 p : sim.positions()) (p.y < 12.0f ? e.south : e.north) += 1;
  for (float t : sim.arrival_times()) e.last = std::max(e.last, t);
  return e;
}

TEST(ExitChoice, QuickestUsesBothDoorsAndEmptiesTheRoomSooner) {
  for (const ModelKind model : {ScenarioSpec{}.model.kind, ModelKind::CollisionFreeSpeed}) {
    SCOPED_TRACE(to_string(model));
    const Evacuation nearest = evacuate(room(ExitChoice::Nearest, model));
    const Evacuation quickest = evacuate(room(ExitChoice::Quickest, model));
    std::printf(
        "  %s, %lld agents: nearest %lld south / %lld north, out by %.1f s; quickest %lld / %lld, out by %.1f s "
        "(%.0f%% sooner)\n",
        to_string(model), static_cast<long long>(nearest.agents), static_cast<long long>(nearest.south),
        static_cast<long long>(nearest.north), nearest.last, static_cast<long long>(quickest.south),
        static_cast<long long>(quickest.north), quickest.last, 100.0 * (1.0 - quickest.last / nearest.last));
    EXPECT_EQ(nearest.arrived, nearest.agents);
    EXPECT_EQ(quickest.arrived, quickest.agents);
    EXPECT_EQ(nearest.south, nearest.agents);
    EXPECT_GE(quickest.north, quickest.agents / 4);
    EXPECT_GE(quickest.south, quickest.agents / 4);
    EXPECT_LE(quickest.last, 0.8f * nearest.last);
  }
}

// The same doors given as door lines: each agent leaves once across its
// door's line (not within arrival_radius of its middle), whichever door it
// switched to.
TEST(ExitChoice, DoorLinesAreLeftByCrossingThem) {
  ScenarioSpec s = room(ExitChoice::Quickest, ModelKind::CollisionFreeSpeed);
  for (ExitSpec& x : s.groups[0].goal.exits) x.half = {0.6f, 0.0f};
  Simulation sim(s);
  while (!sim.all_arrived() && sim.time() < s.duration) sim.step();
  EXPECT_EQ(sim.arrived_count(), sim.agent_count());
  Index south = 0, north = 0;
  for (glm::vec2 p : sim.positions()) {
    EXPECT_TRUE(p.y <= 0.0f || p.y >= 24.0f) << p.x << ", " << p.y << ": left before the line";
    EXPECT_LE(std::fabs(p.x - 16.0f), 0.6f + s.groups[0].radius);
    (p.y < 12.0f ? south : north) += 1;
  }
  float last = 0.0f;
  for (float t : sim.arrival_times()) last = std::max(last, t);
  std::printf("  door lines: %lld south / %lld north, out by %.1f s\n", static_cast<long long>(south),
              static_cast<long long>(north), last);
  EXPECT_GE(north, sim.agent_count() / 4);
  EXPECT_GE(south, sim.agent_count() / 4);
}

TEST(ExitChoice, BadExitsAreLocatedErrors) {
  auto has = [](const std::string& text, const char* part) { return text.find(part) != std::string::npos; };
  ScenarioSpec none = room(ExitChoice::Nearest, ModelKind::CollisionFreeSpeed);
  none.groups[0].goal.exits.clear();
  EXPECT_TRUE(has(test::spawn_error(none), "groups[0].goal.exits"));
  ScenarioSpec narrow = room(ExitChoice::Quickest, ModelKind::CollisionFreeSpeed);
  narrow.groups[0].goal.exits[1].width = 0.0f;
  EXPECT_TRUE(has(test::spawn_error(narrow), "groups[0].goal.exits[1].width"));
  ScenarioSpec walled = room(ExitChoice::Quickest, ModelKind::CollisionFreeSpeed);
  walled.groups[0].goal.exits[1].point = {40, 12};  // outside the walkable area
  EXPECT_TRUE(has(test::spawn_error(walled), "groups[0].goal.exits[1]"));
  ScenarioSpec looping = room(ExitChoice::Nearest, ModelKind::CollisionFreeSpeed);
  looping.groups[0].arrival = ArrivalBehaviour::Loop;
  EXPECT_TRUE(has(test::spawn_error(looping), "groups[0].on_arrival"));
  ScenarioSpec via = room(ExitChoice::Nearest, ModelKind::CollisionFreeSpeed);
  via.groups[0].waypoints = {via.groups[0].goal};
  EXPECT_TRUE(has(test::spawn_error(via), "groups[0].waypoints[0]"));
}

}  // namespace
}  // namespace throng::sim
