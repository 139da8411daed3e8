// The Voronoi roadmap: clearance of every edge against brute force, the
// snapped free space, circle polygons, bad input.
#include "path/roadmap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "path/free_space.h"
#include "tests/path/path_worlds.h"

namespace throng::path {
namespace {

using testing::Shapes;

FreeSpace space_of(const Shapes& s, FreeSpaceOptions o = {}) {
  return FreeSpace::build(&s.walkable, s.polygons, s.circles, o);
}

// A walkable region 2000 km across with one small obstacle: containment and
// clear segments answer as brute force over the boundary does, and the
// roadmap's polylines stay short (their pieces grow instead), so the cost
// follows what the world contains rather than its extent.
TEST(FreeSpace, AHugeNearlyEmptyWorldAnswersLikeBruteForce) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({-1e6f, -1e6f}, {1e6f, 1e6f});
  s.polygons.push_back({sim::rect_ring({0, -5}, {1, 5}), {}});
  const FreeSpace fs = space_of(s);
  auto brute_contains = [&](glm::vec2 p) {
    bool inside = false;
    for (const sim::Segment& e : fs.boundary())
      if (sim::edge_crosses_ray(p, e.a, e.b)) inside = !inside;
    return inside;
  };
  auto brute_clear = [&](glm::vec2 a, glm::vec2 b, float r) {
    if (!brute_contains(a)) return false;
    for (const sim::Segment& e : fs.boundary())
      if (segment_segment_distance(a, b, e.a, e.b) < r) return false;
    return true;
  };
  const glm::vec2 points[] = {{-10, 0},    {0.5f, 0},           {0.5f, 6}, {5e5f, -3e5f},
                              {1.5e6f, 0}, {-9.99e5f, 9.99e5f}, {2, 4.9f}};
  for (const glm::vec2 p : points) EXPECT_EQ(fs.contains(p), brute_contains(p)) << p.x << ", " << p.y;
  for (const glm::vec2 a : points)
    for (const glm::vec2 b : points)
      EXPECT_EQ(fs.segment_clear(a, b, 0.3f), brute_clear(a, b, 0.3f))
          << a.x << "," << a.y << " -> " << b.x << "," << b.y;
  RoadmapOptions ro;
  ro.radius = 0.25f;
  const Roadmap map = build_roadmap(fs, ro);
  EXPECT_GT(map.edges.size(), 0u);
  // Pieces of max_step would need millions of points along the region's
  // sides; the cost follows the obstacle instead.
  EXPECT_LT(map.points.size(), 10000u);
}

TEST(CirclePolygon, ContainsTheCircleWithinTolerance) {
  for (float r : {0.05f, 0.5f, 3.0f, 40.0f}) {
    const sim::Circle c{{1.0f, -2.0f}, r};
    const sim::Ring ring = circumscribed_polygon(c, 0.01f);
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const float d = sim::length_of(ring[i] - c.center);
      EXPECT_GE(d, r * (1 - 1e-6f));
      EXPECT_LE(d, r + 0.01f + 1e-5f);
      // Every edge stays outside the circle (touches it at its midpoint).
      const glm::vec2 mid = 0.5f * (ring[i] + ring[(i + 1) % ring.size()]);
      EXPECT_NEAR(sim::length_of(mid - c.center), r, 1e-4f * std::max(1.0f, r));
    }
  }
}

TEST(FreeSpace, UnionOfOverlappingObstaclesAndContainment) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {10, 10});
  s.polygons.push_back({sim::rect_ring({2, 2}, {5, 5}), {}});
  s.polygons.push_back({sim::rect_ring({4, 4}, {7, 7}), {}});  // overlaps the first
  s.circles.push_back({{7, 7}, 1.0f});                         // overlaps the second
  const FreeSpace fs = space_of(s);
  ASSERT_EQ(fs.components().size(), 1u);
  EXPECT_EQ(fs.components()[0].holes.size(), 1u);  // one merged obstacle
  EXPECT_TRUE(fs.contains({1, 1}));
  EXPECT_FALSE(fs.contains({4.5f, 4.5f}));
  EXPECT_FALSE(fs.contains({7.6f, 7.6f}));
  EXPECT_FALSE(fs.contains({11, 1}));
  EXPECT_NEAR(fs.boundary_distance({1, 1}), 1.0f, 1e-3f);
  EXPECT_NEAR(fs.clearance({9, 1}), 1.0f, 1e-3f);
  // Snapping: vertices within half a unit of the input in each axis.
  for (const sim::Segment& seg : fs.boundary())
    for (glm::vec2 p : {seg.a, seg.b}) {
      EXPECT_NEAR(p.x * 1000.0f, std::round(p.x * 1000.0f), 1e-2f);
      EXPECT_NEAR(p.y * 1000.0f, std::round(p.y * 1000.0f), 1e-2f);
    }
}

TEST(FreeSpace, WallSplitsIntoComponents) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 10});
  s.polygons.push_back({sim::rect_ring({9.5f, -1}, {10.5f, 11}), {}});
  const FreeSpace fs = space_of(s);
  EXPECT_EQ(fs.components().size(), 2u);
  EXPECT_NE(fs.component_of({5, 5}), fs.component_of({15, 5}));
}

TEST(FreeSpace, RejectsBadOptionsAndHugeCoordinates) {
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {10, 10});
  FreeSpaceOptions o;
  o.resolution = NAN;
  EXPECT_THROW(space_of(s, o), Error);
  o = {};
  o.circle_tolerance = -1;
  EXPECT_THROW(space_of(s, o), Error);
  s.walkable.outer = sim::rect_ring({0, 0}, {2.0e6f, 10});  // 2,000 km at 1 mm: beyond 2^30 units
  try {
    space_of(s);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
}

TEST(Roadmap, EveryEdgeKeepsTheRadiusAgainstBruteForce) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const Shapes s = testing::obstacle_field(seed);
    const FreeSpace fs = space_of(s);
    for (float radius : {0.0f, 0.3f, 0.8f}) {
      RoadmapOptions o;
      o.radius = radius;
      const Roadmap map = build_roadmap(fs, o);
      ASSERT_GT(map.edge_count(), 10) << "seed " << seed << " radius " << radius;
      float worst = INFINITY;
      for (const RoadmapEdge& e : map.edges) {
        EXPECT_GE(e.min_clearance, radius);
        for (std::int32_t i = 0; i + 1 < e.point_count; ++i) {
          const glm::vec2 a = map.points[static_cast<std::size_t>(e.point_begin + i)];
          const glm::vec2 b = map.points[static_cast<std::size_t>(e.point_begin + i + 1)];
          worst = std::min(worst, testing::segment_true_clearance(a, b, s, 0.02f));
        }
        // The stored clearance agrees with brute force: never above it (the
        // snapped circles are larger), below by at most the circle tolerance.
        for (std::int32_t i = 0; i < e.point_count; ++i) {
          const auto k = static_cast<std::size_t>(e.point_begin + i);
          const float truth = testing::true_clearance(map.points[k], s);
          EXPECT_LE(map.point_clearance[k], truth + 2e-3f);
          EXPECT_GE(map.point_clearance[k], truth - 0.011f - 2e-3f);
        }
      }
      EXPECT_GE(worst, radius) << "seed " << seed << " radius " << radius;
      // The graph is consistent: CSR adjacency lists each edge at both ends.
      for (std::int32_t k = 0; k < map.edge_count(); ++k) {
        const RoadmapEdge& e = map.edges[static_cast<std::size_t>(k)];
        for (std::int32_t node : {e.a, e.b}) {
          bool listed = false;
          for (std::int32_t j = map.adjacency_begin[static_cast<std::size_t>(node)];
               j < map.adjacency_begin[static_cast<std::size_t>(node) + 1]; ++j)
            listed |= map.adjacency[static_cast<std::size_t>(j)] == k;
          EXPECT_TRUE(listed);
        }
        EXPECT_LT(sim::length_of(map.nodes[static_cast<std::size_t>(e.a)] - map.edge_point(k, 0)), 1e-3f);
        EXPECT_LT(sim::length_of(map.nodes[static_cast<std::size_t>(e.b)] - map.edge_point(k, e.point_count - 1)),
                  1e-3f);
      }
    }
  }
}

// The indexed nearest-point search answers exactly as the scan of every
// edge: the same edges, pieces, points and order, near the roadmap and far
// outside it, for few candidates and for all.
TEST(Roadmap, NearestPointsMatchBruteForce) {
  for (std::uint64_t seed : {1u, 2u}) {
    const Shapes s = testing::obstacle_field(seed);
    RoadmapOptions o;
    o.radius = 0.3f;
    const Roadmap map = build_roadmap(space_of(s), o);
    const sim::Aabb b = map.index_bounds;
    throng::Rng rng(seed);
    for (int q = 0; q < 200; ++q) {
      const glm::vec2 p(static_cast<float>(rng.uniform(b.min.x - 10.0, b.max.x + 10.0)),
                        static_cast<float>(rng.uniform(b.min.y - 10.0, b.max.y + 10.0)));
      for (std::int32_t limit : {1, 5, 32, map.edge_count()}) {
        const std::vector<EdgePoint> fast = map.nearest_points(p, limit),
                                     slow = map.nearest_points_brute_force(p, limit);
        ASSERT_EQ(fast.size(), slow.size()) << "query " << q << " limit " << limit;
        for (std::size_t k = 0; k < fast.size(); ++k) {
          EXPECT_EQ(fast[k].edge, slow[k].edge) << "query " << q << " limit " << limit << " rank " << k;
          EXPECT_EQ(fast[k].piece, slow[k].piece);
          EXPECT_EQ(fast[k].distance, slow[k].distance);
        }
      }
    }
  }
}

TEST(Roadmap, MedialAxisOfACorridorIsItsCentreLine) {
  // A 2 m wide corridor: the roadmap runs along y = 1 with clearance 1.
  Shapes s;
  s.walkable.outer = sim::rect_ring({0, 0}, {20, 2});
  const FreeSpace fs = space_of(s);
  RoadmapOptions o;
  o.radius = 0.5f;
  const Roadmap map = build_roadmap(fs, o);
  ASSERT_GT(map.edge_count(), 0);
  float along = 0;
  for (const RoadmapEdge& e : map.edges)
    for (std::int32_t i = 0; i < e.point_count; ++i) {
      const auto k = static_cast<std::size_t>(e.point_begin + i);
      EXPECT_LE(map.point_clearance[k], 1.0f + 1e-3f);
      if (map.point_clearance[k] > 0.99f) {
        EXPECT_NEAR(map.points[k].y, 1.0f, 1e-3f);
      }
    }
  for (const RoadmapEdge& e : map.edges)
    if (e.min_clearance > 0.99f) along += e.length;
  EXPECT_NEAR(along, 18.0f, 0.01f);  // the centre line ends 1 m from each end wall
}

}  // namespace
}  // namespace throng::path
