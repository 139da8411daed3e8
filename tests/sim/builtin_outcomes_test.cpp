// Outcomes of every built-in scenario (examples/*.yaml, as `throng run NAME`
// runs them: io::load_builtin_scenario + io::build_simulation, so with the
// route planner where the file asks for it), resized to a few hundred agents
// and run to the scenario's end. At every step: every position finite, no
// agent in an obstacle, no overlap beyond the model's bound, no agent stuck
// (StuckTracker: at rest over 5 s with the way ahead free). At the end:
// measurable progress towards the goals, and where the scenario ends with
// its agents at their goals, the arrivals.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>

#include "io/scenario_yaml.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// The model's bounds, as in the acceptance runs (simulation_test.cpp,
// docs/simulation.md): agents are discs of radius 0.25 m; no two overlap by
// more than 8 cm (a third of the radius) at any step, and pairs deeper than
// 5 cm are at most 0.5% of the agents. Penetration: 1 mm of float error.
constexpr float kOverlapLimit = 0.08f;
constexpr float kOverlapTolerance = 0.05f;
constexpr double kDeepPairFraction = 0.005;
constexpr float kPenetrationTolerance = 1e-3f;
// Progress is measured over the first kProgressSeconds of each run (or the
// whole run when it is shorter): the plaza ships with 30 s.
constexpr double kProgressSeconds = 30.0;
// An agent is "advancing" when it gained at least half the distance it
// would walk unhindered in that time.
constexpr double kAdvancing = 0.5;

// What each built-in must achieve, at the size it is run with (fewer agents
// under the sanitizers, test::sanitized()):
//   progress  the mean, over agents, of the distance gained towards the goal
//             in the first kProgressSeconds divided by the distance the agent
//             would walk unhindered at its preferred speed in that time (an
//             agent that arrived counts its whole start distance);
//   advancing the fraction of agents whose own ratio is at least kAdvancing
//             (nullopt where a queue holds most agents back by design);
//   arrived   the fraction of agents at their goal when the run ends (it ends
//             at the scenario's duration, or when all have arrived where the
//             scenario says so); nullopt where the scenario's clock ends long
//             before a walk across it could (then progress is the outcome).
// The bounds come from runs of seeds 1 to 4 (the test runs the scenario's
// seed, 1) and sit about 20% below the lowest seen; the figures are in the
// comment of each entry (Release, double buffer as shipped).
struct Size {
  std::int64_t agents = 200;
  double progress = 0.5;
  std::optional<double> advancing;
};
struct Expectation {
  Size full, sanitized;
  std::optional<double> arrived;
};

const std::map<std::string, Expectation>& expectations() {
  static const std::map<std::string, Expectation> e = {
      // Half the room, to keep the test short. As shipped (300) the door
      // jam of the double buffer reached 3.9 to 7.8 cm (seeds 1-5) before
      // the extra contact passes, 2.8 to 3.8 cm with them. 150: all leave by 169-193 s of 900 s; progress
      // 0.257-0.302 (most wait in the queue at the door); deepest overlap
      // 3.0-4.4 cm, no pair deeper than 5 cm. 60: all by 94-125 s, progress
      // 0.373-0.426, 1.5-3.7 cm.
      {"bottleneck", {{150, 0.20, std::nullopt}, {60, 0.28, std::nullopt}, 1.0}},
      // All stop at their antipodes by 110-120 s of 900 s; progress
      // 0.746-0.757, every agent advancing; deepest 4.0-5.2 cm, at most one
      // pair deeper than 5 cm (0.5% of 200). Smaller rings (100, 150) have
      // one such pair in most seeds, over 0.5% of their size, so the
      // sanitizers run the same 200 (about 1,100 steps).
      {"circle", {{200, 0.60, 0.9}, {200, 0.60, 0.9}, 1.0}},
      // 100 each way. As shipped (300) one seed of four has 2 pairs deeper
      // than 5 cm (over 0.5%). 200: all leave by 112-151 s of 600 s; progress
      // 0.810-0.839, advancing 0.970-0.980; deepest 3.9-4.7 cm. 100:
      // progress 0.929-0.952, all advancing, 1.2-2.0 cm.
      {"corridor", {{200, 0.65, 0.85}, {100, 0.75, 0.9}, 1.0}},
      // 300 (150): all leave by 155-165 s of 900 s; progress 0.972-0.978
      // (0.978-0.982), all advancing; deepest overlap under 4 mm.
      {"crossing", {{300, 0.85, 0.9}, {150, 0.85, 0.9}, 1.0}},
      // As shipped (100; 60): all cross by 197-201 s (159-165 s) of the
      // 400 s, seeds 1-4; those pushed back behind a wall corner after
      // passing a waypoint are planned again (sim/replanning.h; before it,
      // 98-100 of 100 crossed). Progress 0.264-0.289 (0.318-0.336): the
      // routes wind through the gaps; deepest 2.9 cm.
      {"maze", {{100, 0.20, std::nullopt}, {60, 0.25, std::nullopt}, 1.0}},
      // 30 s is about 39 m of a mean 620 m walk: 0-5 agents arrive, so
      // progress is the outcome. Walking straight at the goal (`planning:
      // none`): 0.895-0.907 (300: 0.879-0.909), advancing 0.938-0.950
      // (0.927-0.960; the rest walk round obstacles or arrived within a few
      // metres). On roadmap routes, as shipped: 0.937, advancing 0.996
      // (seed 1); deepest overlap 1 mm.
      {"plaza", {{1000, 0.75, 0.85}, {300, 0.75, 0.85}, std::nullopt}},
  };
  return e;
}

// A new built-in is run with these until it gets its own entry.
const Expectation kDefault{{200, 0.5, std::nullopt}, {100, 0.5, std::nullopt}, 0.95};

struct Outcome {
  Index agents = 0, arrived = 0, active_end = 0;
  std::int64_t steps = 0;
  double seconds = 0;
  Index non_finite = 0;                // agent-steps with a non-finite position
  Index max_penetrations = 0;          // most agents in an obstacle at one step
  std::int64_t penetration_steps = 0;  // steps with any
  float max_overlap_depth = 0.0f;
  Index max_deep_pairs = 0;
  double start_distance = 0;  // mean distance to the final goal at the start
  double end_distance = 0;    // at the end (arrived agents: 0)
  double progress = 0;        // see Expectation::progress
  double advancing = 0;       // fraction of agents whose own progress is at least kAdvancing
  double moved = 0;           // mean distance between start and end positions
  double progress_seconds = 0;
  Index expected_active = 0;  // agents that should still be active: all but those arrived in a despawn group
  StuckStats stuck;
};

// Each agent's final goal (the waypoint whose arrival counts as arriving).
std::vector<glm::vec2> final_goals(const CrowdState& c) {
  const auto waypoints = c.waypoints.to_vector();
  const auto begin = c.waypoint_begin.to_vector();
  const auto goal = c.waypoint_goal.to_vector();
  std::vector<glm::vec2> g(begin.size());
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = waypoints[static_cast<std::size_t>(begin[i] + goal[i])];
  return g;
}

// Distance of each agent to its final goal; 0 once it has arrived.
std::vector<double> remaining(const Simulation& sim, const std::vector<glm::vec2>& goals) {
  const auto p = sim.positions();
  const auto f = sim.flags();
  std::vector<double> d(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    d[i] = (f[i] & kAgentArrived) != 0 ? 0.0 : static_cast<double>(length_of(goals[i] - p[i]));
  return d;
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

Outcome run_builtin(const std::string& name, std::int64_t agents) {
  io::LoadedScenario l = io::load_builtin_scenario(name);
  if (agents < l.spec.total_agents()) scale_agent_counts(l.spec, agents);
  const auto sim = io::build_simulation(l);
  Outcome r;
  r.agents = sim->agent_count();
  const CrowdState& c = sim->crowd();
  const std::vector<glm::vec2> goals = final_goals(c);
  const std::vector<glm::vec2> start = sim->positions();
  const std::vector<double> d0 = remaining(*sim, goals);
  const auto pref = c.pref_speed.to_vector();
  r.start_distance = mean_of(d0);
  auto progress_now = [&] {
    const std::vector<double> d = remaining(*sim, goals);
    double sum = 0;
    Index advancing = 0;
    for (std::size_t i = 0; i < d.size(); ++i) {
      const double p = (d0[i] - d[i]) / (static_cast<double>(pref[i]) * sim->time());
      sum += p;
      advancing += p >= kAdvancing ? 1 : 0;
    }
    r.progress = sum / static_cast<double>(d.size());
    r.advancing = static_cast<double>(advancing) / static_cast<double>(d.size());
    r.progress_seconds = sim->time();
  };
  const std::int64_t steps = l.spec.step_count();
  const auto progress_step = static_cast<std::int64_t>(std::lround(kProgressSeconds / static_cast<double>(l.spec.dt)));
  bool progress_taken = false;
  StuckTracker stuck;
  while (r.steps < steps && !(l.spec.stop_when_arrived && sim->all_arrived())) {
    sim->step();
    ++r.steps;
    for (const glm::vec2 p : sim->positions()) r.non_finite += std::isfinite(p.x) && std::isfinite(p.y) ? 0 : 1;
    const Index pen = count_obstacle_penetrations(sim->world(), c.position.span(), c.radius.span(), c.flags.span(),
                                                  kPenetrationTolerance);
    r.max_penetrations = std::max(r.max_penetrations, pen);
    r.penetration_steps += pen > 0 ? 1 : 0;
    const OverlapStats o =
        measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), kOverlapTolerance, sim->contact_cell());
    r.max_overlap_depth = std::max(r.max_overlap_depth, o.max_depth);
    r.max_deep_pairs = std::max(r.max_deep_pairs, o.pairs);
    stuck.update(*sim);
    if (r.steps == progress_step) {
      progress_now();
      progress_taken = true;
    }
  }
  if (!progress_taken && r.steps > 0) progress_now();
  r.end_distance = mean_of(remaining(*sim, goals));
  r.arrived = sim->arrived_count();
  r.active_end = sim->active_count();
  const auto group = c.group.to_vector();
  const auto flags = sim->flags();
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const bool left = (flags[i] & kAgentArrived) != 0 &&
                      l.spec.groups[static_cast<std::size_t>(group[i])].arrival == ArrivalBehaviour::Despawn;
    r.expected_active += left ? 0 : 1;
  }
  r.stuck = stuck.stats();
  r.seconds = sim->time();
  const auto end = sim->positions();
  for (std::size_t i = 0; i < end.size(); ++i) r.moved += static_cast<double>(length_of(end[i] - start[i]));
  r.moved /= static_cast<double>(std::max<std::size_t>(1, end.size()));
  return r;
}

class BuiltinOutcome : public ::testing::TestWithParam<std::string> {};

TEST_P(BuiltinOutcome, RunsToItsEndWithProgressArrivalsAndNoCollisions) {
  const std::string name = GetParam();
  const auto it = expectations().find(name);
  if (it == expectations().end())
    std::printf("  %s has no entry in expectations(): default bounds (measure it and add one)\n", name.c_str());
  const Expectation& e = it == expectations().end() ? kDefault : it->second;
  const Size& size = test::sanitized() ? e.sanitized : e.full;
  const std::int64_t n = size.agents;
  const Outcome r = run_builtin(name, n);
  std::printf(
      "  %s, %lld agents: %lld steps (%.0f s), arrived %lld, active at the end %lld; mean distance to goal %.1f -> "
      "%.1f m, "
      "progress %.3f over %.0f s, advancing %.3f, moved %.1f m; deepest overlap %.4f m, deep pairs at most %lld; "
      "penetrations at most %lld\n",
      name.c_str(), static_cast<long long>(r.agents), static_cast<long long>(r.steps), r.seconds,
      static_cast<long long>(r.arrived), static_cast<long long>(r.active_end), r.start_distance, r.end_distance,
      r.progress, r.progress_seconds, r.advancing, r.moved, static_cast<double>(r.max_overlap_depth),
      static_cast<long long>(r.max_deep_pairs), static_cast<long long>(r.max_penetrations));
  std::string stuck_where;
  for (const StuckExample& x : r.stuck.examples)
    stuck_where +=
        fmt::format(" agent {} at {:.1f} s at ({:.2f}, {:.2f});", x.agent, x.time, x.position.x, x.position.y);
  std::printf("  %s stuck agents: %lld (at most %lld at once, first at %.1f s)%s\n", name.c_str(),
              static_cast<long long>(r.stuck.agents), static_cast<long long>(r.stuck.max_at_once), r.stuck.first_time,
              stuck_where.c_str());
  EXPECT_EQ(r.agents, std::min<std::int64_t>(n, io::load_builtin_scenario(name).spec.total_agents()));
  EXPECT_GT(r.steps, 0);
  EXPECT_EQ(r.non_finite, 0);
  EXPECT_EQ(r.max_penetrations, 0) << "in " << r.penetration_steps << " steps";
  EXPECT_EQ(r.stuck.agents, 0) << stuck_where;
  EXPECT_LT(r.max_overlap_depth, kOverlapLimit);
  EXPECT_LE(static_cast<double>(r.max_deep_pairs), kDeepPairFraction * static_cast<double>(r.agents));
  EXPECT_GT(r.moved, 0.0);
  EXPECT_LT(r.end_distance, r.start_distance);
  EXPECT_GE(r.progress, size.progress);
  if (size.advancing) {
    EXPECT_GE(r.advancing, *size.advancing);
  }
  if (e.arrived) {
    EXPECT_GE(static_cast<double>(r.arrived), *e.arrived * static_cast<double>(r.agents));
  }
  // Arrived agents of despawn groups left; everyone else is still there
  // (stopped at the goal, or walking back along a loop).
  EXPECT_EQ(r.active_end, r.expected_active);
}

INSTANTIATE_TEST_SUITE_P(Builtins, BuiltinOutcome, ::testing::ValuesIn(io::builtin_scenario_names()),
                         [](const ::testing::TestParamInfo<std::string>& p) { return p.param; });

}  // namespace
}  // namespace throng::sim
