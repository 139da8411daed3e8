// People arriving over time (inflow): each agent enters at its scheduled
// time where its point is free, never onto another agent; a crowded
// entrance holds the rest back until there is room; every agent gets in
// and through; the same bits for any thread count and both schedulers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/exec.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// A 4 m x 40 m corridor; `count` agents enter in the `entrance` rect at its
// west end and walk 36 m east, leaving the scene at the end.
ScenarioSpec corridor(std::int64_t count, InflowSpec inflow, glm::vec2 entrance_max) {
  ScenarioSpec s = test::collision_free_spec("inflow", 0.05f, 200.0f, {{0, 0}, {40, 0}, {40, 4}, {0, 4}});
  GroupSpec g;
  g.count = count;
  g.radius = 0.2f;
  g.speed = {1.34f, 0.26f, 0.8f, 1.8f};
  g.spawn.kind = Region::Kind::rect;
  g.spawn.min = {0.3f, 0.3f};
  g.spawn.max = entrance_max;
  g.goal.kind = GoalSpec::Kind::Offset;
  g.goal.value = {36.0f, 0.0f};
  g.arrival = ArrivalBehaviour::Despawn;
  g.inflow = inflow;
  s.groups = {g};
  return s;
}

InflowSpec at_rate(float rate, float from) {
  InflowSpec in;
  in.enabled = true;
  in.rate = rate;
  in.from = from;
  return in;
}

struct EntryRun {
  std::vector<double> entered;  // s: the step start at which each agent entered (-1: never)
  float deepest = 0.0f;         // deepest overlap at any step
  bool all_arrived = false;
};

// Runs to the end, noting when each agent turns active and the deepest
// overlap after every step.
EntryRun run(const ScenarioSpec& s) {
  Simulation sim(s);
  EntryRun r;
  r.entered.assign(static_cast<std::size_t>(sim.agent_count()), -1.0);
  EXPECT_EQ(sim.active_count(), 0);
  EXPECT_EQ(sim.pending_count(), sim.agent_count());
  while (!sim.all_arrived() && sim.time() < s.duration) {
    const double t0 = sim.time();
    sim.step();
    const std::vector<std::uint8_t> f = sim.flags();
    for (std::size_t i = 0; i < f.size(); ++i)
      if (r.entered[i] < 0 && (f[i] & (kAgentActive | kAgentArrived)) != 0) r.entered[i] = t0;
    const CrowdState& c = sim.crowd();
    r.deepest =
        std::max(r.deepest, measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f, 1.0f).max_depth);
  }
  r.all_arrived = sim.all_arrived();
  EXPECT_EQ(sim.pending_count(), 0);
  return r;
}

// A wide entrance and a slow rate: every agent enters in the step that
// starts at its scheduled time, from + k / rate.
TEST(Inflow, AgentsEnterOnScheduleWhereThereIsRoom) {
  const InflowSpec in = at_rate(1.0f, 2.0f);
  const ScenarioSpec s = corridor(20, in, {3.0f, 3.7f});
  const EntryRun r = run(s);
  EXPECT_TRUE(r.all_arrived);
  for (std::size_t k = 0; k < r.entered.size(); ++k) {
    const double due = std::ceil(in.entry_time(static_cast<std::int64_t>(k)) / s.dt - 1e-6) * s.dt;
    EXPECT_NEAR(r.entered[k], due, 1e-4) << "agent " << k;
  }
  EXPECT_LE(r.deepest, 0.01f);
}

// A 0.5 m x 0.5 m entrance asked for 10 P/s: far more than can stand there,
// so agents wait for room. None enters before its time or onto anyone (no
// overlap deeper than 1 cm at any step), the entrance passes them as fast
// as it clears, and all arrive.
TEST(Inflow, ACrowdedEntranceHoldsAgentsBackWithoutOverlaps) {
  const InflowSpec in = at_rate(10.0f, 0.0f);
  const ScenarioSpec s = corridor(60, in, {0.8f, 0.8f});
  const EntryRun r = run(s);
  EXPECT_TRUE(r.all_arrived);
  EXPECT_LE(r.deepest, 0.01f);
  int late = 0;
  for (std::size_t k = 0; k < r.entered.size(); ++k) {
    const double due = in.entry_time(static_cast<std::int64_t>(k));
    EXPECT_GE(r.entered[k], due - 1e-4) << "agent " << k << " entered early";
    late += r.entered[k] > due + 0.5 ? 1 : 0;
  }
  std::printf("  60 agents asked to enter at 10 P/s through 0.25 m^2: %d waited over 0.5 s, last in at %.2f s\n", late,
              *std::max_element(r.entered.begin(), r.entered.end()));
  EXPECT_GT(late, 30);
}

// Late in a run the float entry times round away from the step times
// (32.15 s at dt 0.05 is 32.1500015 as a float): each still enters in the
// step that starts at its time, not one later (a 30 m entrance: room for all).
TEST(Inflow, LateEntriesAreOnTimeToo) {
  const InflowSpec in = at_rate(20.0f / 3.0f, 32.0f);
  ScenarioSpec s = corridor(6, in, {30.0f, 3.7f});
  s.groups[0].goal = GoalSpec::at({39.0f, 2.0f});
  s.duration = 80.0f;
  const EntryRun r = run(s);
  for (std::size_t k = 0; k < r.entered.size(); ++k) {
    const double t = in.entry_time(static_cast<std::int64_t>(k));
    EXPECT_NEAR(r.entered[k], std::round(t / s.dt) * s.dt, 1e-4) << "agent " << k << " due at " << t;
  }
}

// Listed times: agent k enters at times[k].
TEST(Inflow, ListedTimes) {
  InflowSpec in;
  in.enabled = true;
  in.times = {0.0f, 0.5f, 0.5f, 7.25f, 20.0f};
  const ScenarioSpec s = corridor(5, in, {3.0f, 3.7f});
  const EntryRun r = run(s);
  EXPECT_TRUE(r.all_arrived);
  for (std::size_t k = 0; k < in.times.size(); ++k)
    EXPECT_NEAR(r.entered[k], std::ceil(in.times[k] / s.dt - 1e-6) * s.dt, 1e-4) << "agent " << k;
}

// The same crowded entrance on 1, 2 and 4 threads, under both schedulers:
// the same positions and flags, bit for bit, half way through the entries.
TEST(Inflow, TheSameBitsOnAnyThreadCount) {
  for (const SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour}) {
    SCOPED_TRACE(to_string(scheduler));
    ScenarioSpec s = corridor(60, at_rate(10.0f, 0.0f), {0.8f, 0.8f});
    s.scheduler = scheduler;
    auto snapshot = [&](int threads) {
      ScopedExecution exec(Backend::Cpu, threads);
      Simulation sim(s);
      sim.run(300);
      return std::pair{sim.positions(), sim.flags()};
    };
    const auto one = snapshot(1);
    EXPECT_GT(std::count(one.second.begin(), one.second.end(), kAgentActive), 5);
    for (int t : {2, 4}) {
      const auto other = snapshot(t);
      EXPECT_TRUE(test::same_bits(one.first, other.first)) << t << " threads";
      EXPECT_TRUE(test::same_bits(one.second, other.second)) << t << " threads";
    }
  }
}

TEST(Inflow, BadSchedulesAreLocatedErrors) {
  auto error_of = [](ScenarioSpec s) { return test::spawn_error(s); };
  auto has = [](const std::string& text, const char* part) { return text.find(part) != std::string::npos; };
  EXPECT_TRUE(has(error_of(corridor(10, at_rate(-1.0f, 0.0f), {3, 3})), "groups[0].inflow.rate"));
  EXPECT_TRUE(has(error_of(corridor(10, at_rate(NAN, 0.0f), {3, 3})), "groups[0].inflow.rate"));
  EXPECT_TRUE(has(error_of(corridor(10, at_rate(1.0f, -2.0f), {3, 3})), "groups[0].inflow.from"));
  // 1000 agents at 1 P/s do not fit in 200 s.
  EXPECT_TRUE(has(error_of(corridor(1000, at_rate(1.0f, 0.0f), {3, 3})), "the start of the run's last step"));
  InflowSpec until = at_rate(1.0f, 0.0f);
  until.until = 5.0f;
  EXPECT_TRUE(has(error_of(corridor(10, until, {3, 3})), "after until"));
  InflowSpec listed;
  listed.enabled = true;
  listed.times = {0.0f, 3.0f, 2.0f};
  EXPECT_TRUE(has(error_of(corridor(3, listed, {3, 3})), "groups[0].inflow.times[2]"));
  EXPECT_TRUE(has(error_of(corridor(4, listed, {3, 3})), "3 entry times for a count of 4"));
  ScenarioSpec resized = corridor(3, listed, {3, 3});
  EXPECT_THROW(scale_agent_counts(resized, 30), Error);  // --agents cannot resize listed times
  ScenarioSpec points = corridor(1, at_rate(1.0f, 0.0f), {3, 3});
  points.groups[0].spawn.kind = Region::Kind::points;
  points.groups[0].spawn.points = {{1.0f, 1.0f}};
  EXPECT_TRUE(has(error_of(points), "groups[0].spawn"));
  ScenarioSpec both = corridor(10, at_rate(1.0f, 0.0f), {3, 3});
  both.groups[0].premovement = {PremovementSpec::Kind::uniform, 0, 0, 1, 2};
  EXPECT_TRUE(has(error_of(both), "groups[0].premovement"));
}

}  // namespace
}  // namespace throng::sim
