// Small scenarios built in C++ for the sim tests (the YAML built-ins live in
// io/ and are tested there).
#pragma once

#include <glm/common.hpp>

#include "sim/scenario.h"

namespace throng::sim::test {

// N agents evenly on a circle (1 m apart) walking to their antipodes.
inline ScenarioSpec circle_spec(std::int64_t n, std::uint64_t seed = 1) {
  ScenarioSpec s;
  s.name = "circle";
  s.dt = 0.1f;
  s.seed = seed;
  GroupSpec g;
  g.name = "ring";
  g.count = n;
  g.radius = 0.25f;
  g.speed = {1.3f, 0.1f, 1.0f, 1.6f};
  g.spawn.kind = Region::Kind::ring;
  g.spawn.spacing = 1.0f;
  GoalSpec goal;
  goal.kind = GoalSpec::Kind::Mirror;
  goal.value = glm::vec2(0.0f);
  g.goal = goal;
  g.arrival = ArrivalBehaviour::Stop;
  s.groups = {g};
  return s;
}

// Two perpendicular flows through a walled crossroads.
inline ScenarioSpec crossing_spec(std::int64_t n_per_flow, std::uint64_t seed = 1) {
  ScenarioSpec s;
  s.name = "crossing";
  s.dt = 0.1f;
  s.seed = seed;
  // Four square blocks leave a cross-shaped street 20 m wide.
  const float w = 10.0f, L = 80.0f;
  for (int sx : {-1, 1})
    for (int sy : {-1, 1}) {
      const glm::vec2 a(sx * w, sy * w), b(sx * L, sy * L);
      s.world.polygons.push_back({rect_ring(glm::min(a, b), glm::max(a, b)), {}});
    }
  auto flow = [&](glm::vec2 min, glm::vec2 max, glm::vec2 offset, const char* name) {
    GroupSpec g;
    g.name = name;
    g.count = n_per_flow;
    g.radius = 0.25f;
    g.speed = {1.3f, 0.15f, 0.9f, 1.7f};
    g.spawn.kind = Region::Kind::rect;
    g.spawn.min = min;
    g.spawn.max = max;
    GoalSpec goal;
    goal.kind = GoalSpec::Kind::Offset;
    goal.value = offset;
    g.goal = goal;
    g.arrival = ArrivalBehaviour::Despawn;
    return g;
  };
  s.groups = {flow({-75.0f, -9.0f}, {-15.0f, 9.0f}, {90.0f, 0.0f}, "east"), flow({-9.0f, -75.0f}, {9.0f, -15.0f}, {0.0f, 90.0f}, "north")};
  return s;
}

}  // namespace throng::sim::test
