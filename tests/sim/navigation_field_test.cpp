// Navigation fields in the simulation (`planning: field`), run as `throng
// run` runs a scenario (io::build_simulation):
// - a crowd leaves a room through a 4.2 m x 31 m channel to a point 70 m
//   beyond: everyone arrives, under the collision-free speed model within
//   1.5x of the time the channel's capacity allows (N / (1.3 P/(m s) x
//   4.2 m)) plus the longest free walk (the farthest agent's walking
//   distance at its own speed), under the others at all;
// - 20 agents walk round the corner of an L-shaped corridor (RiMEA 3.0
//   test 6): all arrive, none enters a wall;
// - the same bits on 1, 2 and 4 threads.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/exec.h"
#include "io/scenario_yaml.h"
#include "path/distance_field.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/same_bits_on_threads.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// The room (40 x 30 m), the channel and the open area beyond; `agents` of
// radius 0.25 m walk to (141, 15).
std::string channel_yaml(const char* model, std::int64_t agents) {
  return "name: channel\nseed: 1\ndt: 0.1\nduration: 900\nstop_when_arrived: true\nplanning: field\n"
         "model: {type: " +
         std::string(model) +
         "}\n"
         "world:\n  walkable: {polygon: [[0, 0], [40, 0], [40, 12.9], [71, 12.9], [71, 0], [151, 0], [151, 30],\n"
         "    [71, 30], [71, 17.1], [40, 17.1], [40, 30], [0, 30]]}\n"
         "groups:\n  - name: crowd\n    count: " +
         std::to_string(agents) +
         "\n    radius: 0.25\n    speed: {mean: 1.3, stddev: 0.15, min: 0.9, max: 1.7}\n"
         "    spawn: {rect: {min: [1, 1], max: [39, 29]}}\n    goal: {point: [141, 15]}\n    on_arrival: despawn\n";
}

struct Outcome {
  Index agents = 0, arrived = 0, max_penetrations = 0;
  double seconds = 0, longest_free_walk = 0;  // s
  double longest_distance = 0;                // m: the farthest agent's walk
};

Outcome run(const std::string& yaml, const char* name) {
  const io::LoadedScenario l = io::parse_scenario(yaml, name);
  const auto sim = io::build_simulation(l);
  Outcome o;
  o.agents = sim->agent_count();
  EXPECT_EQ(sim->fields().count(), 1);
  // The longest free walk: each agent's walking distance at its own speed,
  // the distance from a field without the walls' slowness (first order: a
  // few per cent long on diagonals).
  path::DistanceFieldOptions plain;
  plain.wall_cost = 0.0f;
  const FieldData f =
      path::build_distance_field(path::FreeSpace::build(sim->world()), sim->fields().grid(0).target, 0.25f, plain);
  const std::vector<glm::vec2> p = sim->positions();
  const std::vector<float> speed = sim->crowd().pref_speed.to_vector();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto gi = static_cast<std::size_t>(std::lround((p[i].x - f.grid.origin.x) / f.grid.cell));
    const auto gj = static_cast<std::size_t>(std::lround((p[i].y - f.grid.origin.y) / f.grid.cell));
    const float d = f.distance[gj * static_cast<std::size_t>(f.grid.nx) + gi];
    if (!(d < INFINITY)) continue;
    o.longest_free_walk = std::max(o.longest_free_walk, static_cast<double>(d / speed[i]));
    o.longest_distance = std::max(o.longest_distance, static_cast<double>(d));
  }
  const std::int64_t steps = l.spec.step_count();
  for (std::int64_t s = 0; s < steps && !sim->all_arrived(); ++s) {
    sim->step();
    const CrowdState& c = sim->crowd();
    o.max_penetrations =
        std::max(o.max_penetrations,
                 count_obstacle_penetrations(sim->world(), c.position.span(), c.radius.span(), c.flags.span(), 1e-3f));
  }
  o.arrived = sim->arrived_count();
  o.seconds = sim->time();
  return o;
}

TEST(NavigationField, EveryoneThroughTheChannelWithinItsCapacityBound) {
  const std::int64_t n = test::sanitized() ? 300 : 1000;
  const Outcome o = run(channel_yaml("collision_free_speed", n), "channel.yaml");
  const double capacity = static_cast<double>(n) / (1.3 * 4.2);
  const double bound = 1.5 * (capacity + o.longest_free_walk);
  std::printf(
      "  channel, %lld agents, collision-free speed: %lld arrived, the last after %.1f s; bound 1.5 x (%.1f + "
      "%.1f) = %.1f s\n",
      static_cast<long long>(n), static_cast<long long>(o.arrived), o.seconds, capacity, o.longest_free_walk, bound);
  EXPECT_EQ(o.arrived, n);
  EXPECT_LE(o.seconds, bound);
  // Tighter: the farthest walk at the crowd's mean speed, 1.3 m/s.
  const double at_mean = 1.5 * (capacity + o.longest_distance / 1.3);
  std::printf("  the farthest walk, %.1f m, at 1.3 m/s: bound %.1f s\n", o.longest_distance, at_mean);
  EXPECT_LE(o.seconds, at_mean);
  EXPECT_EQ(o.max_penetrations, 0);
}

TEST(NavigationField, EveryModelGetsEveryoneThroughTheChannel) {
  const std::int64_t n = test::sanitized() ? 150 : 500;
  for (const char* model : {"priority", "ttc", "social_force"}) {
    const Outcome o = run(channel_yaml(model, n), "channel.yaml");
    std::printf("  channel, %lld agents, %s: %lld arrived, the last after %.1f s\n", static_cast<long long>(n), model,
                static_cast<long long>(o.arrived), o.seconds);
    EXPECT_EQ(o.arrived, n) << model;
    EXPECT_EQ(o.max_penetrations, 0) << model;
  }
}

// RiMEA 3.0 test 6 as JuPedSim's notebook builds it: an L-shaped corridor
// 2 m wide, (0,0)-(12,0)-(12,12)-(10,12)-(10,2)-(0,2); 20 people in its
// first 6 m walk round the left corner to its top end and must all get
// round without passing through the walls.
std::string corner_yaml(const char* model) {
  return "name: corner\nseed: 1\ndt: 0.05\nduration: 120\nstop_when_arrived: true\nplanning: field\n"
         "model: {type: " +
         std::string(model) +
         "}\n"
         "world:\n  walkable: {polygon: [[0, 0], [12, 0], [12, 12], [10, 12], [10, 2], [0, 2]]}\n"
         "groups:\n  - name: walkers\n    count: 20\n    radius: 0.25\n    speed: {mean: 1.34, stddev: 0.05, min: "
         "1.2, max: 1.5}\n"
         "    spawn: {rect: {min: [0.3, 0.3], max: [6, 1.7]}}\n    goal: {point: [11, 11.4]}\n"
         "    on_arrival: despawn\n";
}

TEST(NavigationField, TwentyRoundACornerAllArrive) {
  for (const char* model : {"collision_free_speed", "priority", "ttc", "social_force"}) {
    const Outcome o = run(corner_yaml(model), "corner.yaml");
    std::printf("  corner, %s: %lld of 20 arrived, the last after %.1f s\n", model, static_cast<long long>(o.arrived),
                o.seconds);
    EXPECT_EQ(o.arrived, 20) << model;
    EXPECT_EQ(o.max_penetrations, 0) << model;
  }
}

TEST(NavigationField, SameBitsOnAnyThreadCount) {
  const io::LoadedScenario l = io::parse_scenario(corner_yaml("collision_free_speed"), "corner.yaml");
  test::expect_same_bits_on_threads(l, 300);
}

}  // namespace
}  // namespace throng::sim
