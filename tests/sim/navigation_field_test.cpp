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

namespace throng::sim {
namespace {

// The lines of equal distance of a field that is the straight distance to
// a point (closed form) are circles round it: every segment's ends lie on
// a circle of a radius the spacing divides, and each circle's segments add
// up to its circumference; no line crosses the blocked nodes.
TEST(FieldContours, ThePointFieldsLinesAreCirclesRoundTheTarget) {
  FieldData f;
  f.grid.origin = {-10.0f, -10.0f};
  f.grid.cell = 0.25f;
  f.grid.nx = f.grid.ny = 81;
  f.grid.target = {0.5f, -0.25f};
  for (std::int32_t j = 0; j < f.grid.ny; ++j)
    for (std::int32_t i = 0; i < f.grid.nx; ++i) {
      const glm::vec2 p = f.grid.origin + f.grid.cell * glm::vec2(static_cast<float>(i), static_cast<float>(j));
      // A blocked square (a pillar) at x 4-6, y 4-6.
      const bool blocked = p.x >= 4.0f && p.x <= 6.0f && p.y >= 4.0f && p.y <= 6.0f;
      f.distance.push_back(blocked ? INFINITY : length_of(p - f.grid.target));
    }
  NavigationFields fields;
  fields.add(f);
  fields.upload();
  const std::vector<std::vector<glm::vec2>> lines = field_contours(fields.host_view(), 0, 2.0f);
  double circumference[4] = {0, 0, 0, 0};  // radii 2, 4, 6, 8 (2 and 4 clear of the pillar, 5.5 m away)
  for (const std::vector<glm::vec2>& s : lines) {
    ASSERT_EQ(s.size(), 2u);
    const float r0 = length_of(s[0] - f.grid.target), r1 = length_of(s[1] - f.grid.target);
    const float level = 2.0f * std::round(r0 / 2.0f);
    EXPECT_NEAR(r0, level, 0.01f);
    EXPECT_NEAR(r1, level, 0.01f);
    for (const glm::vec2 q : s)
      EXPECT_FALSE(q.x > 4.0f && q.x < 6.0f && q.y > 4.0f && q.y < 6.0f) << q.x << ", " << q.y;
    const int k = static_cast<int>(level / 2.0f) - 1;
    if (k >= 0 && k < 4) circumference[k] += length_of(s[1] - s[0]);
  }
  for (int k = 0; k < 2; ++k)
    EXPECT_NEAR(circumference[k], 2.0 * 3.14159265 * 2.0 * (k + 1), 0.01 * 2.0 * (k + 1) * 6.3);
  EXPECT_THROW(field_contours(fields.host_view(), 0, 0.0f), Error);
  EXPECT_THROW(field_contours(fields.host_view(), 0, NAN), Error);
  EXPECT_THROW(field_contours(fields.host_view(), 0, 1e-4f), Error);       // under a hundredth of a cell
  EXPECT_EQ(field_contours(fields.host_view(), 0, 2.0f, 10).size(), 10u);  // capped
}

}  // namespace
}  // namespace throng::sim
