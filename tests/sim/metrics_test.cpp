// Metrics against brute force on the host.
#include "sim/metrics.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
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

// ---- Voronoi density and speed ------------------------------------------

// Agents on a square lattice of spacing a have square cells of side a, which
// tile any area inside the lattice: the Voronoi density is 1/a^2 exactly,
// and the speed is the agents' common speed.
TEST(MetricsVoronoi, SquareLatticeDensityIsOneOverSpacingSquared) {
  for (const float a : {1.0f, 0.7f, 0.45f}) {
    SCOPED_TRACE(a);
    std::vector<glm::vec2> p, v, goal;
    for (int y = -30; y <= 30; ++y)
      for (int x = -30; x <= 30; ++x) {
        p.push_back({a * static_cast<float>(x), a * static_cast<float>(y)});
        v.push_back({1.2f, 0.0f});
        goal.push_back({1000.0f, a * static_cast<float>(y)});
      }
    const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
    Aabb area;  // not aligned with the cells
    area.add({-2.3f * a, -1.1f * a});
    area.add({2.9f * a, 3.4f * a});
    const double size = (static_cast<double>(area.max.x) - area.min.x) * (static_cast<double>(area.max.y) - area.min.y);
    const VoronoiSample s =
        measure_area_voronoi(p, v, goal, flags, area, 1.0f);  // corners at a/sqrt(2) < 1: cut by no disc
    // Exact up to the rounding of the lattice's float coordinates.
    EXPECT_NEAR(s.density * a * a, 1.0, 1e-6);
    EXPECT_NEAR(s.speed, 1.2, 1e-6);
    EXPECT_NEAR(s.speed_magnitude, 1.2, 1e-6);
    EXPECT_NEAR(s.covered, size, 1e-6 * size);
  }
}

// A lone agent's cell is the disc polygon: density 1 / its area where the
// area holds the whole cell; an area without agents nearby reads 0.
TEST(MetricsVoronoi, LoneAgentHasTheDiscCell) {
  const std::vector<glm::vec2> p{{0, 0}}, v{{0.5f, 0}}, goal{{10, 0}};
  const std::vector<std::uint8_t> flags{kAgentActive};
  constexpr double kPi = 3.14159265358979323846;
  const double disc = 0.5 * kVoronoiDiscVertices * 1.5 * 1.5 * std::sin(2.0 * kPi / kVoronoiDiscVertices);
  Aabb big;
  big.add({-5, -5});
  big.add({5, 5});
  const VoronoiSample s = measure_area_voronoi(p, v, goal, flags, big, 1.5f);
  EXPECT_NEAR(s.density, 1.0 / 100.0, 1e-12);
  EXPECT_NEAR(s.covered, disc, 1e-9);
  EXPECT_NEAR(s.speed, 0.5 * disc / 100.0, 1e-9);
  Aabb far;
  far.add({20, 20});
  far.add({30, 30});
  EXPECT_EQ(measure_area_voronoi(p, v, goal, flags, far, 1.5f).density, 0.0);
}

// Inside the regular n-gon of radius r around c with a corner at angle 0.
bool in_disc_polygon(glm::dvec2 q, glm::dvec2 c, double r) {
  constexpr double kPi = 3.14159265358979323846;
  const double step = 2.0 * kPi / kVoronoiDiscVertices;
  const glm::dvec2 d = q - c;
  double angle = std::atan2(d.y, d.x);
  if (angle < 0) angle += 2.0 * kPi;
  const double mid = (std::floor(angle / step) + 0.5) * step;  // the edge's normal
  return d.x * std::cos(mid) + d.y * std::sin(mid) <= r * std::cos(0.5 * step);
}

// Cells of hand-placed points against point sampling: a sample belongs to
// the cell of its nearest point, if inside that point's disc polygon.
TEST(MetricsVoronoi, CellsMatchPointSampling) {
  // Close points cut each other's cells; (3, 3) and (-2.6, -2.4) are farther
  // than two cut-offs from every other: their cells are whole discs.
  const std::vector<glm::vec2> p{{0, 0}, {1, 0}, {0.3f, 0.9f}, {-0.8f, 0.4f}, {3, 3}, {0.5f, -1.2f}, {-2.6f, -2.4f}};
  const float cutoff = 1.3f;
  const std::vector<ConvexPolygon> cells = voronoi_cells(p, cutoff);
  ASSERT_EQ(cells.size(), p.size());
  Aabb rect;  // an area cutting some cells
  rect.add({-0.5f, -0.7f});
  rect.add({1.4f, 2.6f});
  const double h = 0.005;
  std::vector<double> whole(p.size(), 0.0), part(p.size(), 0.0);
  for (double y = -4.5 + h / 2; y < 5.0; y += h)
    for (double x = -4.5 + h / 2; x < 5.0; x += h) {
      std::size_t best = 0;
      double best_d = INFINITY;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double d = std::hypot(x - p[i].x, y - p[i].y);
        if (d < best_d) best_d = d, best = i;
      }
      if (!in_disc_polygon({x, y}, glm::dvec2(p[best]), cutoff)) continue;
      whole[best] += h * h;
      if (x >= rect.min.x && x <= rect.max.x && y >= rect.min.y && y <= rect.max.y) part[best] += h * h;
    }
  double density = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_NEAR(polygon_area(cells[i]), whole[i], 0.01);
    EXPECT_NEAR(polygon_area(clip_to_rect(cells[i], rect)), part[i], 0.01);
    density += part[i] / whole[i];
  }
  const std::vector<glm::vec2> v(p.size(), glm::vec2(0.0f)), goal(p.size(), glm::vec2(0.0f));
  const std::vector<std::uint8_t> flags(p.size(), kAgentActive);
  const double size = static_cast<double>(rect.size().x) * rect.size().y;
  EXPECT_NEAR(measure_area_voronoi(p, v, goal, flags, rect, cutoff).density, density / size, 0.005);
  // Sanity of the reference: the cells of the close points are cut by their neighbours, the far one is not.
  EXPECT_LT(whole[0], 0.5 * 3.14159 * cutoff * cutoff);
  EXPECT_GT(whole[4], 0.99 * 3.14159 * cutoff * cutoff);
  EXPECT_GT(whole[6], 0.99 * 3.14159 * cutoff * cutoff);
}

TEST(MetricsVoronoi, SameResultOnOneAndFourThreads) {
  const Crowd c = random_crowd(6000, 15.0f, 5);
  Aabb area;
  area.add({-4, -3});
  area.add({5, 6});
  VoronoiSample one, four;
  {
    ScopedExecution exec(Backend::Cpu, 1);
    one = measure_area_voronoi(c.p, c.v, c.goal, c.flags, area, 2.0f);
  }
  {
    ScopedExecution exec(Backend::Cpu, 4);
    four = measure_area_voronoi(c.p, c.v, c.goal, c.flags, area, 2.0f);
  }
  EXPECT_EQ(one.density, four.density);
  EXPECT_EQ(one.speed, four.speed);
  EXPECT_EQ(one.speed_magnitude, four.speed_magnitude);
  // Dense enough that the cells tile the area: close to the classic count.
  EXPECT_NEAR(one.covered, 81.0, 1e-6);
  EXPECT_NEAR(one.density, measure_area(c.p, c.v, c.goal, c.flags, area).density, 0.1 * one.density);
}

// ---- line crossings and the N-t flow -------------------------------------

// Agents at at(i, t), stepped by hand every dt: every step's crossings.
std::vector<LineCrossing> walk_crossings(std::size_t n, const std::function<glm::vec2(std::size_t, double)>& at,
                                         const std::vector<std::uint8_t>& flags, const std::vector<Segment>& lines,
                                         double dt, int steps) {
  Aabb bounds;
  for (const Segment& s : lines) bounds.add(s.a), bounds.add(s.b);
  std::vector<LineCrossing> all;
  std::vector<glm::vec2> before(n), after(n);
  for (std::size_t i = 0; i < n; ++i) before[i] = at(i, 0.0);
  for (int k = 1; k <= steps; ++k) {
    for (std::size_t i = 0; i < n; ++i) after[i] = at(i, k * dt);
    const std::vector<LineCrossing> step =
        line_crossings(before, flags, after, flags, lines, bounds, (k - 1) * dt, k * dt);
    all.insert(all.end(), step.begin(), step.end());
    before = after;
  }
  return all;
}

// Walkers crossing x = 0 between y = -5 and 5 at known times. The line runs
// from (0, 5) to (0, -5): its left, the positive side, is +x.
TEST(MetricsLines, CrossingsOfStraightWalkersAtKnownTimes) {
  struct Walker {
    float v, t_cross, y;  // speed along x (negative: towards -x), time at x = 0, y
  };
  const std::vector<Walker> w{{1.0f, 1.25f, 0.0f}, {1.3f, 2.0f, 1.0f},  {0.8f, 3.05f, -2.0f},
                              {1.1f, 4.5f, 4.0f},  {-1.2f, 2.7f, 0.5f}, {1.0f, 2.0f, 6.0f} /* beside the line */,
                              {1.0f, 1.5f, 0.0f} /* inactive */};
  std::vector<std::uint8_t> flags(w.size(), kAgentActive);
  flags[6] = 0;
  const std::vector<Segment> lines{{{0, 5}, {0, -5}}};
  const auto at = [&](std::size_t i, double t) {
    return glm::vec2(static_cast<float>(w[i].v * (t - w[i].t_cross)), w[i].y);
  };
  const std::vector<LineCrossing> got = walk_crossings(w.size(), at, flags, lines, 0.1, 60);
  std::vector<double> positive, negative;
  for (const LineCrossing& x : got) {
    EXPECT_EQ(x.line, 0);
    EXPECT_NEAR(x.time, w[static_cast<std::size_t>(x.agent)].t_cross, 1e-5) << x.agent;
    (x.direction > 0 ? positive : negative).push_back(x.time);
  }
  ASSERT_EQ(positive.size(), 4u);
  ASSERT_EQ(negative.size(), 1u);
  EXPECT_NEAR(negative[0], 2.7, 1e-5);
  // N-t: 4 crossings from 1.25 s to 4.5 s: (4 - 1) / 3.25 persons/s over a 10 m line.
  const LineFlow f = line_flow(positive, 10.0);
  EXPECT_EQ(f.crossings, 4);
  EXPECT_TRUE(f.timed);
  EXPECT_NEAR(f.first_time, 1.25, 1e-5);
  EXPECT_NEAR(f.last_time, 4.5, 1e-5);
  EXPECT_NEAR(f.flow, 3.0 / 3.25, 1e-5);
  EXPECT_NEAR(f.specific_flow, 3.0 / 32.5, 1e-6);
  EXPECT_FALSE(line_flow(negative, 10.0).timed);  // one crossing: no period
  EXPECT_EQ(line_flow(negative, 10.0).flow, 0.0);
}

// The steady flow: a door that passes one person every 0.5 s once the
// crowd presses on it, after a slow build-up (crossings 3 s apart up to
// t[4]) and before a slow emptying (3 s apart from t[36]): of 40
// crossings, t[4] (10%) to t[36] (90%) span 32 intervals of 0.5 s.
TEST(MetricsLines, SteadyFlowLeavesOutTheBuildUpAndTheEmptying) {
  std::vector<double> t;
  for (int k = 0; k < 5; ++k) t.push_back(3.0 * k);
  for (int k = 0; k < 32; ++k) t.push_back(t.back() + 0.5);
  for (int k = 0; k < 3; ++k) t.push_back(t.back() + 3.0);
  const LineFlow f = line_flow(t, 2.0);
  EXPECT_NEAR(f.steady_flow, 2.0, 1e-12);
  EXPECT_NEAR(f.steady_specific_flow, 1.0, 1e-12);
  EXPECT_NEAR(f.flow, 39.0 / (t.back() - t.front()), 1e-12);  // the whole run: far less
  EXPECT_LT(f.flow, 0.6 * f.steady_flow);
  // Below 10 crossings there is no steady part to tell apart: the whole run's.
  const std::vector<double> few(t.begin(), t.begin() + 9);
  EXPECT_DOUBLE_EQ(line_flow(few, 2.0).steady_flow, line_flow(few, 2.0).flow);
}

// An agent that crosses, turns back and crosses again is counted each
// time, once each way; one that stops exactly on the line and walks on is
// counted once, when it reached the line.
TEST(MetricsLines, TurningBackAndStoppingOnTheLine) {
  const std::vector<Segment> lines{{{0, 5}, {0, -5}}};
  const std::vector<std::uint8_t> flags(2, kAgentActive);
  const auto at = [](std::size_t i, double t) {
    if (i == 0) return glm::vec2(static_cast<float>(t <= 1.0 ? t - 0.5 : 1.5 - t), 0.0f);  // +x until 1 s, then back
    // 0.25 m steps, resting on x = 0 from 0.5 s to 1 s.
    const double x = t < 0.5 ? t * 0.5 - 0.25 : (t < 1.0 ? 0.0 : (t - 1.0) * 0.5);
    return glm::vec2(static_cast<float>(x), 1.0f);
  };
  const std::vector<LineCrossing> got = walk_crossings(2, at, flags, lines, 0.25, 8);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].agent, 0);
  EXPECT_EQ(got[0].direction, 1);
  EXPECT_NEAR(got[0].time, 0.5, 1e-6);
  EXPECT_EQ(got[1].agent, 1);
  EXPECT_EQ(got[1].direction, 1);
  EXPECT_NEAR(got[1].time, 1.0, 1e-6);  // leaves the line then
  EXPECT_EQ(got[2].agent, 0);
  EXPECT_EQ(got[2].direction, -1);
  EXPECT_NEAR(got[2].time, 1.5, 1e-6);
}

// Many agents, several lines: the same list on 1 and 4 threads, and the
// same as a brute-force check of each step against each line.
TEST(MetricsLines, SameCrossingsOnOneAndFourThreadsAndAsBruteForce) {
  const Crowd c = random_crowd(20000, 20.0f, 6);
  std::vector<glm::vec2> after = c.p;
  for (std::size_t i = 0; i < after.size(); ++i) after[i] += 0.5f * c.v[i];
  std::vector<std::uint8_t> flags_after = c.flags;
  flags_after[5] = 0;  // despawned during the step
  const std::vector<Segment> lines{{{-10, -10}, {10, 10}}, {{0, -15}, {0, 15}}, {{-5, 3}, {12, 3}}};
  Aabb bounds;
  for (const Segment& s : lines) bounds.add(s.a), bounds.add(s.b);
  std::vector<LineCrossing> one, four;
  {
    ScopedExecution exec(Backend::Cpu, 1);
    one = line_crossings(c.p, c.flags, after, flags_after, lines, bounds, 2.0, 2.5);
  }
  {
    ScopedExecution exec(Backend::Cpu, 4);
    four = line_crossings(c.p, c.flags, after, flags_after, lines, bounds, 2.0, 2.5);
  }
  ASSERT_EQ(one.size(), four.size());
  for (std::size_t k = 0; k < one.size(); ++k) {
    EXPECT_EQ(one[k].agent, four[k].agent);
    EXPECT_EQ(one[k].line, four[k].line);
    EXPECT_EQ(one[k].direction, four[k].direction);
    EXPECT_EQ(one[k].time, four[k].time);
  }
  std::size_t want = 0, k = 0;
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    if (!c.flags[i] || !flags_after[i]) continue;
    for (std::size_t l = 0; l < lines.size(); ++l) {
      glm::vec2 q;
      if (!segments_intersect(c.p[i], after[i], lines[l].a, lines[l].b, &q)) continue;
      ++want;
      ASSERT_LT(k, one.size());
      EXPECT_EQ(one[k].agent, static_cast<Index>(i));
      EXPECT_EQ(one[k].line, static_cast<std::int32_t>(l));
      // The side it ends on: left of the line is positive.
      EXPECT_EQ(one[k].direction, cross2(lines[l].b - lines[l].a, after[i] - lines[l].a) > 0 ? 1 : -1);
      const double s = length_of(q - c.p[i]) / length_of(after[i] - c.p[i]);
      EXPECT_NEAR(one[k].time, 2.0 + 0.5 * s, 1e-4);
      ++k;
    }
  }
  EXPECT_EQ(one.size(), want);
  EXPECT_GT(want, 300u);
}

}  // namespace
}  // namespace throng::sim
