// The paper's three forces, each alone against hand-computed cases, and
// their priority (a higher force suppresses the lower ones), on the stage
// functions the kernels run.
#include "sim/steering.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/crowd.h"
#include "sim/sense.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace throng::sim {
namespace {

constexpr float kEps = 1e-5f;

void expect_vec(glm::vec2 got, glm::vec2 want, float eps = kEps) {
  EXPECT_NEAR(got.x, want.x, eps) << "got (" << got.x << ", " << got.y << ")";
  EXPECT_NEAR(got.y, want.y, eps) << "got (" << got.x << ", " << got.y << ")";
}

// Agent at the origin walking +x at 1 m/s, radius 0.25; pred_time 1 s,
// probe_margin 0.1: probe length 0.25 + 1 * 1 = 1.25 m, half-width 0.35 m.
// The priority model's parameters (the collision-free speed model is the
// default).
ModelParams model() {
  ModelParams m;
  m.kind = ModelKind::Priority;
  return m;
}
Probe probe_east() { return make_probe({0.0f, 0.0f}, {1.0f, 0.0f}, 0.0f, 0.25f, model()); }

TEST(ObstacleAvoidance, ProbeSize) {
  const Probe p = probe_east();
  EXPECT_FLOAT_EQ(p.length, 1.25f);
  EXPECT_FLOAT_EQ(p.half_width, 0.35f);
  expect_vec(p.forward, {1.0f, 0.0f});
  // At rest the probe points along the heading and is just the radius long.
  const Probe still = make_probe({0.0f, 0.0f}, {0.0f, 0.0f}, 1.5707963f, 0.25f, model());
  expect_vec(still.forward, {0.0f, 1.0f});
  EXPECT_FLOAT_EQ(still.length, 0.25f);
}

TEST(ObstacleAvoidance, WallHeadOnPushesBackAndToTheRight) {
  const Probe p = probe_east();
  // Wall x = 1 across the path: hit at (1, 0), 1 m ahead, normal (-1, 0).
  const ProbeHit h = probe_segment(p, {1.0f, -2.0f}, {1.0f, 2.0f});
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.distance, 1.0f);
  expect_vec(h.point, {1.0f, 0.0f});
  expect_vec(h.normal, {-1.0f, 0.0f});
  // Strength 4 * (1 - 1/1.25) * 1 = 0.8; repulsion (-1, 0) + pull to the
  // right (0, -1) when head-on, normalised.
  const float s = 0.8f / std::sqrt(2.0f);
  expect_vec(obstacle_force(p, h, 4.0f), {-s, -s});
}

TEST(ObstacleAvoidance, SlantedWallPullsAlongItsLean) {
  const Probe p = probe_east();
  // Wall from (1, 0) to (2, 1): inside the probe from x = 1 (y = 0) to
  // x = 1.25; nearest hit (1, 0) at 1 m, normal (-1, 1)/sqrt 2 (towards the
  // agent), approach 1/sqrt 2.
  const ProbeHit h = probe_segment(p, {1.0f, 0.0f}, {2.0f, 1.0f});
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.distance, 1.0f);
  expect_vec(h.point, {1.0f, 0.0f});
  expect_vec(h.normal, glm::vec2(-1.0f, 1.0f) / std::sqrt(2.0f));
  // Strength 4 * (1 - 1/1.25) / sqrt 2; repulsion (-1, 0) plus a pull to the
  // left, the side the normal leans to: direction (-1, 1)/sqrt 2.
  const float strength = 0.8f / std::sqrt(2.0f);
  expect_vec(obstacle_force(p, h, 4.0f), glm::vec2(-1.0f, 1.0f) * (strength / std::sqrt(2.0f)));
}

TEST(ObstacleAvoidance, WallAlongsideGivesNoForce) {
  const Probe p = probe_east();
  // A wall 0.3 m to the left, parallel to the motion: the agent is not approaching it.
  const ProbeHit h = probe_segment(p, {-5.0f, 0.3f}, {5.0f, 0.3f});
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.distance, 0.0f);
  expect_vec(obstacle_force(p, h, 4.0f), {0.0f, 0.0f});
}

TEST(ObstacleAvoidance, NothingAheadOrBeyondTheProbe) {
  const Probe p = probe_east();
  EXPECT_FALSE(probe_segment(p, {1.3f, -2.0f}, {1.3f, 2.0f}).hit);    // beyond the 1.25 m length
  EXPECT_FALSE(probe_segment(p, {-1.0f, -2.0f}, {-1.0f, 2.0f}).hit);  // behind
  EXPECT_FALSE(probe_segment(p, {0.0f, 0.5f}, {1.0f, 0.5f}).hit);     // outside the 0.35 m band
  EXPECT_FALSE(probe_circle(p, {3.0f, 0.0f}, 1.0f).hit);
}

TEST(ObstacleAvoidance, CornerOnlyInTheMarginBandNudgesSideways) {
  const Probe p = probe_east();
  // A wall starting 0.3 m to the left (beyond the 0.25 m radius, inside the
  // 0.35 m band): the disc would pass it. Strength 4 * (1 - 1/1.25) = 0.8,
  // straight to the right.
  const ProbeHit h = probe_segment(p, {1.0f, 0.3f}, {1.0f, 2.0f});
  ASSERT_TRUE(h.hit);
  EXPECT_FLOAT_EQ(h.distance, 1.0f);
  expect_vec(obstacle_force(p, h, 4.0f), {0.0f, -0.8f});
}

TEST(ObstacleAvoidance, CircleAhead) {
  const Probe p = probe_east();
  // Disc of radius 0.2 at (1, 0): nearest point (0.8, 0), normal (-1, 0).
  const ProbeHit h = probe_circle(p, {1.0f, 0.0f}, 0.2f);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance, 0.8f, kEps);
  expect_vec(h.normal, {-1.0f, 0.0f});
  // Strength 4 * (1 - 0.8/1.25) = 1.44, back and to the right.
  const float s = 1.44f / std::sqrt(2.0f);
  expect_vec(obstacle_force(p, h, 4.0f), {-s, -s});
  // A disc of radius 0.2 centred 0.5 m to the left reaches 0.15 m into the
  // 0.35 m band: nearest band point x = 1 - sqrt(0.2^2 - 0.15^2) at y = 0.35,
  // beyond the radius, so a sideways nudge to the right weighted by the
  // approach (the normal there is (x - 1, 0.35 - 0.5) / 0.2).
  const ProbeHit side = probe_circle(p, {1.0f, 0.5f}, 0.2f);
  ASSERT_TRUE(side.hit);
  const float x = 1.0f - std::sqrt(0.04f - 0.0225f);
  EXPECT_NEAR(side.distance, x, kEps);
  const float approach = -(x - 1.0f) / 0.2f;
  expect_vec(obstacle_force(p, side, 4.0f), {0.0f, -4.0f * (1.0f - x / 1.25f) * approach});
}

TEST(AgentAvoidance, HeadOnNeighbourPredictedCloseGivesLateralForce) {
  // A at the origin walking +x at 1 m/s; B at (2, 0.2) walking -x at 1 m/s.
  // Closest approach at t = 1 s with B 0.2 m to A's left; observation radii
  // 0.25 + 0.15 each: reach 0.8.
  const Threat t = predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {2.0f, 0.2f}, {-1, 0}, 0.4f, 1.0f);
  ASSERT_TRUE(t.found);
  EXPECT_FLOAT_EQ(t.time, 1.0f);
  expect_vec(t.separation, {0.0f, 0.2f});
  EXPECT_FLOAT_EQ(t.reach, 0.8f);
  // Strength 4 * (1 - 0.2 / 0.8) = 3, away from B's side: to the right.
  expect_vec(avoidance_force({1, 0}, t, 4.0f), {0.0f, -3.0f});
}

TEST(AgentAvoidance, ExactlyHeadOnKeepsRight) {
  const Threat t = predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {2.0f, 0.0f}, {-1, 0}, 0.4f, 1.0f);
  ASSERT_TRUE(t.found);
  expect_vec(avoidance_force({1, 0}, t, 4.0f), {0.0f, -4.0f});
}

TEST(AgentAvoidance, NoThreatWhenFarBehindOrReceding) {
  // Closest approach after the 1 s horizon is still 2 m away.
  EXPECT_FALSE(predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {4.0f, 0.2f}, {-1, 0}, 0.4f, 1.0f).found);
  // Behind the agent (its own to avoid).
  EXPECT_FALSE(predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {-0.5f, 0.0f}, {2, 0}, 0.4f, 1.0f).found);
  // Ahead but walking away faster.
  EXPECT_FALSE(predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {0.6f, 0.0f}, {2, 0}, 0.4f, 1.0f).found);
  // Passing wide: predicted 1 m apart > reach 0.8.
  EXPECT_FALSE(predict_threat({0, 0}, {1, 0}, {1, 0}, 0.4f, {2.0f, 1.0f}, {-1, 0}, 0.4f, 1.0f).found);
}

TEST(AgentAvoidance, MostUrgentIsEarliestThenClosest) {
  Threat early, late, close;
  early.found = late.found = close.found = true;
  early.time = 0.5f;
  late.time = 0.9f;
  close.time = 0.5f;
  early.separation = {0.5f, 0.0f};
  close.separation = {0.1f, 0.0f};
  EXPECT_TRUE(more_urgent(early, late));
  EXPECT_FALSE(more_urgent(late, early));
  EXPECT_TRUE(more_urgent(close, early));
  EXPECT_TRUE(more_urgent(early, Threat{}));
  EXPECT_FALSE(more_urgent(Threat{}, early));
}

TEST(PathFollowing, InsideTheLaneWalksAlongTheLeg) {
  // At rest on the leg (0,0) -> (10,0), preferred speed 1.3 m/s, relaxation
  // 0.5 s: desired (1.3, 0), force (1.3 - 0) / 0.5 = 2.6 m/s^2.
  expect_vec(path_following_force({0, 0}, {0, 0}, 1.3f, {0, 0}, {10, 0}, model()), {2.6f, 0.0f});
  // Already at the desired velocity: no force.
  expect_vec(path_following_force({3, 0.2f}, {1.3f, 0}, 1.3f, {0, 0}, {10, 0}, model()), {0.0f, 0.0f});
}

TEST(PathFollowing, OutsideTheLaneSteersBackAhead) {
  // 2 m off the leg (lane half-width 0.5): seek the projection moved one
  // look-ahead (1.3 m) along: (1.3, 0); desired = 1.3 * unit((1.3, -2)).
  const glm::vec2 d = glm::vec2(1.3f, -2.0f) * (1.3f / std::sqrt(1.3f * 1.3f + 4.0f));
  expect_vec(path_following_force({0, 2}, {0, 0}, 1.3f, {0, 0}, {10, 0}, model()), d / 0.5f);
}

TEST(PathFollowing, SlowsDownAtTheGoalAndTurnsBackWhenPastIt) {
  // 0.5 m before the goal: inside the slowing distance 1.3 * 0.5 = 0.65 m,
  // desired speed 1.3 * 0.5 / 0.65 = 1.0.
  expect_vec(path_following_force({9.5f, 0}, {0, 0}, 1.3f, {0, 0}, {10, 0}, model()), {2.0f, 0.0f});
  // 1 m past the goal (it missed the arrival disc): seek the goal.
  const glm::vec2 d = glm::vec2(-1.0f, -0.3f) * (1.3f / std::sqrt(1.09f));
  expect_vec(path_following_force({11.0f, 0.3f}, {0, 0}, 1.3f, {0, 0}, {10, 0}, model()), d / 0.5f);
}

TEST(PathFollowing, ForceIsCappedAtMaxForce) {
  // Walking the wrong way at 1.3 m/s: (1.3 - -1.3) / 0.5 = 5.2 > 4.
  const glm::vec2 f = path_following_force({0, 0}, {-1.3f, 0}, 1.3f, {0, 0}, {10, 0}, model());
  expect_vec(f, {4.0f, 0.0f});
}

TEST(Priority, HigherForceSuppressesTheLower) {
  const glm::vec2 o(1, 0), a(0, 1), p(0.5f, 0.5f), zero(0);
  expect_vec(prioritized(o, a, p), o);
  expect_vec(prioritized(zero, a, p), a);
  expect_vec(prioritized(zero, zero, p), p);
}

// The same on the sense and steer stages: two agents walking at each other
// in a corridor, one of them also heading into a wall.
struct Scene {
  World world;
  CrowdState crowd;
  AgentGrid bins;
  ModelParams m = model();
  StepContext ctx;

  Scene(std::vector<glm::vec2> positions, std::vector<glm::vec2> velocities, std::vector<glm::vec2> goals,
        const WorldSpec& spec) {
    world = World::build(spec, m.query_radius());
    CrowdHost h;
    h.position = positions;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const glm::vec2 v = velocities[i];
      h.heading.push_back(std::atan2(v.y, v.x));
      h.radius.push_back(0.25f);
      h.pref_speed.push_back(1.3f);
      h.group.push_back(0);
      h.waypoint_begin.push_back(static_cast<std::int32_t>(i));
      h.waypoint_count.push_back(1);
      h.waypoint_goal.push_back(0);
      h.waypoints.push_back(goals[i]);
    }
    h.groups.push_back({});
    crowd = upload_crowd(h);
    crowd.velocity.copy_from(velocities);
    bins = AgentGrid(m.query_radius());
    bins.rebuild(crowd.position.span(), crowd.flags.span());
    ctx.world = world.view();
    ctx.bins = bins.view();
    ctx.model = m;
    ctx.dt = 0.1f;
  }
  std::vector<glm::vec2> sensed() {
    Buffer<glm::vec2> out(crowd.count);
    sense_double_buffer(ctx, arrays_of(crowd), out.span());
    return out.to_vector();
  }
};

TEST(Priority, ObstacleForceSuppressesAgentAvoidanceInTheSenseStage) {
  WorldSpec walls;
  walls.polygons.push_back({rect_ring({1.0f, -2.0f}, {1.5f, 2.0f}), {}});  // a wall 1 m ahead of agent 0
  Scene with_wall({{0, 0}, {2.5f, 0.2f}}, {{1, 0}, {-1, 0}}, {{5, 0}, {-5, 0}}, walls);
  // Agent 0: the wall (its force as computed by hand above) wins over agent 1 beyond it.
  const Probe p = probe_east();
  expect_vec(with_wall.sensed()[0], obstacle_force(p, probe_segment(p, {1.0f, -2.0f}, {1.0f, 2.0f}), 4.0f));

  // Without the wall, agent 1 (at (2, 0.2), closing at 2 m/s) is the threat.
  Scene open({{0, 0}, {2.0f, 0.2f}}, {{1, 0}, {-1, 0}}, {{5, 0}, {-5, 0}}, WorldSpec{});
  const std::vector<glm::vec2> s = open.sensed();
  expect_vec(s[0], {0.0f, -3.0f});
  expect_vec(s[1], {0.0f, 3.0f});  // its right is +y

  // Steering adds path following only where nothing was sensed: agent 0's
  // velocity changes by exactly the sensed force * dt (kept below its
  // preferred speed 1.3: |(1, -0.3)| = 1.044).
  Buffer<glm::vec2> sensed(std::span<const glm::vec2>(s), Memory::Host), moved(2);
  steer_double_buffer(open.ctx, arrays_of(open.crowd), sensed.span(), moved.span());
  expect_vec(moved.to_vector()[0], glm::vec2(0.0f) + glm::vec2(1.0f, -0.3f) * 0.1f);
}

}  // namespace
}  // namespace throng::sim
