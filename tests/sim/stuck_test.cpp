// Stuck agents (StuckTracker, metrics.h) on hand-made crowds and against a
// brute-force reference built on the geometry of the world spec.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/exec.h"
#include "sim/crowd.h"
#include "sim/metrics.h"

namespace throng::sim {
namespace {

constexpr double kDt = 0.1;
constexpr std::uint8_t kActive = kAgentActive;
constexpr std::uint8_t kStoppedAtGoal = kAgentActive | kAgentArrived | kAgentStopped;

struct Crowd {
  std::vector<glm::vec2> p, v, goal;
  std::vector<float> r;
  std::vector<std::uint8_t> flags;
  void add(glm::vec2 position, glm::vec2 velocity, glm::vec2 to, std::uint8_t f = kActive, float radius = 0.25f) {
    p.push_back(position);
    v.push_back(velocity);
    goal.push_back(to);
    r.push_back(radius);
    flags.push_back(f);
  }
};

// A 40 m square with a 1 x 4 m wall block at x 3..4, y -2..2, and a pillar.
WorldSpec room() {
  WorldSpec spec;
  spec.has_walkable = true;
  spec.walkable = {rect_ring({-20, -20}, {20, 20}), {}};
  spec.polygons.push_back({rect_ring({3, -2}, {4, 2}), {}});
  spec.circles.push_back({{-10, 10}, 1.0f});
  return spec;
}

void step(StuckTracker& t, const World& w, const Crowd& c, std::int64_t k) {
  t.update(w, c.p, c.v, c.r, c.goal, c.flags, 1.0f, static_cast<double>(k) * kDt, kDt);
}

// Agents at rest with their way free are stuck once their time at rest
// exceeds 5 s: after 51 steps of 0.1 s, not after 50.
TEST(StuckAgents, FrozenInFreeSpaceIsStuckAfterMoreThanFiveSecondsNotBefore) {
  const World w = World::build(room(), 4.0f);
  Crowd c;
  c.add({-5, 0}, {0, 0}, {-5, 10});                  // 0: open floor: stuck
  c.add({2.3f, 0}, {0, 0}, {10, 0});                 // 1: goal through the wall, 0.7 m ahead of its centre: not
  c.add({1.0f, 0}, {0, 0}, {10, 0});                 // 2: goal through the wall, 1.75 m of free floor ahead: stuck
  c.add({2.7f, 2.4f}, {0, 0}, {2.7f, 10});           // 3: beside the wall's corner, the way up free: stuck
  c.add({-5, -5}, {1, 0}, {10, -5});                 // 4: walking: not
  c.add({-5, 5}, {0, 0.1f}, {-5, 15});               // 5: 0.1 m/s is not below 0.1: not
  c.add({5, 5}, {0, 0}, {5, 15}, 0);                 // 6: inactive: not
  c.add({5, -5}, {0, 0}, {5, -15}, kStoppedAtGoal);  // 7: stopped at its goal: not
  c.add({-5, -10}, {0, 0}, {-5, -10});               // 8: standing on its goal (not stopped): no way ahead, not
  c.add({-9.6f, 8.5f}, {0, 0}, {-9.0f, 10});         // 9: the pillar inside its probe: not
  const std::vector<Index> want = {0, 2, 3};

  StuckTracker t;
  std::int64_t k = 0;
  for (; k < 51; ++k) {
    const bool over = static_cast<double>(k + 1) * kDt > 5.0 + 1e-9;  // time at rest after this step exceeds 5 s
    step(t, w, c, k + 1);
    const StuckStats& s = t.stats();
    ASSERT_EQ(s.now, over ? 3 : 0) << "step " << k + 1;
    ASSERT_EQ(s.agents, over ? 3 : 0) << "step " << k + 1;
  }
  const StuckStats& s = t.stats();
  EXPECT_EQ(s.max_at_once, 3);
  EXPECT_DOUBLE_EQ(s.first_time, 5.1);
  ASSERT_EQ(s.examples.size(), want.size());
  for (std::size_t e = 0; e < want.size(); ++e) {
    EXPECT_EQ(s.examples[e].agent, want[e]);
    EXPECT_DOUBLE_EQ(s.examples[e].time, 5.1);
    EXPECT_EQ(s.examples[e].position, c.p[static_cast<std::size_t>(want[e])]);
  }
  const std::vector<std::int32_t> rest = t.rest_steps();
  for (std::size_t i = 0; i < rest.size(); ++i) EXPECT_EQ(rest[i], i == 0 || i == 2 || i == 3 ? 51 : 0) << i;

  // Agent 0 walks one step: no longer stuck, still counted once; back at
  // rest it needs another 51 steps, and it is counted once still.
  c.v[0] = {0.5f, 0};
  step(t, w, c, ++k);
  EXPECT_EQ(t.stats().now, 2);
  EXPECT_EQ(t.stats().agents, 3);
  c.v[0] = {0, 0};
  for (int m = 0; m < 51; ++m) step(t, w, c, ++k);
  EXPECT_EQ(t.stats().now, 3);
  EXPECT_EQ(t.stats().agents, 3);
  EXPECT_EQ(t.stats().examples.size(), 3u);
  EXPECT_DOUBLE_EQ(t.stats().first_time, 5.1);
}

// Someone in the probe (r + 0.3 m ahead, radius r) holds an agent back:
// queues are not stuck, only a frozen head with the floor free before it.
TEST(StuckAgents, AgentsWaitingBehindOthersAreNotStuck) {
  const World w = World::build(room(), 4.0f);
  Crowd c;
  const glm::vec2 east{30, 0};
  c.add({-15, 0}, {0, 0}, glm::vec2{-15, 0} + east);          // 0: queue tail: not
  c.add({-14.45f, 0}, {0, 0}, glm::vec2{-14.45f, 0} + east);  // 1: middle: not
  c.add({-13.9f, 0}, {0, 0}, glm::vec2{-13.9f, 0} + east);    // 2: head, floor free before it: stuck
  c.add({-15, 5}, {0, 0}, {10, 5});           // 3: the next one's disc 0.5 m away, inside the probe: not
  c.add({-14.0f, 5}, {0, 0}, {10, 5});        // 4: free: stuck
  c.add({-15, 7}, {0, 0}, {10, 7});           // 5: the next one's disc 0.7 m away: stuck
  c.add({-13.8f, 7}, {0, 0}, {10, 7});        // 6: free: stuck
  c.add({-15, -5}, {0, 0}, {10, -5});         // 7: the one ahead is inactive (left): stuck
  c.add({-14.45f, -5}, {0, 0}, {10, -5}, 0);  // 8
  c.add({-15, -8}, {0, 0}, {10, -8});         // 9: behind one stopped at its goal: not
  c.add({-14.45f, -8}, {0, 0}, {-14.45f, -8}, kStoppedAtGoal);  // 10: stopped: not
  c.add({-15, -12}, {0, 0}, {-15, -2});              // 11: the one ahead stands to the side of the way up: stuck
  c.add({-14.4f, -11.6f}, {0.3f, 0}, {10, -11.6f});  // 12: walking
  StuckTracker t;
  for (std::int64_t k = 1; k <= 60; ++k) step(t, w, c, k);
  std::vector<Index> got;
  for (const StuckExample& e : t.stats().examples) got.push_back(e.agent);
  EXPECT_EQ(got, (std::vector<Index>{2, 4, 5, 6, 7, 11}));
  EXPECT_EQ(t.stats().now, 6);
}

// The per-step test against one written from the world spec's geometry and
// all pairs, on a random crowd in a room with a wall block and a pillar;
// the same counters and figures on 1 and 4 threads.
TEST(StuckAgents, MatchesBruteForceAndIsTheSameOnOneAndFourThreads) {
  const WorldSpec spec = room();
  const World w = World::build(spec, 4.0f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-21.0f, 21.0f), vel(-0.15f, 0.15f), rad(0.2f, 0.3f);
  Crowd c;
  for (int i = 0; i < 3000; ++i) {
    const std::uint8_t f = i % 13 == 0 ? 0 : (i % 7 == 0 ? kStoppedAtGoal : kActive);
    c.add({pos(rng), pos(rng)}, {vel(rng), vel(rng)}, {pos(rng), pos(rng)}, f, rad(rng));
  }
  auto way_free = [&](std::size_t i) {
    if ((c.flags[i] & kAgentActive) == 0 || (c.flags[i] & kAgentStopped) != 0) return false;
    if (std::hypot(c.v[i].x, c.v[i].y) >= 0.1f) return false;
    const glm::vec2 d = c.goal[i] - c.p[i];
    const float len = std::hypot(d.x, d.y);
    const float r = c.r[i];
    const glm::vec2 q = c.p[i] + ((r + 0.3f) / len) * d;
    if (!point_in_polygon(q, spec.walkable) || closest_boundary_point(q, spec.walkable).distance < r) return false;
    if (point_in_polygon(q, spec.polygons[0]) || distance_to_polygon(q, spec.polygons[0]) < r) return false;
    if (std::hypot(q.x - spec.circles[0].center.x, q.y - spec.circles[0].center.y) < spec.circles[0].radius + r)
      return false;
    for (std::size_t j = 0; j < c.p.size(); ++j)
      if (j != i && (c.flags[j] & kAgentActive) != 0 && std::hypot(c.p[j].x - q.x, c.p[j].y - q.y) < r + c.r[j])
        return false;
    return true;
  };
  std::vector<std::int32_t> want(c.p.size());
  Index free_count = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    want[i] = way_free(i) ? 1 : 0;
    free_count += want[i];
  }
  EXPECT_GT(free_count, 100);
  EXPECT_LT(free_count, 1500);  // both outcomes are common

  // Half the agents walk on at random from step to step; with a 1 s
  // threshold some become stuck, some stop being stuck.
  auto run = [&](int threads) {
    ScopedExecution exec(Backend::Cpu, threads);
    StuckOptions o;
    o.threshold_s = 1.0;
    StuckTracker t(o);
    Crowd moving = c;
    std::mt19937 walk(11);
    std::vector<Index> now;
    for (std::int64_t k = 1; k <= 40; ++k) {
      t.update(w, moving.p, moving.v, moving.r, moving.goal, moving.flags, 1.0f, static_cast<double>(k) * kDt, kDt);
      if (k == 1) {
        EXPECT_EQ(t.rest_steps(), want) << threads << " threads";
      }
      now.push_back(t.stats().now);
      for (std::size_t i = 0; i < moving.v.size(); i += 2) moving.v[i] = walk() % 8 == 0 ? glm::vec2(0.5f, 0) : c.v[i];
    }
    return std::pair{t.stats(), now};
  };
  const auto [one, one_now] = run(1);
  const auto [four, four_now] = run(4);
  EXPECT_GT(one.agents, 20);
  EXPECT_GT(one.agents, one.now);  // some were stuck and walked on
  EXPECT_EQ(one.agents, four.agents);
  EXPECT_EQ(one.max_at_once, four.max_at_once);
  EXPECT_EQ(one.first_time, four.first_time);
  EXPECT_EQ(one_now, four_now);
  ASSERT_EQ(one.examples.size(), kStuckExamples);
  ASSERT_EQ(four.examples.size(), kStuckExamples);
  for (std::size_t e = 0; e < kStuckExamples; ++e) {
    EXPECT_EQ(one.examples[e].agent, four.examples[e].agent);
    EXPECT_EQ(one.examples[e].time, four.examples[e].time);
  }
}

// A crowd that grows between steps: the agents already there keep their
// time at rest, the new ones start at none.
TEST(StuckAgents, NewAgentsStartWithNoTimeAtRest) {
  const World w = World::build(room(), 4.0f);
  Crowd c;
  c.add({-5, 0}, {0, 0}, {-5, 10});
  StuckTracker t;
  for (std::int64_t k = 1; k <= 30; ++k) step(t, w, c, k);
  c.add({5, 8}, {0, 0}, {5, 15});
  for (std::int64_t k = 31; k <= 51; ++k) step(t, w, c, k);
  EXPECT_EQ(t.rest_steps(), (std::vector<std::int32_t>{51, 21}));
  EXPECT_EQ(t.stats().now, 1);
}

}  // namespace
}  // namespace throng::sim
