// Pre-movement times (RiMEA 3.0 test 5): drawn per agent from the group's
// distribution within its bounds, on a stream of their own (the rest of the
// spawn is unchanged by them), and obeyed by every model: an agent stands
// where it spawned until its time, then walks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "core/error.h"
#include "sim/crowd.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "sim/world.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// `count` agents spread over a large open field, each walking 10 m east.
ScenarioSpec field(std::int64_t count, PremovementSpec p) {
  ScenarioSpec s = test::open_field(count, {0, 0}, {400, 400}, {10, 0});
  s.duration = 400.0f;
  s.groups[0].premovement = p;
  return s;
}

using test::spawn;
using test::spawn_error;

double mean_of(const std::vector<float>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}
double stddev_of(const std::vector<float>& v) {
  const double m = mean_of(v);
  double s = 0;
  for (float x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

TEST(Premovement, NoneLetsEveryAgentWalkAtOnce) {
  const CrowdHost h = spawn(field(100, {}));
  ASSERT_EQ(h.start_time.size(), 100u);
  for (float t : h.start_time) EXPECT_EQ(t, 0.0f);
}

// 4000 draws: sample mean and spread against the distribution's, within
// about five standard errors; every draw within the bounds.
TEST(Premovement, DrawsFollowTheDistributionWithinItsBounds) {
  using Kind = PremovementSpec::Kind;
  const std::int64_t n = 4000;
  {
    const CrowdHost h = spawn(field(n, {Kind::uniform, 0, 0, 10, 100}));
    for (float t : h.start_time) ASSERT_TRUE(t >= 10.0f && t <= 100.0f) << t;
    EXPECT_NEAR(mean_of(h.start_time), 55.0, 2.0);
    EXPECT_NEAR(stddev_of(h.start_time), 90.0 / std::sqrt(12.0), 1.5);
  }
  {
    const CrowdHost h = spawn(field(n, {Kind::normal, 30, 5, 0, 100}));
    EXPECT_NEAR(mean_of(h.start_time), 30.0, 0.4);
    EXPECT_NEAR(stddev_of(h.start_time), 5.0, 0.3);
  }
  {
    // The mean and spread of the times themselves (not of their logarithm).
    const CrowdHost h = spawn(field(n, {Kind::lognormal, 20, 8, 0, 300}));
    for (float t : h.start_time) ASSERT_GT(t, 0.0f);
    EXPECT_NEAR(mean_of(h.start_time), 20.0, 0.7);
    EXPECT_NEAR(stddev_of(h.start_time), 8.0, 0.8);
  }
  {
    // Tight bounds truncate: every draw inside them.
    const CrowdHost h = spawn(field(n, {Kind::normal, 30, 10, 25, 32}));
    for (float t : h.start_time) ASSERT_TRUE(t >= 25.0f && t <= 32.0f) << t;
  }
}

// Same seed, same times; and adding pre-movement to a group changes neither
// where its agents stand nor how fast they walk nor where they go.
TEST(Premovement, DrawnFromTheSeedOnAStreamOfTheirOwn) {
  const PremovementSpec p{PremovementSpec::Kind::uniform, 0, 0, 5, 50};
  const CrowdHost a = spawn(field(300, p)), b = spawn(field(300, p)), none = spawn(field(300, {}));
  EXPECT_EQ(a.start_time, b.start_time);
  EXPECT_EQ(a.position, none.position);
  EXPECT_EQ(a.pref_speed, none.pref_speed);
  EXPECT_EQ(a.waypoints, none.waypoints);
  ScenarioSpec other = field(300, p);
  other.seed = 2;
  EXPECT_NE(spawn(other).start_time, a.start_time);
}

TEST(Premovement, BadBoundsAndSpreadsAreLocatedErrors) {
  using Kind = PremovementSpec::Kind;
  auto error_of = [](PremovementSpec p) { return spawn_error(field(10, p)); };
  EXPECT_NE(error_of({Kind::uniform, 0, 0, -1, 10}).find("groups[0].premovement.min"), std::string::npos);
  EXPECT_NE(error_of({Kind::uniform, 0, 0, 20, 10}).find("groups[0].premovement.max"), std::string::npos);
  EXPECT_NE(error_of({Kind::uniform, 0, 0, 0, NAN}).find("groups[0].premovement.max"), std::string::npos);
  EXPECT_NE(error_of({Kind::normal, NAN, 1, 0, 10}).find("groups[0].premovement.mean"), std::string::npos);
  EXPECT_NE(error_of({Kind::lognormal, 0, 1, 0, 10}).find("groups[0].premovement.mean"), std::string::npos);
  EXPECT_NE(error_of({Kind::normal, 5, -1, 0, 10}).find("groups[0].premovement.stddev"), std::string::npos);
  // Beyond the scenario's end the agents would never walk.
  EXPECT_NE(error_of({Kind::uniform, 0, 0, 0, 500}).find("the run's last step"), std::string::npos);
}

// Agents far apart (no neighbour in reach), each waiting a different time:
// under every model each one stays exactly where it spawned until its start
// time, has walked off within a second after it, and arrives no earlier than
// its start time plus the unhindered walk.
TEST(Premovement, EveryModelHoldsEachAgentUntilItsTime) {
  for (const ModelKind model :
       {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce}) {
    SCOPED_TRACE(to_string(model));
    ScenarioSpec s = field(0, {PremovementSpec::Kind::uniform, 0, 0, 1, 6});
    s.model.kind = model;
    s.planning = PlanningKind::None;
    s.dt = 0.05f;
    s.duration = 30.0f;
    GroupSpec& g = s.groups[0];
    g.spawn.kind = Region::Kind::points;
    for (int k = 0; k < 8; ++k) g.spawn.points.push_back({0.0f, 20.0f * static_cast<float>(k)});
    g.count = static_cast<std::int64_t>(g.spawn.points.size());
    g.speed = {1.3f, 0.0f, 1.3f, 1.3f};
    Simulation sim(s);
    const std::vector<glm::vec2> start = sim.positions();
    const CrowdHost h = spawn(s);
    const std::vector<float>& when = h.start_time;
    std::vector<bool> left(start.size(), false);
    while (!sim.all_arrived() && sim.time() < 30.0) {
      sim.step();
      const std::vector<glm::vec2> p = sim.positions();
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (sim.time() <= when[i]) {
          EXPECT_EQ(p[i], start[i]) << "agent " << i << " moved at " << sim.time() << " s before its " << when[i];
        } else if (sim.time() >= when[i] + 1.0) {
          left[i] = left[i] || length_of(p[i] - start[i]) > 0.3f;
        }
      }
    }
    for (std::size_t i = 0; i < left.size(); ++i) EXPECT_TRUE(left[i]) << "agent " << i;
    const std::vector<float> arrived = sim.arrival_times();
    for (std::size_t i = 0; i < arrived.size(); ++i) {
      EXPECT_GE(arrived[i], when[i] + (10.0f - g.arrival_radius) / 1.3f - 0.1f) << "agent " << i;
      EXPECT_LE(arrived[i], when[i] + 10.0f / 1.3f * 1.5f) << "agent " << i;
    }
  }
}

// A start time that falls on a step walks in that step, whatever the float
// rounding of the two (0.01 s steps are slightly under 0.01 as floats).
TEST(Premovement, AStartOnAStepWalksInThatStep) {
  ScenarioSpec s = field(0, {PremovementSpec::Kind::uniform, 0, 0, 0.05f, 0.05f});
  s.planning = PlanningKind::None;
  s.dt = 0.01f;
  s.duration = 1.0f;
  s.model.max_speed = 1.5f;
  GroupSpec& g = s.groups[0];
  g.spawn.kind = Region::Kind::points;
  g.spawn.points = {{0.0f, 0.0f}};
  g.count = 1;
  g.radius = 0.2f;
  g.speed = {1.3f, 0.0f, 1.3f, 1.3f};
  Simulation sim(s);
  const glm::vec2 start = sim.positions()[0];
  sim.run(5);  // the steps that start at 0 .. 0.04 s: standing
  EXPECT_EQ(sim.positions()[0], start);
  sim.step();  // the step that starts at 0.05 s
  EXPECT_GT(length_of(sim.positions()[0] - start), 0.0f);
}

// Waiting is not being stuck: a crowd that waits 10 s counts no stuck agent.
TEST(Premovement, WaitingAgentsAreNotStuck) {
  ScenarioSpec s = field(50, {PremovementSpec::Kind::uniform, 0, 0, 10, 10});
  s.planning = PlanningKind::None;
  s.duration = 12.0f;
  Simulation sim(s);
  StuckTracker stuck;
  for (int k = 0; k < 110; ++k) {
    sim.step();
    stuck.update(sim);
  }
  EXPECT_EQ(stuck.stats().agents, 0);
}

}  // namespace
}  // namespace throng::sim
