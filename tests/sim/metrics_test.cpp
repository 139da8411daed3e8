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
  std::vector<glm::vec2> p, v;
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
  const AreaSample s = measure_area(c.p, c.v, c.flags, area);
  Index n = 0;
  double speed = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i)
    if (c.flags[i] && area.contains(c.p[i])) {
      ++n;
      speed += std::hypot(c.v[i].x, c.v[i].y);
    }
  EXPECT_EQ(s.agents, n);
  EXPECT_DOUBLE_EQ(s.area, 100.0);
  EXPECT_DOUBLE_EQ(s.density, static_cast<double>(n) / 100.0);
  EXPECT_NEAR(s.mean_speed, speed / static_cast<double>(n), 1e-6);  // float lengths
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
