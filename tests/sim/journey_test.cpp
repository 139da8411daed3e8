// Journeys of stages: gates (lines passed anywhere along them) and waiting
// at waypoints (a waiting area is a `random` waypoint with a wait), under
// every model; against the unhindered walk, which closed form gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "sim/crowd.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

constexpr ModelKind kModels[] = {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc,
                                 ModelKind::SocialForce};
constexpr float kSpeed = 1.3f;

// Agents at `starts` in an open field, walking at kSpeed through `via`
// to a goal 20 m east of where each started.
ScenarioSpec walkers(ModelKind model, const std::vector<glm::vec2>& starts, const GoalSpec& via) {
  ScenarioSpec s = test::straight_spec("journey", model, 0.05f, 60.0f);
  GroupSpec g;
  g.spawn.kind = Region::Kind::points;
  g.spawn.points = starts;
  g.count = static_cast<std::int64_t>(starts.size());
  g.radius = 0.2f;
  g.speed = {kSpeed, 0.0f, kSpeed, kSpeed};
  g.waypoints = {via};
  g.goal.kind = GoalSpec::Kind::Offset;
  g.goal.value = {20.0f, 0.0f};
  s.groups = {g};
  return s;
}

// Where each agent's path first crosses x = line_x (the y there), NaN if never.
std::vector<float> crossings_of(Simulation& sim, float line_x) {
  std::vector<glm::vec2> before = sim.positions();
  std::vector<float> y(before.size(), NAN);
  while (!sim.all_arrived() && sim.time() < 60.0) {
    sim.step();
    const std::vector<glm::vec2> p = sim.positions();
    for (std::size_t i = 0; i < p.size(); ++i)
      if (std::isnan(y[i]) && before[i].x < line_x && p[i].x >= line_x) {
        const float t = (line_x - before[i].x) / (p[i].x - before[i].x);
        y[i] = before[i].y + t * (p[i].y - before[i].y);
      }
    before = p;
  }
  return y;
}

// Seven walkers abreast, 1.5 m apart, and one whose straight line passes
// 3 m beyond the gate's end. A gate 10 m long across their way: each walker
// crosses it where its straight line does and arrives in the unhindered
// time (a point waypoint would draw them to its middle); the one outside
// crosses within the gate, a body and 10 cm inside its end.
TEST(Journey, AGateIsPassedWhereverTheAgentMeetsIt) {
  std::vector<glm::vec2> starts;
  for (int k = -3; k <= 3; ++k) starts.push_back({0.0f, 1.5f * static_cast<float>(k)});
  starts.push_back({0.0f, 8.0f});
  for (const ModelKind model : kModels) {
    SCOPED_TRACE(to_string(model));
    const ScenarioSpec s = walkers(model, starts, GoalSpec::gate({10.0f, -5.0f}, {10.0f, 5.0f}));
    Simulation sim(s);
    const std::vector<float> y = crossings_of(sim, 10.0f);
    ASSERT_TRUE(sim.all_arrived()) << sim.arrived_count() << " of " << sim.agent_count();
    const std::vector<float> arrived = sim.arrival_times();
    for (std::size_t i = 0; i + 1 < starts.size(); ++i) {
      EXPECT_NEAR(y[i], starts[i].y, 0.25f) << "walker " << i;
      EXPECT_LE(arrived[i], 20.0f / kSpeed * 1.08f) << "walker " << i;
    }
    const std::size_t outside = starts.size() - 1;
    // (The priority model's turns are slow: its centre, not its body, stays inside.)
    EXPECT_LE(y[outside], model == ModelKind::Priority ? 5.0f : 5.0f - 0.2f) << "crossed beside the gate";
    EXPECT_GE(y[outside], 5.0f - 0.2f - 0.1f - 0.35f);
  }
}

// The same crossing with a point waypoint in the gate's middle draws the
// walkers off their line: the gate is what lets them keep it.
TEST(Journey, APointWaypointInsteadDrawsWalkersToIt) {
  std::vector<glm::vec2> starts;
  for (int k = -3; k <= 3; ++k) starts.push_back({0.0f, 1.5f * static_cast<float>(k)});
  const ScenarioSpec s = walkers(ModelKind::CollisionFreeSpeed, starts, GoalSpec::at({10.0f, 0.0f}));
  Simulation sim(s);
  const std::vector<float> y = crossings_of(sim, 10.0f);
  EXPECT_LT(std::fabs(y.front()), 2.0f);
  EXPECT_LT(std::fabs(y.back()), 2.0f);
}

// A gate crossed from the other side, its ends given in either order, is
// passed the same, and only once the agent is across it.
TEST(Journey, AGateCountsFromEitherSideOnceCrossed) {
  for (const bool reversed : {false, true}) {
    ScenarioSpec s = walkers(
        ModelKind::CollisionFreeSpeed, {{20.0f, 0.0f}},
        reversed ? GoalSpec::gate({10.0f, 5.0f}, {10.0f, -5.0f}) : GoalSpec::gate({10.0f, -5.0f}, {10.0f, 5.0f}));
    s.groups[0].goal.value = {-20.0f, 0.0f};
    Simulation sim(s);
    while (!sim.all_arrived() && sim.time() < 40.0) {
      sim.step();
      if (sim.crowd().waypoint_cursor.to_vector()[0] > 0) {
        EXPECT_LT(sim.positions()[0].x, 10.0f) << sim.time();
      }
    }
    ASSERT_TRUE(sim.all_arrived()) << "reversed " << reversed;
    EXPECT_LE(sim.arrival_times()[0], 20.0f / kSpeed * 1.08f);
  }
}

// A turnstile: a gate 0.3 m long, shorter than a body and its margins,
// with a 3 s wait once through. Every model walks through it (led past its
// middle: none creeps onto the line), stands 3 s just past it, and walks on.
TEST(Journey, ATurnstileWithAWaitIsPassedByEveryModel) {
  for (const ModelKind model : kModels) {
    SCOPED_TRACE(to_string(model));
    GoalSpec turnstile = GoalSpec::gate({10.0f, -0.15f}, {10.0f, 0.15f});
    turnstile.wait_s = 3.0f;
    const ScenarioSpec s = walkers(model, {{0.0f, 0.0f}}, turnstile);
    Simulation sim(s);
    float stood = 0.0f, stood_at = NAN;
    glm::vec2 before = sim.positions()[0];
    while (!sim.all_arrived() && sim.time() < 60.0) {
      sim.step();
      const glm::vec2 p = sim.positions()[0];
      if (p == before && sim.time() > 1.0) {
        stood += s.dt;
        stood_at = p.x;
      }
      before = p;
    }
    ASSERT_TRUE(sim.all_arrived());
    EXPECT_NEAR(stood, 3.0f, 1.5f * s.dt);
    EXPECT_GE(stood_at, 10.0f);  // past the line
    EXPECT_LE(stood_at, 10.0f + kSpeed * s.dt + 0.01f);
    EXPECT_LE(sim.arrival_times()[0], 20.0f / kSpeed * 1.1f + 3.0f);
  }
}

// An exit given as a door line 10 m long across the walkers' way: each
// leaves where its straight line meets it, in the unhindered time (plus a
// second to reach speed from standing, which the social force model takes).
TEST(Journey, ADoorLineExitIsLeftWhereverTheAgentMeetsIt) {
  std::vector<glm::vec2> starts;
  for (int k = -3; k <= 3; ++k) starts.push_back({0.0f, 1.5f * static_cast<float>(k)});
  for (const ModelKind model : kModels) {
    SCOPED_TRACE(to_string(model));
    ScenarioSpec s = walkers(model, starts, GoalSpec::at({0.0f, 0.0f}));
    GroupSpec& g = s.groups[0];
    g.waypoints.clear();
    g.goal.kind = GoalSpec::Kind::Exits;
    ExitSpec door;
    door.point = {10.0f, 0.0f};
    door.half = {0.0f, 5.0f};
    door.width = 10.0f;
    g.goal.exits = {door};
    g.arrival = ArrivalBehaviour::Despawn;
    Simulation sim(s);
    const std::vector<float> y = crossings_of(sim, 10.0f);
    ASSERT_TRUE(sim.all_arrived()) << sim.arrived_count() << " of " << sim.agent_count();
    const std::vector<float> arrived = sim.arrival_times();
    for (std::size_t i = 0; i < starts.size(); ++i) {
      EXPECT_NEAR(y[i], starts[i].y, 0.25f) << "walker " << i;
      EXPECT_LE(arrived[i], 10.0f / kSpeed + 1.0f) << "walker " << i;  // (a second to reach speed)
    }
  }
}

// Longest run of consecutive steps (in s) over which the agent did not move.
float longest_stand(const std::vector<std::vector<glm::vec2>>& track, std::size_t i, float dt) {
  int best = 0, run = 0;
  for (std::size_t k = 1; k < track.size(); ++k) {
    run = track[k][i] == track[k - 1][i] ? run + 1 : 0;
    best = std::max(best, run);
  }
  return static_cast<float>(best) * dt;
}

// Agents far apart, each stopping 6 s at a waypoint halfway: every model
// holds each agent still there for the wait (to a step) and it arrives the
// wait later than the unhindered walk.
TEST(Journey, AWaitAtAWaypointHoldsTheAgentThatLong) {
  for (const ModelKind model : kModels) {
    SCOPED_TRACE(to_string(model));
    const std::vector<glm::vec2> starts = {{0.0f, 0.0f}, {0.0f, 30.0f}, {0.0f, 60.0f}};
    GoalSpec via = GoalSpec::at({10.0f, 0.0f});
    via.kind = GoalSpec::Kind::Offset;  // 10 m ahead of each
    via.wait_s = 6.0f;
    const ScenarioSpec s = walkers(model, starts, via);
    Simulation sim(s);
    std::vector<std::vector<glm::vec2>> track{sim.positions()};
    while (!sim.all_arrived() && sim.time() < 60.0) {
      sim.step();
      track.push_back(sim.positions());
    }
    ASSERT_TRUE(sim.all_arrived());
    const std::vector<float> arrived = sim.arrival_times();
    for (std::size_t i = 0; i < starts.size(); ++i) {
      const float stand = longest_stand(track, i, s.dt);
      EXPECT_GE(stand, 6.0f - s.dt - 1e-3f) << "agent " << i;
      EXPECT_LE(stand, 6.0f + s.dt + 1e-3f) << "agent " << i;
      const float walk = (20.0f - s.groups[0].arrival_radius) / kSpeed;
      EXPECT_GE(arrived[i], walk + 6.0f - 1.0f) << "agent " << i;
      EXPECT_LE(arrived[i], 20.0f / kSpeed * 1.1f + 6.0f) << "agent " << i;
    }
  }
}

// 40 agents in an 8 m square on an open field, on their way through a
// waiting area from (20, 0) to `corner` (5 s each) to (45, 3).
ScenarioSpec waiting_crowd(glm::vec2 corner) {
  ScenarioSpec s = test::open_field(40, {0, 0}, {8, 8}, {0, 0});
  GoalSpec area;
  area.kind = GoalSpec::Kind::Random;
  area.region.kind = Region::Kind::rect;
  area.region.min = {20, 0};
  area.region.max = corner;
  area.wait_s = 5.0f;
  s.groups[0].waypoints = {area};
  s.groups[0].goal = GoalSpec::at({45.0f, 3.0f});
  return s;
}

// A waiting area: 40 agents each drawn a spot of its own inside it (bodies
// at least 25 cm apart), all of them reach it, wait and walk on.
TEST(Journey, AWaitingAreaGivesEveryAgentASpotOfItsOwn) {
  ScenarioSpec s = waiting_crowd({26, 6});
  s.planning = PlanningKind::None;
  s.dt = 0.05f;
  s.duration = 120.0f;
  GroupSpec& g = s.groups[0];
  g.radius = 0.2f;
  g.arrival = ArrivalBehaviour::Despawn;
  g.arrival_radius = 1.0f;
  const CrowdHost h = test::spawn(s);
  std::vector<glm::vec2> spots;
  for (std::size_t i = 0; i < h.waypoint_begin.size(); ++i) {
    const glm::vec2 q = h.waypoints[static_cast<std::size_t>(h.waypoint_begin[i])];
    EXPECT_TRUE(q.x >= 20 && q.x <= 26 && q.y >= 0 && q.y <= 6);
    for (glm::vec2 other : spots) EXPECT_GE(length_of(q - other), 2.0f * g.radius + 0.25f);  // room to pass
    spots.push_back(q);
  }
  Simulation sim(s);
  std::vector<std::vector<glm::vec2>> track{sim.positions()};
  while (!sim.all_arrived() && sim.time() < 120.0) {
    sim.step();
    track.push_back(sim.positions());
  }
  EXPECT_TRUE(sim.all_arrived()) << sim.arrived_count() << " of " << sim.agent_count();
  // Each stood its 5 s within the arrival radius of its own spot.
  for (std::size_t i = 0; i < spots.size(); ++i) {
    std::size_t k = 1;
    while (k + 100 < track.size() && track[k + 100][i] != track[k][i]) ++k;
    ASSERT_LT(k + 100, track.size()) << "agent " << i << " never stood 5 s";
    EXPECT_LE(length_of(track[k][i] - spots[i]), g.arrival_radius) << "agent " << i;
  }
  // No one arrives before walking the 20 m there, waiting, and the 20 m on.
  for (float t : sim.arrival_times()) EXPECT_GE(t, 5.0f + 30.0f / 2.0f);
}

// An area too small for its crowd is refused, naming the waypoint.
TEST(Journey, AWaitingAreaWithoutRoomIsALocatedError) {
  const ScenarioSpec s = waiting_crowd({21, 1});
  const std::string e = test::spawn_error(s);
  EXPECT_NE(e.find("groups[0].waypoints[0].random"), std::string::npos) << e;
  EXPECT_NE(e.find("make the area larger"), std::string::npos) << e;
}

TEST(Journey, BadStagesAreLocatedErrors) {
  auto error_with = [](GoalSpec via, bool as_goal = false) {
    ScenarioSpec s = walkers(ModelKind::CollisionFreeSpeed, {{0.0f, 0.0f}}, GoalSpec::at({5.0f, 0.0f}));
    (as_goal ? s.groups[0].goal : s.groups[0].waypoints[0]) = via;
    return test::spawn_error(s);
  };
  GoalSpec nan_wait = GoalSpec::at({5.0f, 0.0f});
  nan_wait.wait_s = NAN;
  EXPECT_NE(error_with(nan_wait).find("groups[0].waypoints[0].wait"), std::string::npos);
  nan_wait.wait_s = -1.0f;
  EXPECT_NE(error_with(nan_wait).find("groups[0].waypoints[0].wait"), std::string::npos);
  EXPECT_NE(error_with(GoalSpec::gate({5, 0}, {5, 0.01f})).find("groups[0].waypoints[0].gate"), std::string::npos);
  EXPECT_NE(error_with(GoalSpec::gate({5, 0}, {5, NAN})).find("groups[0].waypoints[0].gate"), std::string::npos);
  EXPECT_NE(error_with(GoalSpec::gate({5, -1}, {5, 1}), true).find("groups[0].goal"), std::string::npos);
  GoalSpec waiting_goal = GoalSpec::at({5.0f, 0.0f});
  waiting_goal.wait_s = 3.0f;
  EXPECT_NE(error_with(waiting_goal, true).find("groups[0].goal.wait"), std::string::npos);
}

}  // namespace
}  // namespace throng::sim
