// Counterflow: the lane order parameter against hand-counted cases, then
// two opposing streams of 200 in a 4 m corridor under each model, with the
// lane order after 20 s, arrivals and progress speed reported (and bounded:
// see the figures in docs/simulation.md).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "sim/crowd.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

constexpr std::uint8_t kActive = kAgentActive;

TEST(LaneOrder, SeparateLanesGiveOneAndAMixedLineGivesHalf) {
  const glm::vec2 east(1.0f, 0.0f);
  // Two lanes 1 m apart, band 0.3 m: everyone sees only its own direction.
  std::vector<glm::vec2> p, g;
  for (int k = 0; k < 5; ++k) {
    p.push_back({0.5f * static_cast<float>(k), 0.0f}), g.push_back({100.0f, 0.0f});
    p.push_back({0.5f * static_cast<float>(k), 1.0f}), g.push_back({-100.0f, 1.0f});
  }
  const LaneOrder lanes = lane_order(p, g, std::vector<std::uint8_t>(p.size(), kActive), east, 0.3f, 2.0f);
  EXPECT_DOUBLE_EQ(lanes.order, 1.0);
  EXPECT_EQ(lanes.counted, 10);
  // One line E E W W, 0.5 m apart, reach 0.75 m: the ends see one neighbour
  // of their own direction (phi 1), the middle two one of each (phi 0).
  const std::vector<glm::vec2> line = {{0.0f, 0.0f}, {0.5f, 0.0f}, {1.0f, 0.0f}, {1.5f, 0.0f}};
  const std::vector<glm::vec2> goals = {{9.0f, 0.0f}, {9.0f, 0.0f}, {-9.0f, 0.0f}, {-9.0f, 0.0f}};
  const LaneOrder mixed = lane_order(line, goals, std::vector<std::uint8_t>(4, kActive), east, 0.3f, 0.75f);
  EXPECT_DOUBLE_EQ(mixed.order, 0.5);
  // Inactive agents do not count, and an agent alone in its band is skipped.
  std::vector<std::uint8_t> flags(4, kActive);
  flags[1] = flags[2] = 0;
  const LaneOrder apart = lane_order(line, goals, flags, east, 0.3f, 0.75f);
  EXPECT_EQ(apart.counted, 0);
  EXPECT_DOUBLE_EQ(apart.order, 0.0);
}

struct CounterflowRun {
  double lane_order_20s = 0;
  Index arrived = 0, agents = 0;
  double progress_speed = 0;  // mean over arrived agents of start-to-goal distance / arrival time
};

// A 4 m x 120 m corridor; 200 agents walk east from its west half, 200 west
// from its east half, each 60 m, and leave at the far side.
CounterflowRun counterflow(ModelKind model, std::int64_t per_side) {
  ScenarioSpec s;
  s.name = "counterflow";
  s.model.kind = model;
  s.model.max_speed = 1.8f;  // dt * max_speed below 0.9 radius
  s.planning = PlanningKind::None;
  s.duration = 300.0f;
  s.world.has_walkable = true;
  s.world.walkable.outer = {{-62.0f, 0.0f}, {62.0f, 0.0f}, {62.0f, 4.0f}, {-62.0f, 4.0f}};
  for (int side : {1, -1}) {
    GroupSpec g;
    g.count = per_side;
    g.radius = 0.2f;
    g.speed = {1.34f, 0.26f, 0.8f, 1.8f};
    g.spawn.kind = Region::Kind::rect;
    g.spawn.min = {side > 0 ? -58.0f : 18.0f, 0.3f};
    g.spawn.max = {side > 0 ? -18.0f : 58.0f, 3.7f};
    g.goal.kind = GoalSpec::Kind::Offset;
    g.goal.value = {60.0f * static_cast<float>(side), 0.0f};
    g.arrival = ArrivalBehaviour::Despawn;
    s.groups.push_back(g);
  }
  Simulation sim(s);
  const std::vector<glm::vec2> start = sim.positions();
  const std::vector<glm::vec2> goals = sim.crowd().goal.to_vector();
  CounterflowRun r;
  r.agents = sim.agent_count();
  while (sim.steps_done() < 200) sim.step();
  r.lane_order_20s =
      lane_order(sim.positions(), sim.crowd().goal.to_vector(), sim.flags(), {1.0f, 0.0f}, 0.3f, 5.0f).order;
  while (!sim.all_arrived() && sim.time() < 300.0) sim.step();
  const std::vector<float> arrival = sim.arrival_times();
  for (std::size_t i = 0; i < arrival.size(); ++i) {
    if (arrival[i] < 0.0f) continue;
    ++r.arrived;
    r.progress_speed += glm::length(goals[i] - start[i]) / arrival[i];
  }
  if (r.arrived > 0) r.progress_speed /= static_cast<double>(r.arrived);
  return r;
}

TEST(Counterflow, StreamsInAFourMetreCorridorPassEachOther) {
  const std::int64_t per_side = test::sanitized() ? 100 : 200;
  for (const ModelKind model :
       {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce}) {
    SCOPED_TRACE(to_string(model));
    const CounterflowRun r = counterflow(model, per_side);
    std::printf(
        "  %s, 2 x %lld: lane order after 20 s %.2f, arrived %lld of %lld within 300 s, mean progress speed %.2f m/s\n",
        to_string(model), static_cast<long long>(per_side), r.lane_order_20s, static_cast<long long>(r.arrived),
        static_cast<long long>(r.agents), r.progress_speed);
    // Lanes form under every model (the order is far above a mixed crowd's).
    // The collision-free speed, time-to-collision and social force models
    // get everyone through; the priority model leaves a few swirling against
    // the walls at 300 s. Only the social force model reaches the 0.8 m/s of
    // progress of real counterflows (figures in docs/simulation.md).
    EXPECT_GE(r.lane_order_20s, 0.6);
    EXPECT_GE(r.arrived, model == ModelKind::Priority ? r.agents * 97 / 100 : r.agents);
  }
}

}  // namespace
}  // namespace throng::sim
