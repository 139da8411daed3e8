// Planning: paths exist exactly between points of the same free component
// (checked against two raster references), keep the radius (brute force),
// and do not depend on the thread count.
#include "path/planner.h"

#include <gtest/gtest.h>

#include <numeric>

#include "core/error.h"
#include "core/exec.h"
#include "tests/path/path_worlds.h"

namespace throng::path {
namespace {

using testing::Shapes;

Planner planner_for(const Shapes& s, float radius) {
  PlanOptions o;
  o.radius = radius;
  return Planner::build(FreeSpace::build(&s.walkable, s.polygons, s.circles, o.free_space), o);
}

void expect_clear(const PlannedPath& p, const Shapes& s, float radius, const PathQuery& q) {
  ASSERT_TRUE(p.found());
  ASSERT_GE(p.points.size(), 2u);
  EXPECT_EQ(p.points.front(), q.start);
  EXPECT_EQ(p.points.back(), q.goal);
  for (std::size_t i = 1; i < p.points.size(); ++i)
    EXPECT_GE(testing::segment_true_clearance(p.points[i - 1], p.points[i], s, 0.02f), radius - 1e-3f);
  for (std::size_t i = 1; i < p.roadmap_points.size(); ++i)
    EXPECT_GE(testing::segment_true_clearance(p.roadmap_points[i - 1], p.roadmap_points[i], s, 0.05f), radius - 1e-3f);
  EXPECT_LE(p.length, polyline_length(p.roadmap_points) + 1e-3f);  // shortcuts never lengthen
  EXPECT_GE(p.length, sim::length_of(q.goal - q.start) - 1e-3f);
}

TEST(Planner, GapNarrowerThanTheAgentSeparatesTheRoom) {
  for (const float gap : {0.4f, 1.5f}) {
    Shapes s;
    s.walkable.outer = sim::rect_ring({0, 0}, {20, 10});
    const float lo = 5.0f - gap / 2, hi = 5.0f + gap / 2;
    s.polygons.push_back({sim::rect_ring({9.5f, -1}, {10.5f, lo}), {}});
    s.polygons.push_back({sim::rect_ring({9.5f, hi}, {10.5f, 11}), {}});
    const float radius = 0.3f;  // needs a 0.6 m gap
    const Planner planner = planner_for(s, radius);
    Rng rng(5);
    for (int i = 0; i < 20; ++i) {
      const PathQuery q{{static_cast<float>(rng.uniform(1, 9)), static_cast<float>(rng.uniform(1, 9))},
                        {static_cast<float>(rng.uniform(11, 19)), static_cast<float>(rng.uniform(1, 9))}};
      const PlannedPath p = planner.plan(q);
      if (gap > 2 * radius) {
        expect_clear(p, s, radius, q);
      } else {
        EXPECT_EQ(p.status, PlanStatus::Unreachable);
      }
      // Same side: always a path.
      const PathQuery same{q.start, {static_cast<float>(rng.uniform(1, 9)), static_cast<float>(rng.uniform(1, 9))}};
      expect_clear(planner.plan(same), s, radius, same);
    }
  }
}

// Raster references on a cluttered room, cells of side h:
//   strict: centre clearance >= r + h  (joined strict cells => a true path);
//   loose:  centre clearance >= r - h  (a true path => joined loose cells).
struct Raster {
  float h;
  int nx, ny;
  std::vector<std::int32_t> label;
  glm::vec2 centre(int x, int y) const { return {(x + 0.5f) * h, (y + 0.5f) * h}; }
  std::int32_t at(glm::vec2 p) const {
    const int x = static_cast<int>(p.x / h), y = static_cast<int>(p.y / h);
    return label[static_cast<std::size_t>(y * nx + x)];
  }
};
Raster raster(const Shapes& s, float h, float threshold, const std::vector<float>& clearance, int nx, int ny) {
  Raster r{h, nx, ny, std::vector<std::int32_t>(static_cast<std::size_t>(nx * ny), -1)};
  std::vector<std::int32_t> parent(static_cast<std::size_t>(nx * ny));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::int32_t a) {
    while (parent[static_cast<std::size_t>(a)] != a)
      a = parent[static_cast<std::size_t>(a)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(a)])];
    return a;
  };
  auto ok = [&](int x, int y) { return clearance[static_cast<std::size_t>(y * nx + x)] >= threshold; };
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      if (!ok(x, y)) continue;
      if (x > 0 && ok(x - 1, y)) parent[static_cast<std::size_t>(find(y * nx + x))] = find(y * nx + x - 1);
      if (y > 0 && ok(x, y - 1)) parent[static_cast<std::size_t>(find(y * nx + x))] = find((y - 1) * nx + x);
    }
  for (int i = 0; i < nx * ny; ++i)
    if (ok(i % nx, i / nx)) r.label[static_cast<std::size_t>(i)] = find(i);
  return r;
}

TEST(Planner, PathExistsExactlyWithinAFreeComponent) {
  const float radius = 0.45f, h = 0.1f;
  for (std::uint64_t seed : {11u, 12u}) {
    Shapes s = testing::obstacle_field(seed, 60);
    // A closed pen: the free space inside its hole is a component of its own.
    s.polygons.push_back({sim::rect_ring({30, 20}, {38, 28}), {sim::rect_ring({31, 21}, {37, 27})}});
    const Planner planner = planner_for(s, radius);
    const int nx = 400, ny = 300;
    std::vector<float> clearance(static_cast<std::size_t>(nx * ny));
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        clearance[static_cast<std::size_t>(y * nx + x)] = testing::true_clearance({(x + 0.5f) * h, (y + 0.5f) * h}, s);
    const Raster strict = raster(s, h, radius + h, clearance, nx, ny);
    const Raster loose = raster(s, h, radius - h, clearance, nx, ny);
    std::vector<glm::vec2> starts;
    Rng rng(seed);
    while (starts.size() < 80) {
      // Every fourth point inside the pen.
      const bool pen = starts.size() % 4 == 0;
      const int x = pen ? static_cast<int>(rng.uniform(310, 370)) : static_cast<int>(rng.below(nx));
      const int y = pen ? static_cast<int>(rng.uniform(210, 270)) : static_cast<int>(rng.below(ny));
      if (strict.label[static_cast<std::size_t>(y * nx + x)] >= 0) starts.push_back(strict.centre(x, y));
    }
    int joined = 0, apart = 0;
    std::vector<PathQuery> queries;
    for (std::size_t i = 0; i + 1 < starts.size(); i += 2) queries.push_back({starts[i], starts[i + 1]});
    const std::vector<PlannedPath> paths = planner.plan_all(queries);
    for (std::size_t i = 0; i < queries.size(); ++i) {
      const PathQuery& q = queries[i];
      if (strict.at(q.start) == strict.at(q.goal)) {
        ++joined;
        expect_clear(paths[i], s, radius, q);
      } else if (loose.at(q.start) != loose.at(q.goal)) {
        ++apart;
        EXPECT_FALSE(paths[i].found()) << "seed " << seed << " query " << i;
      } else if (paths[i].found()) {
        expect_clear(paths[i], s, radius, q);
      }
    }
    EXPECT_GT(joined, 5);
    EXPECT_GT(apart, 0) << "the field should have more than one free component for this radius";
  }
}

TEST(Planner, SameResultForAnyThreadCount) {
  const Shapes s = testing::obstacle_field(21, 40);
  const Planner planner = planner_for(s, 0.3f);
  std::vector<PathQuery> queries;
  Rng rng(3);
  while (queries.size() < 64) {
    const glm::vec2 a(static_cast<float>(rng.uniform(1, 39)), static_cast<float>(rng.uniform(1, 29)));
    const glm::vec2 b(static_cast<float>(rng.uniform(1, 39)), static_cast<float>(rng.uniform(1, 29)));
    if (planner.space().clearance(a) > 0.35f && planner.space().clearance(b) > 0.35f) queries.push_back({a, b});
  }
  std::vector<std::vector<PlannedPath>> runs;
  for (int threads : {1, 2, 4}) {
    ScopedExecution scope(Backend::Cpu, threads);
    runs.push_back(planner.plan_all(queries));
  }
  int found = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    found += runs[0][i].found();
    for (std::size_t r = 1; r < runs.size(); ++r) {
      EXPECT_EQ(runs[r][i].status, runs[0][i].status);
      EXPECT_EQ(runs[r][i].points, runs[0][i].points);
    }
  }
  EXPECT_GT(found, 40);
}

TEST(Planner, BlockedEndsAreReportedNotPlanned) {
  const Shapes s = testing::obstacle_field(4);
  const Planner planner = planner_for(s, 0.3f);
  EXPECT_EQ(planner.plan({{-5, 5}, {20, 15}}).status, PlanStatus::StartBlocked);
  EXPECT_EQ(planner.plan({{0.1f, 15}, {20, 15}}).status, PlanStatus::StartBlocked);  // too close to the wall
  EXPECT_EQ(planner.plan({{20, 15}, {5.5f, 7}}).status, PlanStatus::GoalBlocked);    // inside the L wall
  PlanOptions bad;
  bad.radius = -1;
  EXPECT_THROW(bad.validate(), Error);
  bad = {};
  bad.shortcut_clearance = 0.1f;
  bad.radius = 0.3f;
  EXPECT_THROW(bad.validate(), Error);
}

}  // namespace
}  // namespace throng::path
