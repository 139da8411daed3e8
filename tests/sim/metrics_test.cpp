// Metrics against brute force on the host.
#include "sim/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <map>
#include <random>

#include "core/exec.h"
#include "sim/crowd.h"

namespace throng::sim {
namespace {

struct Crowd {
  std::vector<glm::vec2> p, v, goal;
  std::vector<float> r;
  std::vector<std::uint8_t> flags;
};

Crowd random_crowd(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-extent, extent), s(-1.5f, 1.5f), rad(0.2f, 0.3f);
  Crowd c;
  for (std::size_t i = 0; i < n; ++i) {
    c.p.push_back({d(rng), d(rng)});
    c.v.push_back({s(rng), s(rng)});
    c.r.push_back(rad(rng));
    c.goal.push_back({d(rng), d(rng)});
    c.flags.push_back(i % 11 == 0 ? 0 : kAgentActive);
  }
  return c;
}

TEST(Metrics, OverlapsMatchBruteForce) {
  const Crowd c = random_crowd(3000, 20.0f, 1);  // dense: many overlaps
  for (int threads : {1, 2, 4}) {
    ScopedExecution exec(Backend::Cpu, threads);
    const OverlapStats got = measure_overlaps(c.p, c.r, c.flags, 0.05f, 0.6f);
    Index pairs = 0, touching = 0;
    float depth = 0.0f, min_gap = INFINITY;
    for (std::size_t i = 0; i < c.p.size(); ++i)
      for (std::size_t j = i + 1; j < c.p.size(); ++j) {
        if (!c.flags[i] || !c.flags[j]) continue;
        const float gap = length_of(c.p[i] - c.p[j]) - c.r[i] - c.r[j];
        if (gap < 0.0f) ++touching;
        if (-gap > 0.05f) ++pairs;
        depth = std::max(depth, -gap);
        min_gap = std::min(min_gap, gap);
      }
    EXPECT_EQ(got.pairs, pairs);
    EXPECT_EQ(got.touching, touching);
    EXPECT_FLOAT_EQ(got.max_depth, depth);
    EXPECT_FLOAT_EQ(got.min_separation, min_gap);  // the closest pair overlaps, so the bins see it
    EXPECT_GT(pairs, 0);
  }
}

TEST(Metrics, NoOverlapWhenApart) {
  const std::vector<glm::vec2> p = {{0, 0}, {0.6f, 0}, {5, 5}};
  const std::vector<float> r = {0.25f, 0.25f, 0.25f};
  const std::vector<std::uint8_t> f(3, kAgentActive);
  const OverlapStats s = measure_overlaps(p, r, f, 0.0f, 1.0f);
  EXPECT_EQ(s.pairs, 0);
  EXPECT_EQ(s.touching, 0);
  EXPECT_FLOAT_EQ(s.max_depth, 0.0f);
  EXPECT_NEAR(s.min_separation, 0.1f, 1e-6f);
}

TEST(Metrics, ObstaclePenetrationsMatchTheGeometry) {
  WorldSpec spec;
  spec.has_walkable = true;
  spec.walkable = {rect_ring({-10, -10}, {10, 10}), {}};
  spec.polygons.push_back({{{0, 0}, {4, 0}, {4, 1}, {1, 1}, {1, 4}, {0, 4}}, {}});  // an L
  spec.circles.push_back({{-5, -5}, 1.0f});
  const World w = World::build(spec, 4.0f);
  Crowd c = random_crowd(4000, 11.0f, 2);  // some outside the walkable region too
  const Index got = count_obstacle_penetrations(w, c.p, c.r, c.flags, 1e-3f);
  Index want = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    if (!c.flags[i]) continue;
    const glm::vec2 q = c.p[i];
    const float r = c.r[i] - 1e-3f;
    const bool outside = !point_in_polygon(q, spec.walkable) || closest_boundary_point(q, spec.walkable).distance < r;
    const bool in_l = distance_to_polygon(q, spec.polygons[0]) < r || point_in_polygon(q, spec.polygons[0]);
    const bool in_circle = length_of(q - spec.circles[0].center) < spec.circles[0].radius + r;
    want += (outside || in_l || in_circle) ? 1 : 0;
  }
  EXPECT_EQ(got, want);
  EXPECT_GT(want, 100);
}

TEST(Metrics, AreaSpeedAndDensityMatchCounting) {
  const Crowd c = random_crowd(5000, 30.0f, 3);
  Aabb area;
  area.add({-5, -2});
  area.add({5, 8});
  const AreaSample s = measure_area(c.p, c.v, c.goal, c.flags, area);
  Index n = 0;
  double magnitude = 0, along = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i)
    if (c.flags[i] && area.contains(c.p[i])) {
      ++n;
      magnitude += std::hypot(c.v[i].x, c.v[i].y);
      // In double, by angles: |v| cos(angle between v and the way to the goal).
      const double to_goal = std::atan2(double(c.goal[i].y) - c.p[i].y, double(c.goal[i].x) - c.p[i].x);
      along += std::hypot(c.v[i].x, c.v[i].y) * std::cos(std::atan2(c.v[i].y, c.v[i].x) - to_goal);
    }
  EXPECT_EQ(s.agents, n);
  EXPECT_DOUBLE_EQ(s.area, 100.0);
  EXPECT_DOUBLE_EQ(s.density, static_cast<double>(n) / 100.0);
  EXPECT_NEAR(s.mean_speed_magnitude, magnitude / static_cast<double>(n), 1e-6);  // float lengths
  EXPECT_NEAR(s.mean_speed, along / static_cast<double>(n), 1e-5);
  EXPECT_LT(std::abs(s.mean_speed), 0.5 * s.mean_speed_magnitude);  // random headings: little net advance
  EXPECT_NEAR(s.flow, s.density * s.mean_speed, 1e-12);

  double all = 0;
  Index active = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i)
    if (c.flags[i]) {
      all += std::hypot(c.v[i].x, c.v[i].y);
      ++active;
    }
  EXPECT_NEAR(mean_speed(c.v, c.flags), all / static_cast<double>(active), 1e-6);
}

// A jam that swirls: agents fast sideways, slow towards their goals. The
// speed of the fundamental diagram is the advance, not |v|.
TEST(Metrics, AreaSpeedIsTheAdvanceTowardsTheGoalNotTheSpeed) {
  const std::vector<glm::vec2> p{{0, 0}, {1, 0}, {2, 0}, {3, 0}};
  const std::vector<glm::vec2> goal{{0, 10}, {1, 10}, {2, 10}, {3, -10}};
  const std::vector<glm::vec2> v{{1.2f, 0.1f}, {-1.2f, 0.1f}, {0.0f, 0.0f}, {0.6f, -0.8f}};
  const std::vector<std::uint8_t> flags(4, kAgentActive);
  Aabb area;
  area.add({-1, -1});
  area.add({4, 1});
  const AreaSample s = measure_area(p, v, goal, flags, area);
  EXPECT_EQ(s.agents, 4);
  EXPECT_NEAR(s.mean_speed, (0.1 + 0.1 + 0.0 + 0.8) / 4.0, 1e-6);
  EXPECT_NEAR(s.mean_speed_magnitude, (std::hypot(1.2, 0.1) * 2 + 0.0 + 1.0) / 4.0, 1e-6);
  EXPECT_NEAR(s.flow, 4.0 / 10.0 * s.mean_speed, 1e-9);
}

TEST(Metrics, DensityHistogramCountsEachActiveAgentOnceInTheBinOfItsCell) {
  const Crowd c = random_crowd(4000, 15.0f, 4);
  const DensityHistogram h = density_histogram(c.p, c.flags, 2.0f, 0.5f);
  std::map<std::pair<std::int32_t, std::int32_t>, int> per_cell;
  for (std::size_t i = 0; i < c.p.size(); ++i)
    if (c.flags[i]) ++per_cell[{cell_coord(c.p[i].x, 2.0f), cell_coord(c.p[i].y, 2.0f)}];
  std::array<std::int64_t, kDensityBins> want{};
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    if (!c.flags[i]) continue;
    const float density = static_cast<float>(per_cell[{cell_coord(c.p[i].x, 2.0f), cell_coord(c.p[i].y, 2.0f)}]) / 4.0f;
    ++want[static_cast<std::size_t>(std::min(static_cast<int>(density / 0.5f), kDensityBins - 1))];
  }
  EXPECT_EQ(h.agents, want);
}

TEST(Metrics, ArrivalStats) {
  const ArrivalStats s = arrival_stats({-1.0f, 10.0f, 20.0f, -1.0f, 30.0f});
  EXPECT_EQ(s.total, 5);
  EXPECT_EQ(s.arrived, 3);
  EXPECT_DOUBLE_EQ(s.mean_time, 20.0);
  EXPECT_DOUBLE_EQ(s.min_time, 10.0);
  EXPECT_DOUBLE_EQ(s.max_time, 30.0);
}

}  // namespace
}  // namespace throng::sim
