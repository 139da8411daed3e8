// Spawning in areas (hexagonal lattice, dense up to about 6.5 agents per m^2
// at r = 0.2 m, random-looking when sparse, deterministic from the seed) and
// at exact points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "sim/crowd.h"
#include "sim/world.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

// `count` agents of radius 0.2 m in the rect; dt small enough for that radius.
ScenarioSpec field(std::int64_t count, glm::vec2 min, glm::vec2 max, float radius = 0.2f) {
  ScenarioSpec s = test::open_field(count, min, max, {10, 0});
  s.dt = 0.05f;
  s.groups[0].radius = radius;
  return s;
}

using test::spawn;
using test::spawn_error;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The smallest centre distance over all pairs (brute force).
float min_pair_distance(const std::vector<glm::vec2>& p) {
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) best = std::min(best, length_of(p[i] - p[j]));
  return best;
}

// Every agent of every group placed, in free space, none closer than 2r.
void expect_all_placed_free_and_apart(const ScenarioSpec& spec) {
  const World w = World::build(spec.world, spec.model.query_radius());
  const CrowdHost h = spawn_crowd(spec, w);
  ASSERT_EQ(static_cast<std::int64_t>(h.position.size()), spec.total_agents());
  for (std::size_t i = 0; i < h.position.size(); ++i) EXPECT_TRUE(w.disc_fits(h.position[i], h.radius[i])) << i;
  EXPECT_GE(min_pair_distance(h.position), 2 * spec.groups[0].radius);
}

std::vector<float> nearest_neighbour_distances(const std::vector<glm::vec2>& p) {
  std::vector<float> out(p.size(), std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = 0; j < p.size(); ++j)
      if (i != j) out[i] = std::min(out[i], length_of(p[i] - p[j]));
  return out;
}

TEST(SpawnDensity, ARectFillsAtSixPerSquareMetreWithoutOverlap) {
  const CrowdHost h = spawn(field(600, {0, 0}, {10, 10}));  // 6 P/m^2
  ASSERT_EQ(h.position.size(), 600u);
  for (glm::vec2 p : h.position) {
    EXPECT_TRUE(p.x >= 0 && p.x <= 10 && p.y >= 0 && p.y <= 10) << p.x << ", " << p.y;
  }
  EXPECT_GE(min_pair_distance(h.position), 2 * 0.2f);
}

TEST(SpawnDensity, DiscsAndPolygonsFillDenselyToo) {
  ScenarioSpec disc = field(0, {0, 0}, {1, 1});
  disc.groups[0].spawn.kind = Region::Kind::disc;
  disc.groups[0].spawn.center = {0, 0};
  disc.groups[0].spawn.radius = 5.0f;
  disc.groups[0].count = 450;  // 5.7 P/m^2
  const CrowdHost d = spawn(disc);
  ASSERT_EQ(d.position.size(), 450u);
  for (glm::vec2 p : d.position) EXPECT_LE(length_of(p), 5.0f);
  EXPECT_GE(min_pair_distance(d.position), 0.4f);

  ScenarioSpec triangle = field(0, {0, 0}, {1, 1});
  triangle.groups[0].spawn.kind = Region::Kind::polygon;
  triangle.groups[0].spawn.polygon.outer = {{0, 0}, {10, 0}, {0, 10}};
  triangle.groups[0].count = 260;  // 5.2 P/m^2
  const CrowdHost t = spawn(triangle);
  ASSERT_EQ(t.position.size(), 260u);
  for (glm::vec2 p : t.position) EXPECT_TRUE(p.x >= 0 && p.y >= 0 && p.x + p.y <= 10) << p.x << ", " << p.y;
  EXPECT_GE(min_pair_distance(t.position), 0.4f);
}

TEST(SpawnDensity, BeyondTheDensestPackingIsAClearError) {
  const std::string e = spawn_error(field(700, {0, 0}, {10, 10}));  // 7 P/m^2
  EXPECT_TRUE(contains(e, "groups[0].spawn")) << e;
  EXPECT_TRUE(contains(e, "cannot fit")) << e;
}

TEST(SpawnDensity, WallsObstaclesAndOtherGroupsAreRespected) {
  // A circular obstacle in the middle, and a second group packed around it.
  ScenarioSpec spec = field(400, {0, 0}, {10, 10});
  spec.world.circles.push_back({{5, 5}, 2.0f});
  spec.world.circle_fields.push_back("world.obstacles[0]");
  GroupSpec second = spec.groups[0];
  second.count = 100;
  spec.groups.push_back(second);
  expect_all_placed_free_and_apart(spec);
}

TEST(SpawnDensity, AMostlyBlockedRegionStillFillsItsFreePart) {
  // A 20 m square of which a 20 m x 3 m strip is free: the first lattice,
  // sized for the whole square, is too sparse; a denser one follows.
  ScenarioSpec spec = field(250, {0, 0}, {20, 20});
  spec.world.polygons.push_back({rect_ring({-1, 3}, {21, 21}), {}});
  spec.world.polygon_fields.push_back("world.obstacles[0]");
  expect_all_placed_free_and_apart(spec);
}

TEST(SpawnRandomness, SparseSpawnsAreNotALattice) {
  const CrowdHost h = spawn(field(400, {0, 0}, {20, 20}));  // 1 P/m^2
  ASSERT_EQ(h.position.size(), 400u);
  const std::vector<float> nn = nearest_neighbour_distances(h.position);
  double mean = 0, var = 0;
  for (float v : nn) mean += v;
  mean /= static_cast<double>(nn.size());
  for (float v : nn) var += (v - mean) * (v - mean);
  const double sd = std::sqrt(var / static_cast<double>(nn.size()));
  // A lattice (with or without vacancies) has a handful of distinct
  // nearest-neighbour distances; these spread continuously.
  EXPECT_GT(sd / mean, 0.15) << "mean " << mean << " sd " << sd;
  std::vector<float> sorted = nn;
  std::sort(sorted.begin(), sorted.end());
  // On a lattice with a third of its sites taken about 90 % of the nearest
  // neighbours sit at the spacing; here no 2 cm band of distances holds
  // more than a quarter of them.
  std::size_t crowded_band = 0;
  for (std::size_t i = 0, j = 0; i < sorted.size(); ++i) {
    while (sorted[i] - sorted[j] > 0.02f) ++j;
    crowded_band = std::max(crowded_band, i - j + 1);
  }
  EXPECT_LT(crowded_band, sorted.size() / 4) << "nearest-neighbour distances within 2 cm of each other";
  EXPECT_GE(sorted.front(), 0.4f);
}

TEST(SpawnRandomness, DeterministicForASeedAndDifferentForAnother) {
  for (const std::int64_t count : {100, 600}) {  // sparse and dense
    SCOPED_TRACE(count);
    ScenarioSpec spec = field(count, {0, 0}, {10, 10});
    const CrowdHost a = spawn(spec), b = spawn(spec);
    EXPECT_EQ(a.position, b.position);
    spec.seed = 2;
    const CrowdHost c = spawn(spec);
    ASSERT_EQ(c.position.size(), a.position.size());
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.position.size(); ++i) same += a.position[i] == c.position[i] ? 1 : 0;
    EXPECT_LT(same, a.position.size() / 2);
  }
}

ScenarioSpec at_points(std::vector<glm::vec2> points) {
  ScenarioSpec s = field(static_cast<std::int64_t>(points.size()), {0, 0}, {1, 1}, 0.25f);
  s.dt = 0.1f;
  s.groups[0].spawn.kind = Region::Kind::points;
  s.groups[0].spawn.points = std::move(points);
  return s;
}

TEST(SpawnPoints, AgentsStartExactlyAtThePointsInOrder) {
  const std::vector<glm::vec2> points = {{3.5f, 1.25f}, {0, 0}, {0.5f, 0}, {-7.125f, 2}};  // the two at 0.5 m touch
  const CrowdHost h = spawn(at_points(points));
  EXPECT_EQ(h.position, points);
  ASSERT_EQ(h.waypoints.size(), 4u);
  EXPECT_EQ(h.waypoints[0], points[0] + glm::vec2(10, 0));
}

TEST(SpawnPoints, ErrorsNameThePoint) {
  ScenarioSpec overlap = at_points({{0, 0}, {5, 0}, {5.3f, 0.1f}});
  std::string e = spawn_error(overlap);
  EXPECT_TRUE(contains(e, "groups[0].spawn.points[2]")) << e;
  EXPECT_TRUE(contains(e, "overlaps the one at points[1]")) << e;

  ScenarioSpec in_wall = at_points({{0, 0}, {5, 0}});
  in_wall.world.polygons.push_back({rect_ring({4, -1}, {6, 1}), {}});
  in_wall.world.polygon_fields.push_back("world.obstacles[0]");
  e = spawn_error(in_wall);
  EXPECT_TRUE(contains(e, "groups[0].spawn.points[1]")) << e;
  EXPECT_TRUE(contains(e, "inside obstacle world.obstacles[0]")) << e;

  ScenarioSpec near_wall = at_points({{0, 0}, {3.9f, 0}});
  near_wall.world.polygons = in_wall.world.polygons;
  near_wall.world.polygon_fields = in_wall.world.polygon_fields;
  e = spawn_error(near_wall);
  EXPECT_TRUE(contains(e, "groups[0].spawn.points[1]")) << e;
  EXPECT_TRUE(contains(e, "to a wall")) << e;

  // A later group's point on an agent of an earlier group.
  ScenarioSpec two = at_points({{0, 0}});
  GroupSpec second = two.groups[0];
  second.spawn.points = {{20, 0}, {0.2f, 0.2f}};
  second.count = 2;
  two.groups.push_back(second);
  e = spawn_error(two);
  EXPECT_TRUE(contains(e, "groups[1].spawn.points[1]")) << e;
  EXPECT_TRUE(contains(e, "overlaps agent 0 of groups[0]")) << e;

  ScenarioSpec mismatch = at_points({{0, 0}, {5, 0}});
  mismatch.groups[0].count = 3;
  e = spawn_error(mismatch);
  EXPECT_TRUE(contains(e, "groups[0].spawn.points")) << e;
  EXPECT_TRUE(contains(e, "2 points for a count of 3")) << e;

  ScenarioSpec far = at_points({{0, 0}, {2e7f, 0}});
  e = spawn_error(far);
  EXPECT_TRUE(contains(e, "groups[0].spawn.points[1]")) << e;

  ScenarioSpec resized = at_points({{0, 0}, {5, 0}});
  EXPECT_THROW(scale_agent_counts(resized, 10), Error);
}

}  // namespace
}  // namespace throng::sim
