// The routes `throng route` reports: on the built-in maze (routes planned on
// the roadmap), each sampled route starts where its agent stands, ends at
// its goal, and every segment of it runs through free space (sampled every
// 5 cm against the world); its length adds up; GeoJSON and CSV hold the same
// points.
#include "io/routes_output.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "io/scenario_yaml.h"

namespace throng::io {
namespace {

// With `planning: field`: the way down the field round the corner of an
// L-shaped corridor (RiMEA test 6's), from the agent to its goal, keeps the
// agent's radius from the walls (the field's blocked nodes) and bends at
// the corner only.
TEST(RoutesOutput, FieldRoutesFollowTheFieldRoundTheCorner) {
  const LoadedScenario corner = parse_scenario(
      "name: corner\nplanning: field\nworld:\n  walkable: {polygon: [[0, 0], [12, 0], [12, 12], [10, 12], [10, 2], "
      "[0, 2]]}\ngroups:\n  - count: 20\n    radius: 0.25\n    spawn: {rect: {min: [0.3, 0.3], max: [6, 1.7]}}\n"
      "    goal: {point: [11, 11.4]}\n",
      "corner.yaml");
  const std::unique_ptr<sim::Simulation> sim = build_simulation(corner);
  const std::vector<AgentRoute> routes = sample_routes(*sim, 5);
  ASSERT_EQ(routes.size(), 5u);
  for (const AgentRoute& r : routes) {
    SCOPED_TRACE(r.agent);
    ASSERT_GE(r.points.size(), 3u);  // at least one bend
    EXPECT_EQ(r.points.front(), sim->positions()[static_cast<std::size_t>(r.agent)]);
    EXPECT_EQ(r.points.back(), glm::vec2(11, 11.4f));
    EXPECT_LT(r.points.size(), 12u);  // thinned to its bends
    for (std::size_t s = 1; s < r.points.size(); ++s) {
      const glm::vec2 a = r.points[s - 1], b = r.points[s];
      const int n = static_cast<int>(std::ceil(sim::length_of(b - a) / 0.05f));
      for (int i = 0; i <= n; ++i) {
        const glm::vec2 p = a + (b - a) * (static_cast<float>(i) / static_cast<float>(std::max(n, 1)));
        // Inside the L, at least 0.15 m off its walls (radius 0.25 m less the thinning's 10 cm).
        const bool leg1 = p.x >= 0.15f && p.x <= 11.85f && p.y >= 0.15f && p.y <= 1.85f;
        const bool leg2 = p.x >= 10.15f && p.x <= 11.85f && p.y >= 0.15f && p.y <= 12.0f;
        ASSERT_TRUE(leg1 || leg2) << "segment " << s << " at " << p.x << ", " << p.y;
      }
    }
    // The corner costs a little: no more than the legs' sum from start to (11, 1) to the goal.
    const glm::vec2 start = r.points.front();
    EXPECT_LE(r.length_m, sim::length_of(glm::vec2(11, 1) - start) + 10.4 + 1e-3);
  }
}

// In a periodic corridor agents walk in a direction for ever: a route is
// the way straight on to the corridor's end, not to the goal 1 km ahead.
TEST(RoutesOutput, ADirectionsRouteEndsAtTheAreasEdge) {
  const LoadedScenario ring = parse_scenario(
      "name: ring\nplanning: none\nworld:\n  walkable: {rect: {min: [0, 0], max: [30, 4]}}\n  periodic: [x]\n"
      "groups:\n  - count: 10\n    spawn: {rect: {min: [1, 1], max: [20, 3]}}\n    goal: {direction: [-1, 0]}\n",
      "ring.yaml");
  const std::unique_ptr<sim::Simulation> sim = build_simulation(ring);
  for (const AgentRoute& r : sample_routes(*sim, 4)) {
    ASSERT_EQ(r.points.size(), 2u);
    EXPECT_EQ(r.points.front(), sim->positions()[static_cast<std::size_t>(r.agent)]);
    EXPECT_FLOAT_EQ(r.points.back().x, 0.0f);
    EXPECT_FLOAT_EQ(r.points.back().y, r.points.front().y);
    EXPECT_NEAR(r.length_m, r.points.front().x, 1e-4);
  }
}

TEST(RoutesOutput, SampledRoutesRunThroughFreeSpaceFromStartToGoal) {
  LoadedScenario maze = load_builtin_scenario("maze");
  sim::scale_agent_counts(maze.spec, 40);
  const std::unique_ptr<sim::Simulation> sim = build_simulation(maze);
  const std::vector<AgentRoute> routes = sample_routes(*sim, 7);
  ASSERT_EQ(routes.size(), 7u);
  const std::vector<glm::vec2> start = sim->positions();
  const std::vector<float> radius = sim->crowd().radius.to_vector();
  bool detour = false;
  for (std::size_t k = 0; k < routes.size(); ++k) {
    const AgentRoute& r = routes[k];
    SCOPED_TRACE(r.agent);
    EXPECT_EQ(r.agent, static_cast<Index>(k * 40 / 7));
    ASSERT_GE(r.points.size(), 2u);
    EXPECT_EQ(r.points.front(), start[static_cast<std::size_t>(r.agent)]);
    double length = 0;
    for (std::size_t s = 1; s < r.points.size(); ++s) {
      const glm::vec2 a = r.points[s - 1], b = r.points[s];
      length += sim::length_of(b - a);
      const int n = static_cast<int>(std::ceil(sim::length_of(b - a) / 0.05f));
      for (int i = 0; i <= n; ++i) {
        const glm::vec2 p = a + (b - a) * (static_cast<float>(i) / static_cast<float>(std::max(n, 1)));
        ASSERT_TRUE(sim->world().in_free_space(p)) << "segment " << s << " leaves free space at " << p.x << ", " << p.y;
      }
    }
    EXPECT_NEAR(r.length_m, length, 1e-3);
    EXPECT_GE(r.length_m, r.straight_m - 1e-6);
    detour = detour || r.length_m > 1.2 * r.straight_m;
    EXPECT_GT(radius[static_cast<std::size_t>(r.agent)], 0.0f);
  }
  EXPECT_TRUE(detour) << "the maze's walls make routes longer than the straight line";

  const nlohmann::json j = routes_geojson(routes);
  ASSERT_EQ(j["features"].size(), routes.size());
  const nlohmann::json& f = j["features"][2];
  EXPECT_EQ(f["geometry"]["type"], "LineString");
  EXPECT_EQ(f["properties"]["agent"], routes[2].agent);
  EXPECT_EQ(f["geometry"]["coordinates"].size(), routes[2].points.size());
  EXPECT_NEAR(f["geometry"]["coordinates"][1][0].get<double>(), routes[2].points[1].x, 1e-3);
  std::istringstream csv(routes_csv(routes));
  std::string line;
  std::size_t rows = 0, points = 0;
  std::getline(csv, line);
  EXPECT_EQ(line, "agent,group,point,x,y");
  while (std::getline(csv, line)) ++rows;
  for (const AgentRoute& r : routes) points += r.points.size();
  EXPECT_EQ(rows, points);
}

}  // namespace
}  // namespace throng::io
