// Small encounters run through the whole simulation (head-on, crossing,
// four ways, a circle, a blind corner), shared by the tests of the steering
// models: each agent must arrive within a bound on its unhindered time
// without overlapping a neighbour by more than 1 cm.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/math.h"
#include "sim/metrics.h"
#include "sim/simulation.h"

namespace throng::sim::encounters {

struct Walker {
  glm::vec2 from, to;
  std::vector<glm::vec2> via;  // waypoints
};

inline ScenarioSpec encounter(const std::vector<Walker>& walkers, const WorldSpec& world, ModelKind model) {
  ScenarioSpec s;
  s.name = "encounter";
  s.model.kind = model;
  s.model.max_speed = 1.5f;  // dt * max_speed below 0.9 radius
  s.planning = PlanningKind::None;
  s.world = world;
  s.duration = 120.0f;
  for (const Walker& w : walkers) {
    GroupSpec g;
    g.count = 1;
    g.radius = 0.2f;
    g.speed = {1.3f, 0.0f, 1.3f, 1.3f};
    g.spawn.kind = Region::Kind::points;
    g.spawn.points = {w.from};
    for (glm::vec2 v : w.via) g.waypoints.push_back(GoalSpec::at(v));
    g.goal = GoalSpec::at(w.to);
    g.arrival = ArrivalBehaviour::Despawn;
    g.arrival_radius = 0.3f;
    s.groups.push_back(g);
  }
  return s;
}

inline double route_length(const Walker& w) {
  double d = 0;
  glm::vec2 at = w.from;
  for (glm::vec2 v : w.via) d += glm::length(v - at), at = v;
  return d + glm::length(w.to - at);
}

// Runs to arrival under `model`; every agent must arrive within `slowest` x
// its unhindered time (its route at 1.3 m/s, less the arrival radius; 1.5
// is the aim) and no pair may overlap by more than `deepest_allowed` (1 cm
// is the aim) at any step. Returns the slowest arrival over the unhindered
// time (+inf when someone never arrived).
inline double expect_encounter_resolves(ModelKind model, const std::string& what, const std::vector<Walker>& walkers,
                                        const WorldSpec& world = {}, double slowest = 1.5,
                                        float deepest_allowed = 0.01f) {
  SCOPED_TRACE(what);
  Simulation sim(encounter(walkers, world, model));
  float deepest = 0.0f;
  while (!sim.all_arrived() && sim.time() < 120.0) {
    sim.step();
    const CrowdState& c = sim.crowd();
    deepest =
        std::max(deepest, measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f, 1.0f).max_depth);
  }
  if (!sim.all_arrived()) {
    ADD_FAILURE() << "not everyone arrived after " << sim.time() << " s";
    return INFINITY;
  }
  const std::vector<float> times = sim.arrival_times();
  double worst = 0;
  for (std::size_t i = 0; i < walkers.size(); ++i)
    worst = std::max(worst, times[i] / ((route_length(walkers[i]) - 0.3) / 1.3));
  std::printf("  %s, %s: slowest arrival %.2fx the unhindered time, deepest overlap %.4f m\n", to_string(model),
              what.c_str(), worst, deepest);
  EXPECT_LE(worst, slowest);
  EXPECT_LE(deepest, deepest_allowed);
  return worst;
}

// Two walkers head-on on one line, 10 m apart.
inline std::vector<Walker> head_on_pair() { return {{{0, 0}, {10, 0}, {}}, {{10, 0}, {0, 0}, {}}}; }
// Two walkers crossing at 90 degrees, meeting in the middle.
inline std::vector<Walker> crossing_pair() { return {{{-6, 0}, {6, 0}, {}}, {{0, -6}, {0, 6}, {}}}; }
// Four walkers from the four sides, meeting in the middle.
inline std::vector<Walker> four_ways() {
  return {{{-6, 0}, {6, 0}, {}}, {{6, 0}, {-6, 0}, {}}, {{0, -6}, {0, 6}, {}}, {{0, 6}, {0, -6}, {}}};
}

// Twenty agents on a circle of radius 8 m, each walking to its antipode.
// `turn` (radians) rotates the whole circle: the twenty meet in the same way
// in exact arithmetic, but rounding differs, and a model whose outcome hangs
// on it is not robust.
inline std::vector<Walker> circle_of_twenty(float turn = 0.0f) {
  std::vector<Walker> w;
  for (int k = 0; k < 20; ++k) {
    const float a = turn + static_cast<float>(k) * 6.2831853f / 20.0f;
    const glm::vec2 p(8.0f * std::cos(a), 8.0f * std::sin(a));
    w.push_back({p, -p, {}});
  }
  return w;
}

// An L-shaped corridor 2 m wide: one walker comes from the west arm, one
// from the north arm; they meet at the corner without seeing each other.
inline WorldSpec l_corridor();
inline std::vector<Walker> blind_corner_pair();

// The circle of twenty under `model` laid out at `turns` turns of the ring
// `step` degrees apart (it repeats every 18 degrees), each held to `slowest`
// and `deepest`. Returns the slowest arrival of each layout (over the
// unhindered time), in turn order.
inline std::vector<double> expect_circle_resolves(ModelKind model, double slowest, float deepest = 0.01f, int turns = 4,
                                                  float step = 1.8f) {
  std::vector<double> worst;
  for (int k = 0; k < turns; ++k) {
    const float degrees = step * static_cast<float>(k);
    char what[48];
    std::snprintf(what, sizeof what, "circle of 20 turned %.2f degrees", static_cast<double>(degrees));
    worst.push_back(
        expect_encounter_resolves(model, what, circle_of_twenty(degrees * kPiF / 180.0f), {}, slowest, deepest));
  }
  return worst;
}

// The circle of twenty at `turns` layouts spread evenly over the ring's
// whole period (18 degrees / turns apart): whether a model's outcome hangs
// on rounding shows in the spread of these.
inline std::vector<double> expect_circle_resolves_round_the_ring(ModelKind model, int turns, double slowest,
                                                                 float deepest = 0.01f) {
  return expect_circle_resolves(model, slowest, deepest, turns, 18.0f / static_cast<float>(turns));
}

// The five standard encounters under `model`: head-on, crossing, four ways
// and the blind corner held to 1.5x (the aim), the circle of twenty (all
// meet at once: the hardest of them) to its own bounds, laid out at four
// turns of the circle (0-5.4 degrees; the ring repeats every 18).
inline void expect_standard_encounters_resolve(ModelKind model, double circle_slowest, float circle_deepest = 0.01f) {
  expect_encounter_resolves(model, "head-on", head_on_pair());
  expect_encounter_resolves(model, "crossing", crossing_pair());
  expect_encounter_resolves(model, "four ways", four_ways());
  expect_encounter_resolves(model, "blind corner", blind_corner_pair(), l_corridor());
  expect_circle_resolves(model, circle_slowest, circle_deepest);
}

inline WorldSpec l_corridor() {
  WorldSpec world;
  world.has_walkable = true;
  world.walkable.outer = {{-10, 0}, {2, 0}, {2, 12}, {0, 12}, {0, 2}, {-10, 2}};
  return world;
}
inline std::vector<Walker> blind_corner_pair() { return {{{-8, 1}, {1, 10}, {{1, 1}}}, {{1, 10}, {-8, 1}, {{1, 1}}}}; }

}  // namespace throng::sim::encounters
