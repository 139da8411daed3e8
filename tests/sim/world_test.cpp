// World geometry checks, spawning and the route-planner hook.
#include "sim/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/ground.h"
#include "sim/crowd.h"
#include "sim/geometry.h"
#include "sim/simulation.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

std::string build_error(const WorldSpec& spec) {
  try {
    World::build(spec, 4.0f);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

std::string spawn_error(const ScenarioSpec& spec) {
  try {
    Simulation sim(spec);  // model, world, then crowd
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(WorldGeometry, BadPolygonsAreNamedByField) {
  WorldSpec bowtie;
  bowtie.polygons.push_back({{{0, 0}, {2, 2}, {2, 0}, {0, 2}}, {}});
  bowtie.polygon_fields.push_back("world.obstacles[0]");
  const std::string e = build_error(bowtie);
  EXPECT_TRUE(contains(e, "world.obstacles[0].polygon")) << e;
  EXPECT_TRUE(contains(e, "self-intersecting")) << e;

  WorldSpec hole_outside;
  hole_outside.polygons.push_back({rect_ring({0, 0}, {4, 4}), {rect_ring({10, 10}, {11, 11})}});
  EXPECT_TRUE(contains(build_error(hole_outside), "hole lies outside")) << build_error(hole_outside);

  WorldSpec repeated;
  repeated.polygons.push_back({{{0, 0}, {1, 0}, {1, 0}, {0, 1}}, {}});
  EXPECT_TRUE(contains(build_error(repeated), "zero-length edge")) << build_error(repeated);

  WorldSpec two_points;
  two_points.polygons.push_back({{{0, 0}, {1, 0}}, {}});
  EXPECT_TRUE(contains(build_error(two_points), "at least 3 vertices"));

  WorldSpec flat;
  flat.circles.push_back({{0, 0}, -1.0f});
  EXPECT_TRUE(contains(build_error(flat), "world.circles[0].radius"));

  WorldSpec far;
  far.circles.push_back({{2e7f, 0}, 1.0f});
  EXPECT_TRUE(contains(build_error(far), "beyond the limit"));
}

TEST(WorldGeometry, FreeSpaceAndHoles) {
  WorldSpec spec;
  spec.has_walkable = true;
  spec.walkable = {rect_ring({0, 0}, {20, 20}), {rect_ring({8, 8}, {12, 12})}};
  spec.polygons.push_back({rect_ring({2, 2}, {4, 4}), {rect_ring({2.5f, 2.5f}, {3.5f, 3.5f})}});  // a square ring
  spec.circles.push_back({{15, 15}, 1.0f});
  const World w = World::build(spec, 4.0f);
  EXPECT_TRUE(w.in_free_space({1, 1}));
  EXPECT_FALSE(w.in_free_space({-1, 1}));       // outside the walkable region
  EXPECT_FALSE(w.in_free_space({10, 10}));      // in the walkable region's hole
  EXPECT_FALSE(w.in_free_space({2.2f, 3.0f}));  // in the obstacle
  EXPECT_TRUE(w.in_free_space({3.0f, 3.0f}));   // in the obstacle's hole
  EXPECT_FALSE(w.in_free_space({15.5f, 15}));
  EXPECT_TRUE(contains(w.what_blocks({10, 10}), "world.walkable.holes[0]"));
  EXPECT_TRUE(contains(w.what_blocks({15, 15}), "world.circles[0]"));
  EXPECT_TRUE(w.disc_fits({6, 6}, 0.25f));
  EXPECT_FALSE(w.disc_fits({4.1f, 3.0f}, 0.25f));  // too close to the obstacle's wall
}

// The kernels' float crossing test against the validation's exact one on
// random segments (general position: touching or collinear cases have
// probability zero here).
TEST(WorldGeometry, SegmentsCrossAgreesWithSegmentsIntersect) {
  std::uint64_t state = 99;
  auto uniform = [&state](float lo, float hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<float>(state >> 40) / static_cast<float>(1ull << 24);
  };
  int crossing = 0, apart = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::vec2 a(uniform(-5, 5), uniform(-5, 5)), b(uniform(-5, 5), uniform(-5, 5));
    const glm::vec2 c(uniform(-5, 5), uniform(-5, 5)), d(uniform(-5, 5), uniform(-5, 5));
    const bool exact = segments_intersect(a, b, c, d);
    EXPECT_EQ(segments_cross(a, b, c, d), exact) << a.x << "," << a.y << " " << b.x << "," << b.y;
    (exact ? crossing : apart) += 1;
  }
  EXPECT_GT(crossing, 2000);  // both outcomes well represented
  EXPECT_GT(apart, 2000);
  // Touching at an end point does not count as crossing.
  EXPECT_FALSE(segments_cross({0, 0}, {1, 0}, {1, -1}, {1, 1}));
  EXPECT_TRUE(segments_cross({0, 0}, {2, 0}, {1, -1}, {1, 1}));
}

// Walls crossing more than a thousand cells (the sides of a walkable region
// kilometres across) are kept out of the grid and tested per query; a query
// must still see every wall within one cell side, as the grid promises.
TEST(WorldGeometry, LongWallsOutOfTheGridAreStillFoundNearby) {
  WorldSpec spec;
  spec.has_walkable = true;
  constexpr float kHalf = 1e6f;
  spec.walkable = {rect_ring({-kHalf, -kHalf}, {kHalf, kHalf}), {}};
  spec.polygons.push_back({rect_ring({0, -5}, {1, 5}), {}});
  // A diagonal wall 8 km long, inside the region.
  spec.polygons.push_back({{{1000, 1000}, {6657, 6657}, {6657, 6658}, {1000, 1001}}, {}});
  const float cell = 4.0f;
  const World w = World::build(spec, cell);
  const WorldView v = w.host_view();
  EXPECT_GE(v.long_walls.size(), 5);  // the four sides and the diagonal
  std::uint64_t state = 12345;
  auto uniform = [&state](float lo, float hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<float>(state >> 40) / static_cast<float>(1ull << 24);
  };
  std::vector<glm::vec2> probes;
  for (int i = 0; i < 300; ++i) {
    probes.push_back({uniform(-8, 8), uniform(-8, 8)});                // the short obstacle
    probes.push_back({kHalf - uniform(0, 6), uniform(-1e5f, 1e5f)});   // the east side
    probes.push_back({uniform(-1e5f, 1e5f), -kHalf + uniform(0, 6)});  // the south side
    const float t = uniform(1000, 6650);
    probes.push_back({t + uniform(-5, 5), t + uniform(-5, 5)});  // along the diagonal
  }
  for (const glm::vec2 p : probes) {
    std::vector<const Segment*> seen;
    for_each_obstacle(
        v, obstacle_cell(v, p), [&](const Segment& s) { seen.push_back(&s); }, [](const Circle&) {});
    std::vector<const Segment*> near;
    for_each_wall_near(v, p, [&](const Segment& s) { near.push_back(&s); });
    for (const Segment& s : w.segments()) {
      if (distance_to_segment(p, s.a, s.b) > cell * 0.999f) continue;
      EXPECT_NE(std::find(seen.begin(), seen.end(), &s), seen.end())
          << "wall (" << s.a.x << ", " << s.a.y << ")-(" << s.b.x << ", " << s.b.y << ") missed at " << p.x << ", "
          << p.y;
      EXPECT_NE(std::find(near.begin(), near.end(), &s), near.end())
          << "for_each_wall_near missed it at " << p.x << ", " << p.y;
    }
  }
}

TEST(Spawn, AgentsStartApartInFreeSpaceWithTheirGoals) {
  const ScenarioSpec spec = test::builtin("bottleneck", 300);
  const World w = World::build(spec.world, spec.model.query_radius());
  const CrowdHost h = spawn_crowd(spec, w);
  ASSERT_EQ(h.position.size(), 300u);
  for (std::size_t i = 0; i < h.position.size(); ++i) {
    EXPECT_TRUE(w.disc_fits(h.position[i], h.radius[i])) << i;
    for (std::size_t j = i + 1; j < h.position.size(); ++j)
      ASSERT_GE(length_of(h.position[i] - h.position[j]), h.radius[i] + h.radius[j]);
    // Route: the door, then a random goal in the yard (the goal is last).
    ASSERT_EQ(h.waypoint_count[i], 2);
    EXPECT_EQ(h.waypoint_goal[i], 1);
    EXPECT_EQ(h.waypoints[static_cast<std::size_t>(h.waypoint_begin[i])], glm::vec2(21.5f, 10.0f));
    const glm::vec2 goal = h.waypoints[static_cast<std::size_t>(h.waypoint_begin[i]) + 1];
    EXPECT_TRUE(goal.x >= 34 && goal.x <= 39 && goal.y >= -3 && goal.y <= 23) << goal.x << ", " << goal.y;
    EXPECT_GE(h.pref_speed[i], 0.9f);
    EXPECT_LE(h.pref_speed[i], 1.7f);
  }
}

TEST(Spawn, ClearErrorsForSpawnRegionsGoalsAndParameters) {
  ScenarioSpec in_wall = test::builtin("crossing", 20);
  in_wall.groups[0].spawn.min = {-60, 20};  // inside a block of buildings
  in_wall.groups[0].spawn.max = {-40, 40};
  EXPECT_TRUE(contains(spawn_error(in_wall), "groups[0].spawn")) << spawn_error(in_wall);
  EXPECT_TRUE(contains(spawn_error(in_wall), "inside obstacle world.obstacles[2]")) << spawn_error(in_wall);

  ScenarioSpec goal_in_wall = test::builtin("crossing", 20);
  goal_in_wall.groups[1].goal.kind = GoalSpec::Kind::Offset;
  goal_in_wall.groups[1].goal.value = {30, 70};  // into a block
  EXPECT_TRUE(contains(spawn_error(goal_in_wall), "groups[1].goal")) << spawn_error(goal_in_wall);
  EXPECT_TRUE(contains(spawn_error(goal_in_wall), "lies inside obstacle")) << spawn_error(goal_in_wall);

  // A walled-in courtyard: the goal is free but no path reaches it.
  ScenarioSpec unreachable = test::open_field(10, {-5, -5}, {5, 5}, {0, 0});
  unreachable.groups[0].goal.kind = GoalSpec::Kind::Point;
  unreachable.groups[0].goal.value = {30, 0};
  unreachable.world.polygons.push_back({rect_ring({20, -10}, {40, 10}), {rect_ring({25, -5}, {35, 5})}});
  EXPECT_TRUE(contains(spawn_error(unreachable), "is unreachable")) << spawn_error(unreachable);
  EXPECT_TRUE(contains(spawn_error(unreachable), "groups[0].goal")) << spawn_error(unreachable);

  ScenarioSpec crowded = test::open_field(1000, {0, 0}, {3, 3}, {10, 0});
  EXPECT_TRUE(contains(spawn_error(crowded), "cannot fit")) << spawn_error(crowded);

  ScenarioSpec fast = test::open_field(10, {0, 0}, {10, 10}, {10, 0});
  fast.groups[0].speed.max = 3.0f;
  EXPECT_TRUE(contains(spawn_error(fast), "groups[0].speed.max")) << spawn_error(fast);

  ScenarioSpec huge = test::open_field(10, {0, 0}, {10, 10}, {10, 0});
  huge.groups[0].radius = 3.0f;
  EXPECT_TRUE(contains(spawn_error(huge), "groups[0].radius")) << spawn_error(huge);

  ScenarioSpec bad_model = test::open_field(10, {0, 0}, {10, 10}, {10, 0});
  bad_model.model.pred_time = NAN;
  EXPECT_TRUE(contains(spawn_error(bad_model), "model.pred_time")) << spawn_error(bad_model);

  ScenarioSpec too_many = test::open_field(10, {0, 0}, {10, 10}, {10, 0});
  ScenarioLimits limits;
  limits.max_agents = 5;
  try {
    spawn_crowd(too_many, World::build(too_many.world, 4.0f), limits);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(), "exceed the limit"));
  }
}

// A planner (a real one, for a known world): every route detours through a
// fixed point above the obstacle.
class DetourPlanner : public RoutePlanner {
 public:
  std::vector<std::vector<glm::vec2>> plan(const World&, std::span<const glm::vec2> starts,
                                           std::span<const glm::vec2> goals, float) const override {
    std::vector<std::vector<glm::vec2>> routes;
    for (std::size_t i = 0; i < starts.size(); ++i)
      routes.push_back({glm::vec2(0.0f, 6.0f), glm::vec2(goals[i].x, 6.0f)});
    return routes;
  }
};

TEST(Spawn, ThePlannerFillsRoutesOfGroupsWithAGoalOnly) {
  ScenarioSpec spec = test::open_field(5, {-12, -1}, {-8, 1}, {20, 0});
  spec.world.polygons.push_back({rect_ring({-1, -3}, {1, 3}), {}});
  spec.groups[0].arrival = ArrivalBehaviour::Loop;
  const World w = World::build(spec.world, 4.0f);
  const DetourPlanner planner;
  const CrowdHost h = spawn_crowd(spec, w, {}, &planner);
  for (std::size_t i = 0; i < h.position.size(); ++i) {
    const auto b = static_cast<std::size_t>(h.waypoint_begin[i]);
    // Planned points, the goal, the planned points backwards, the start.
    ASSERT_EQ(h.waypoint_count[i], 6);
    EXPECT_EQ(h.waypoint_goal[i], 2);
    EXPECT_EQ(h.waypoints[b], glm::vec2(0.0f, 6.0f));
    EXPECT_EQ(h.waypoints[b + 2], h.position[i] + glm::vec2(20.0f, 0.0f));
    EXPECT_EQ(h.waypoints[b + 3], h.waypoints[b + 1]);
    EXPECT_EQ(h.waypoints[b + 5], h.position[i]);
  }
  // Explicit waypoints win over the planner.
  GoalSpec via;
  via.value = {0.0f, -6.0f};
  spec.groups[0].waypoints = {via};
  const CrowdHost explicit_route = spawn_crowd(spec, w, {}, &planner);
  EXPECT_EQ(explicit_route.waypoints[0], glm::vec2(0.0f, -6.0f));
  EXPECT_EQ(explicit_route.waypoint_count[0], 4);  // via, goal, via, start
}

TEST(Scenario, ScaleAgentCountsKeepsProportions) {
  ScenarioSpec s = test::builtin("crossing");
  scale_agent_counts(s, 301);
  EXPECT_EQ(s.total_agents(), 301);
  EXPECT_EQ(std::abs(s.groups[0].count - s.groups[1].count), 1);
  EXPECT_THROW(scale_agent_counts(s, 1), Error);
}

TEST(Scenario, OverviewCameraSeesTheWholeScene) {
  Aabb box;
  box.add({-100, -50});
  box.add({300, 150});
  const Camera c = overview_camera(box);
  c.validate();
  const CameraView v = make_camera_view(c);
  for (glm::vec2 corner : {box.min, box.max, glm::vec2(box.min.x, box.max.y), glm::vec2(box.max.x, box.min.y)}) {
    const glm::vec3 px = world_to_pixel(v, world_from_ground(corner));
    EXPECT_GT(px.z, c.near_plane);
    EXPECT_LT(px.z, c.far_plane);
    EXPECT_TRUE(px.x >= 0 && px.x <= static_cast<float>(c.width) && px.y >= 0 && px.y <= static_cast<float>(c.height))
        << corner.x << ", " << corner.y << " -> " << px.x << ", " << px.y;
  }
}

}  // namespace
}  // namespace throng::sim
