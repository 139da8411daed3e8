// Counterflow: the lane order parameter against hand-counted cases, then
// two opposing streams of 200 in a 4 m corridor under each model, dense
// (40 m blocks) and moderate (80 m blocks), with the lane order after 20 s,
// arrivals and progress speed reported (and bounded: see the figures in
// docs/simulation.md).
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

// A 4 m wide corridor; `per_side` agents walk east from a block `block` m
// long west of its middle, as many west from the mirrored block east of
// it, each block starting 18 m from the middle; each agent walks
// block + 20 m and leaves.
CounterflowRun counterflow(ModelKind model, std::int64_t per_side, float block, float duration,
                           std::uint64_t seed = 1) {
  ScenarioSpec s;
  s.name = "counterflow";
  s.seed = seed;
  s.model.kind = model;
  s.model.max_speed = 1.8f;  // dt * max_speed below 0.9 radius
  s.planning = PlanningKind::None;
  s.duration = duration;
  s.world.has_walkable = true;
  s.world.walkable.outer = {
      {-22.0f - block, 0.0f}, {22.0f + block, 0.0f}, {22.0f + block, 4.0f}, {-22.0f - block, 4.0f}};
  for (int side : {1, -1}) {
    GroupSpec g;
    g.count = per_side;
    g.radius = 0.2f;
    g.speed = {1.34f, 0.26f, 0.8f, 1.8f};
    g.spawn.kind = Region::Kind::rect;
    g.spawn.min = {side > 0 ? -18.0f - block : 18.0f, 0.3f};
    g.spawn.max = {side > 0 ? -18.0f : 18.0f + block, 3.7f};
    g.goal.kind = GoalSpec::Kind::Offset;
    g.goal.value = {(20.0f + block) * static_cast<float>(side), 0.0f};
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
  while (!sim.all_arrived() && sim.time() < s.duration) sim.step();
  const std::vector<float> arrival = sim.arrival_times();
  for (std::size_t i = 0; i < arrival.size(); ++i) {
    if (arrival[i] < 0.0f) continue;
    ++r.arrived;
    r.progress_speed += glm::length(goals[i] - start[i]) / arrival[i];
  }
  if (r.arrived > 0) r.progress_speed /= static_cast<double>(r.arrived);
  return r;
}

constexpr ModelKind kModels[] = {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc,
                                 ModelKind::SocialForce};

// Runs the counterflow from `block` m blocks under every model, prints each
// run, asserts that lanes form (the order is far above a mixed crowd's) and
// hands the run to check(model, run) for the rest.
template <class Check>
void run_every_model(float block, float duration, const Check& check) {
  const std::int64_t per_side = test::sanitized() ? 100 : 200;
  for (const ModelKind model : kModels) {
    SCOPED_TRACE(to_string(model));
    const CounterflowRun r = counterflow(model, per_side, block, duration);
    std::printf(
        "  %s, 2 x %lld from %.0f m blocks: lane order after 20 s %.2f, arrived %lld of %lld within %.0f s, mean "
        "progress speed %.2f m/s\n",
        to_string(model), static_cast<long long>(per_side), block, r.lane_order_20s, static_cast<long long>(r.arrived),
        static_cast<long long>(r.agents), duration, r.progress_speed);
    EXPECT_GE(r.lane_order_20s, 0.6);
    check(model, r);
  }
}

// Dense: 1.5 P/m^2 in each block, about 3 P/m^2 where the streams overlap.
// The collision-free speed, time-to-collision and social force models get
// everyone through; the priority model leaves a few swirling against the
// walls at 300 s.
TEST(Counterflow, DenseStreamsInAFourMetreCorridorPassEachOther) {
  run_every_model(40.0f, 300.0f, [](ModelKind model, const CounterflowRun& r) {
    EXPECT_GE(r.arrived, model == ModelKind::Priority ? r.agents * 97 / 100 : r.agents);
  });
}

// The dense run under the default model from other draws of the crowd
// (positions and free speeds). Whether the two streams lock face to face
// across the whole corridor is a chaotic outcome of the draw, so one seed
// says little, and a few dozen draws only estimate the share that lock:
// seeds 2-97 let everyone through in 84 of 96 draws both before and after
// the far look and the rule on neighbours behind the walked direction
// (seeds 2-193 after: 165 of 192), while seeds 2-25 alone went from 21 to
// 19 of 24. (Before walkers yielded to one abreast and the sideways push
// was strengthened, about half the draws locked.) The test asks at least
// 36 of seeds 2-49 (three in four; 43 measured) to let everyone through
// (under the sanitizers, 100 a side, 7 of seeds 2-9).
TEST(Counterflow, DenseStreamsPassEachOtherInMostDrawsOfTheCrowd) {
  const bool sanitized = test::sanitized();
  const std::int64_t per_side = sanitized ? 100 : 200;
  const std::uint64_t last = sanitized ? 9 : 49;
  int through = 0, draws = 0;
  for (std::uint64_t seed = 2; seed <= last; ++seed, ++draws) {
    const CounterflowRun r = counterflow(ModelKind::CollisionFreeSpeed, per_side, 40.0f, 300.0f, seed);
    std::printf("  collision_free_speed, seed %llu: arrived %lld of %lld within 300 s, mean progress speed %.2f m/s\n",
                static_cast<unsigned long long>(seed), static_cast<long long>(r.arrived),
                static_cast<long long>(r.agents), r.progress_speed);
    through += r.arrived == r.agents ? 1 : 0;
  }
  std::printf("  everyone through in %d of %d draws\n", through, draws);
  EXPECT_GE(through, sanitized ? 7 : 36);
}

// Moderate: 0.74 P/m^2 in each block, about 1.5 P/m^2 where the streams
// overlap, near the densities up to which Zhang et al. 2012 measured
// bidirectional streams keeping the unidirectional speed-density relation
// (docs/simulation.md). The collision-free speed and social force models
// keep 0.8 m/s of progress; the others are reported. Each agent walks
// 100 m here, so the run is given 400 s.
TEST(Counterflow, ModerateStreamsFormLanesAndKeepTheirPace) {
  run_every_model(80.0f, 400.0f, [](ModelKind model, const CounterflowRun& r) {
    EXPECT_EQ(r.arrived, r.agents);
    if (model == ModelKind::CollisionFreeSpeed || model == ModelKind::SocialForce) {
      EXPECT_GE(r.progress_speed, 0.8);
    }
  });
}

}  // namespace
}  // namespace throng::sim
