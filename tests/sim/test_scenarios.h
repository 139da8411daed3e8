// Scenarios for the sim tests: the built-ins (examples/*.yaml, embedded in
// throng_io), so tests run exactly what `throng run NAME` runs, plus tiny
// hand-made worlds for unit cases.
#pragma once

#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/scenario_yaml.h"
#include "sim/crowd.h"
#include "sim/scenario.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace throng::sim::test {

// A built-in scenario, resized to `agents` in all (0 = as shipped).
inline ScenarioSpec builtin(std::string_view name, std::int64_t agents = 0) {
  ScenarioSpec s = io::load_builtin_scenario(name).spec;
  if (agents > 0) scale_agent_counts(s, agents);
  return s;
}

// The simulation `throng run` builds for `spec` (io::build_simulation: the
// route planner or navigation fields its `planning` asks for).
inline std::unique_ptr<Simulation> as_run(const ScenarioSpec& spec, const SimulationOptions& options = {}) {
  io::LoadedScenario l;
  l.spec = spec;
  return io::build_simulation(l, options);
}

// One group of `count` agents in a rect walking by `offset`, in an empty world.
inline ScenarioSpec open_field(std::int64_t count, glm::vec2 min, glm::vec2 max, glm::vec2 offset) {
  ScenarioSpec s;
  s.name = "field";
  GroupSpec g;
  g.count = count;
  g.spawn.kind = Region::Kind::rect;
  g.spawn.min = min;
  g.spawn.max = max;
  g.goal.kind = GoalSpec::Kind::Offset;
  g.goal.value = offset;
  s.groups = {g};
  return s;
}

// An empty scenario under `model` without route planning (groups walk
// straight at their goals).
inline ScenarioSpec straight_spec(const char* name, ModelKind model, float dt, float duration) {
  ScenarioSpec s;
  s.name = name;
  s.model.kind = model;
  s.planning = PlanningKind::None;
  s.dt = dt;
  s.duration = duration;
  return s;
}

// An empty scenario for the validation runs: the collision-free speed
// model, no route planning (groups walk straight at their goals), and the
// walkable region `outer`.
inline ScenarioSpec collision_free_spec(const char* name, float dt, float duration, Ring outer) {
  ScenarioSpec s = straight_spec(name, ModelKind::CollisionFreeSpeed, dt, duration);
  s.world.has_walkable = true;
  s.world.walkable.outer = std::move(outer);
  return s;
}

// The two vectors hold the same bits (determinism across thread counts).
template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// True when THRONG_SANITIZED is set (CI's ASan+UBSan run, several times slower).
inline bool sanitized() {
  const char* v = std::getenv("THRONG_SANITIZED");
  return v != nullptr && *v != '\0' && std::string_view(v) != "0";
}

// The crowd spawn_crowd places for `spec` in its own world.
inline CrowdHost spawn(const ScenarioSpec& spec) {
  return spawn_crowd(spec, World::build(spec.world, spec.model.query_radius()));
}

// Copies the state one step reads (positions, velocities, headings, flags,
// legs) from one simulation's crowd to another's of the same spec: both then
// step from the same state.
inline void copy_step_state(CrowdState& to, const CrowdState& from) {
  auto copy = [](auto& dst, const auto& src) { dst.copy_from(src.to_vector()); };
  copy(to.position, from.position);
  copy(to.velocity, from.velocity);
  copy(to.heading, from.heading);
  copy(to.flags, from.flags);
  copy(to.goal, from.goal);
  copy(to.path_start, from.path_start);
  copy(to.waypoint_cursor, from.waypoint_cursor);
}

// The message of the Error spawning `spec` throws, or "no error".
inline std::string spawn_error(const ScenarioSpec& spec) {
  try {
    spawn(spec);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace throng::sim::test
