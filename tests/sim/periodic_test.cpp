// Periodic boundaries (core/periodic.h): the minimum image, bins that wrap,
// neighbours and walls across the seam, the step across it, and the metrics
// that look across it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/buffer.h"
#include "core/error.h"
#include "core/exec.h"
#include "core/periodic.h"
#include "sim/grid.h"
#include "sim/metrics.h"
#include "sim/simulation.h"
#include "tests/sim/same_bits_on_threads.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

constexpr float kLength = 20.0f, kWidth = 4.0f;

// A corridor kLength x kWidth from the origin `at`, periodic along x.
ScenarioSpec ring_corridor(ModelKind model, glm::vec2 at = glm::vec2(0.0f)) {
  ScenarioSpec s = test::straight_spec("ring", model, 0.05f, 30.0f);
  s.stop_when_arrived = false;
  s.world.has_walkable = true;
  s.world.walkable.outer = {at, at + glm::vec2(kLength, 0.0f), at + glm::vec2(kLength, kWidth),
                            at + glm::vec2(0.0f, kWidth)};
  s.world.periodic_x = true;
  return s;
}

// A group of agents at `points`, walking in `direction`.
GroupSpec walkers(std::vector<glm::vec2> points, glm::vec2 direction) {
  GroupSpec g;
  g.count = static_cast<std::int64_t>(points.size());
  g.radius = 0.2f;
  g.speed = {1.3f, 0.0f, 0.5f, 2.0f};
  g.spawn.kind = Region::Kind::points;
  g.spawn.points = std::move(points);
  g.goal.kind = GoalSpec::Kind::Direction;
  g.goal.value = direction;
  return g;
}

// A crowd filling the corridor at about `density` P/m^2, walking +x.
GroupSpec filling(double density, glm::vec2 at = glm::vec2(0.0f)) {
  GroupSpec g;
  g.count = static_cast<std::int64_t>(density * kLength * kWidth);
  g.radius = 0.2f;
  g.speed = {1.34f, 0.05f, 1.24f, 1.44f};  // as uniform as RiMEA 3.0 test 4 asks
  g.spawn.kind = Region::Kind::rect;
  g.spawn.min = at + glm::vec2(0.2f);
  g.spawn.max = at + glm::vec2(kLength - 0.2f, kWidth - 0.2f);
  g.goal.kind = GoalSpec::Kind::Direction;
  g.goal.value = glm::vec2(1.0f, 0.0f);
  return g;
}

TEST(Periodic, NearestImageAndWrapFollowTheClosedForm) {
  const Periodic p{{-5.0f, 2.0f}, {10.0f, 0.0f}};
  EXPECT_TRUE(p.wraps());
  EXPECT_FALSE(Periodic{}.wraps());
  // Of x = 4.5 + 10 k, the one nearest -4.5 is -5.5; y does not wrap.
  EXPECT_FLOAT_EQ(p.near({4.5f, 7.0f}, {-4.5f, 3.0f}).x, -5.5f);
  EXPECT_FLOAT_EQ(p.near({4.5f, 7.0f}, {-4.5f, 3.0f}).y, 7.0f);
  EXPECT_FLOAT_EQ(p.near({1.0f, 0.0f}, {2.0f, 0.0f}).x, 1.0f);   // already nearest
  EXPECT_FLOAT_EQ(p.near({33.0f, 0.0f}, {0.0f, 0.0f}).x, 3.0f);  // several periods away
  EXPECT_FLOAT_EQ(p.wrap({5.25f, 9.0f}).x, -4.75f);
  EXPECT_FLOAT_EQ(p.wrap({-15.5f, 9.0f}).x, 4.5f);
  EXPECT_FLOAT_EQ(p.wrap({-5.0f, 9.0f}).x, -5.0f);
  EXPECT_FLOAT_EQ(p.wrap({-5.0f, 9.0f}).y, 9.0f);
  // A hair below the origin must land inside [origin, origin + period),
  // also where origin + (period - a hair) rounds to origin + period.
  const float x = p.wrap({std::nextafter(-5.0f, -6.0f), 0.0f}).x;
  EXPECT_GE(x, -5.0f);
  EXPECT_LT(x, 5.0f);
  for (const glm::vec2 o : {glm::vec2(60.0f, 10.0f), glm::vec2(100.0f, 30.0f), glm::vec2(3.0f, 2.0f)}) {
    const Periodic q{{o.x, 0.0f}, {o.y, 0.0f}};
    const float w = q.wrap({std::nextafter(o.x, 0.0f), 0.0f}).x;
    EXPECT_GE(w, o.x) << o.x;
    EXPECT_LT(w, o.x + o.y) << o.x;
  }
}

TEST(Periodic, BinsTileThePeriodInAnEvenNumberOfCellsAndWrap) {
  const Periodic p{{1.0f, 0.0f}, {10.0f, 0.0f}};
  const std::vector<glm::vec2> at = {{1.1f, 0.5f}, {10.9f, 0.5f}, {6.0f, 0.5f}};
  const std::vector<std::uint8_t> flags(at.size(), kAgentActive);
  const Buffer<glm::vec2> positions(std::span<const glm::vec2>(at), current_memory());
  const Buffer<std::uint8_t> f(std::span<const std::uint8_t>(flags), current_memory());
  AgentGrid bins(1.3f, p);  // floor(10 / 1.3) = 7 -> 6 cells of 1.667 m
  bins.rebuild(positions.span(), f.span());
  const GridView g = bins.view();
  EXPECT_EQ(g.wrap_x, 6);
  EXPECT_FLOAT_EQ(g.cell_size, 10.0f / 6.0f);
  EXPECT_FLOAT_EQ(bins.cell_size(), 1.3f);  // the side asked for, which metrics pass on
  EXPECT_EQ(g.cell_x(1.1f), 0);
  EXPECT_EQ(g.cell_x(10.9f), 5);
  // The 3x3 around the first cell reaches the last one across the seam, not the middle.
  std::vector<std::int32_t> seen;
  if (g.items.size() > 0) {
    // (Host memory in CPU builds; the GPU tests run the same stages.)
    for_each_in_3x3(g, at[0], [&](std::int32_t j) { seen.push_back(j); });
  }
  EXPECT_EQ(seen, (std::vector<std::int32_t>{1, 0}));
  EXPECT_THROW(AgentGrid(3.0f, p), Error);  // 10 m is under four cells of 3 m
}

// Every model, seen through the seam, steers as it does in the middle: a
// pair meeting head-on across the seam walks the paths of the same pair
// met in the middle of the corridor, moved by half a period.
TEST(Periodic, APairMeetingAcrossTheSeamMovesAsInTheMiddle) {
  for (ModelKind model : {ModelKind::CollisionFreeSpeed, ModelKind::Priority, ModelKind::Ttc, ModelKind::SocialForce}) {
    SCOPED_TRACE(static_cast<int>(model));
    auto run = [&](float x0) {
      ScenarioSpec s = ring_corridor(model);
      const Periodic ring{{0.0f, 0.0f}, {kLength, 0.0f}};
      s.groups = {walkers({ring.wrap({x0 - 1.5f, 2.0f})}, {1.0f, 0.0f}),
                  walkers({ring.wrap({x0 + 1.5f, 2.1f})}, {-1.0f, 0.0f})};
      Simulation sim(s);
      std::vector<std::vector<glm::vec2>> track;
      for (int k = 0; k < 60; ++k) {
        sim.step();
        track.push_back(sim.positions());
      }
      return track;
    };
    const auto seam = run(0.0f), middle = run(0.5f * kLength);
    const Periodic p{{0.0f, 0.0f}, {kLength, 0.0f}};
    float worst = 0.0f, closest = INFINITY;
    for (std::size_t k = 0; k < seam.size(); ++k)
      for (std::size_t i = 0; i < 2; ++i) {
        const glm::vec2 moved = seam[k][i] + glm::vec2(0.5f * kLength, 0.0f);
        worst = std::max(worst, length_of(p.near(moved, middle[k][i]) - middle[k][i]));
        closest = std::min(closest, length_of(p.near(seam[k][0], seam[k][1]) - seam[k][1]));
      }
    EXPECT_LT(worst, 2e-3f) << "paths differ by " << worst << " m";
    EXPECT_GT(closest, 0.3f) << "the pair must pass each other, not walk through";
    EXPECT_LT(std::fabs(seam[0][0].y - seam.back()[0].y) + std::fabs(seam[0][1].y - seam.back()[1].y), 2.0f);
  }
}

// The bins against the all-pairs reference (every agent, at its nearest
// image), as away from the seam (Bins.* in simulation_test.cpp): the
// priority model the same bits; the summing models, whose sums the
// visiting order rounds differently, one step from the same state.
TEST(Periodic, BinnedNeighboursAcrossTheSeamEqualAllPairs) {
  for (ModelKind model : {ModelKind::Priority, ModelKind::CollisionFreeSpeed, ModelKind::Ttc, ModelKind::SocialForce}) {
    SCOPED_TRACE(static_cast<int>(model));
    ScenarioSpec s = ring_corridor(model);
    s.groups = {filling(1.5)};
    s.seed = 7;
    SimulationOptions reference;
    reference.neighbours = NeighbourSearch::AllPairs;
    Simulation binned(s), all_pairs(s, reference);
    if (model == ModelKind::Priority) {
      binned.run(100);
      all_pairs.run(100);
      EXPECT_TRUE(test::same_bits(binned.positions(), all_pairs.positions()));
      continue;
    }
    binned.run(40);
    test::copy_step_state(all_pairs.crowd(), binned.crowd());
    binned.step();
    all_pairs.step();
    const auto a = binned.velocities(), b = all_pairs.velocities(), p = binned.positions();
    float worst = 0.0f;
    Index by_seam = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      worst = std::max(worst, length_of(a[i] - b[i]));
      by_seam += (p[i].x < 1.0f || p[i].x > kLength - 1.0f) ? 1 : 0;
    }
    EXPECT_LT(worst, 1e-4f);
    EXPECT_GT(by_seam, 5);
  }
}

// Walls across the seam: an agent walking into the seam with a pillar just
// beyond it stays off the pillar (its copy, seen from this side).
TEST(Periodic, AnObstacleJustAcrossTheSeamIsSeenFromThisSide) {
  ScenarioSpec s = ring_corridor(ModelKind::CollisionFreeSpeed);
  s.world.circles = {{{0.6f, 2.0f}, 0.5f}};
  s.groups = {walkers({{kLength - 3.0f, 2.0f}, {kLength - 3.0f, 1.0f}}, {1.0f, 0.0f})};
  Simulation sim(s);
  const Periodic p = sim.world().periodic();
  float closest = INFINITY;
  bool wrapped = false;
  for (int k = 0; k < 200; ++k) {
    sim.step();
    for (const glm::vec2 q : sim.positions()) {
      closest = std::min(closest, length_of(p.near(q, {0.6f, 2.0f}) - glm::vec2(0.6f, 2.0f)));
      EXPECT_GE(q.x, 0.0f);
      EXPECT_LT(q.x, kLength);
      wrapped = wrapped || (q.x < 5.0f);
    }
  }
  EXPECT_TRUE(wrapped) << "the agents must have crossed the seam";
  EXPECT_GE(closest, 0.5f + 0.2f - 1e-3f) << "an agent entered the pillar across the seam";
  EXPECT_EQ(count_obstacle_penetrations(sim.world(), sim.crowd().position.span(), sim.crowd().radius.span(),
                                        sim.crowd().flags.span(), 1e-3f),
            0);
}

// The same run on 1, 2 and 4 threads holds the same bits, under both
// schedulers (the four colours stay apart across the seam: an even number
// of cells).
TEST(Periodic, SameBitsOnAnyThreadCountUnderBothSchedulers) {
  for (SchedulerKind scheduler : {SchedulerKind::DoubleBuffer, SchedulerKind::FourColour}) {
    io::LoadedScenario l;
    l.spec = ring_corridor(ModelKind::CollisionFreeSpeed);
    l.spec.scheduler = scheduler;
    l.spec.groups = {filling(2.0)};
    test::expect_same_bits_on_threads(l, 60);
  }
}

// The fundamental diagram of a periodic corridor is the one measured in a
// long open corridor of the same width (same model and speeds): the seam
// changes where the crowd is, not how it walks.
TEST(Periodic, SpeedAtADensityMatchesALongOpenCorridor) {
  const Aabb middle{{5.0f, 0.0f}, {15.0f, kWidth}};
  for (double density : {1.0, 2.5}) {
    SCOPED_TRACE(density);
    ScenarioSpec ring = ring_corridor(ModelKind::CollisionFreeSpeed);
    ring.groups = {filling(density)};
    Simulation periodic(ring);
    // The open corridor: five periods long, filled alike, measured in its
    // middle before its ends are felt there.
    ScenarioSpec open = test::collision_free_spec("open", 0.05f, 30.0f,
                                                  {{0.0f, 0.0f}, {400.0f, 0.0f}, {400.0f, kWidth}, {0.0f, kWidth}});
    open.stop_when_arrived = false;
    GroupSpec g = filling(density);
    g.count *= 5;
    g.spawn.max.x = 5.0f * kLength - 0.2f;
    g.goal.kind = GoalSpec::Kind::Offset;
    g.goal.value = {300.0f, 0.0f};
    open.groups = {g};
    Simulation straight(open);
    const Aabb open_middle{{45.0f, 0.0f}, {55.0f, kWidth}};
    double speed_ring = 0, speed_open = 0, density_ring = 0;
    int samples = 0;
    for (int k = 1; k <= 400; ++k) {
      periodic.step();
      straight.step();
      if (k < 100 || k % 20 != 0) continue;
      const CrowdState& a = periodic.crowd();
      const CrowdState& b = straight.crowd();
      const AreaSample r = measure_area(a.position.span(), a.velocity.span(), a.goal.span(), a.flags.span(), middle);
      const AreaSample o =
          measure_area(b.position.span(), b.velocity.span(), b.goal.span(), b.flags.span(), open_middle);
      speed_ring += r.mean_speed;
      speed_open += o.mean_speed;
      density_ring += r.density;
      ++samples;
    }
    speed_ring /= samples;
    speed_open /= samples;
    density_ring /= samples;
    EXPECT_NEAR(density_ring, density, 0.15 * density);
    EXPECT_NEAR(speed_ring, speed_open, 0.1) << "periodic " << speed_ring << " m/s, open " << speed_open << " m/s";
  }
}

// Counterflow in a ring corridor (the classic periodic experiment): two
// mixed groups of 40 walking opposite ways through a 20 m x 4 m corridor at
// 1 P/m^2 sort themselves into lanes, as in the open corridor
// (counterflow_test.cpp, order >= 0.6), and keep walking. The lane order
// counts neighbours across the seam too.
TEST(Periodic, CounterflowInARingCorridorFormsLanes) {
  ScenarioSpec s = ring_corridor(ModelKind::CollisionFreeSpeed);
  s.duration = 60.0f;
  GroupSpec east = filling(0.5), west = filling(0.5);
  west.goal.value = {-1.0f, 0.0f};
  s.groups = {east, west};
  Simulation sim(s);
  auto order = [&] {
    return lane_order(sim.positions(), sim.crowd().goal.to_vector(), sim.flags(), {1.0f, 0.0f}, 0.3f, 5.0f,
                      sim.world().periodic())
        .order;
  };
  const double mixed = order();
  sim.run(1200);
  const double lanes = order();
  double speed = 0;
  for (const glm::vec2 v : sim.velocities()) speed += std::fabs(v.x) / static_cast<double>(sim.agent_count());
  std::printf(
      "ring counterflow: lane order %.2f at the start, %.2f after 60 s; mean speed along the corridor %.2f m/s\n",
      mixed, lanes, speed);
  EXPECT_LT(mixed, 0.4);
  EXPECT_GE(lanes, 0.6);
  EXPECT_GT(speed, 0.6);
}

// Spawning sees across the seam: a crowd filling the whole period starts
// with no two bodies overlapping there. A direction's goal moves with its
// agent: after a minute it is still 100 km ahead, straight along the
// direction, wherever the crowd pushed the agent.
TEST(Periodic, SpawningAndGoalsRespectTheSeam) {
  ScenarioSpec s = ring_corridor(ModelKind::CollisionFreeSpeed);
  GroupSpec g = filling(2.5);
  g.spawn.min.x = 0.0f;
  g.spawn.max.x = kLength;
  s.groups = {g};
  Simulation sim(s);
  const CrowdState& c = sim.crowd();
  const OverlapStats start =
      measure_overlaps(c.position.span(), c.radius.span(), c.flags.span(), 0.0f, 1.0f, sim.world().periodic());
  EXPECT_EQ(start.touching, 0) << "deepest " << start.max_depth;
  sim.run(1200);
  const std::vector<glm::vec2> p = sim.positions(), goal = sim.crowd().goal.to_vector();
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(goal[i].x - p[i].x, kDirectionReach, 0.01f) << i;
    EXPECT_NEAR(goal[i].y - p[i].y, 0.0f, 1e-3f) << i;
  }
}

TEST(Periodic, MetricsSeeAcrossTheSeam) {
  const Periodic p{{0.0f, 0.0f}, {kLength, 0.0f}};
  // Two discs of 0.2 m whose centres are 0.3 m apart across the seam.
  const std::vector<glm::vec2> at = {{0.1f, 1.0f}, {kLength - 0.2f, 1.0f}};
  const std::vector<float> r = {0.2f, 0.2f};
  const std::vector<std::uint8_t> f = {kAgentActive, kAgentActive};
  const OverlapStats o = measure_overlaps(at, r, f, 0.0f, 1.0f, p);
  EXPECT_EQ(o.touching, 1);
  EXPECT_NEAR(o.max_depth, 0.1f, 1e-4f);
  EXPECT_EQ(measure_overlaps(at, r, f, 0.0f, 1.0f).touching, 0);  // without the seam, far apart
  // A step across the seam crosses a line just before it and one just after
  // it, never the line in the middle it would sweep unwrapped.
  const std::vector<glm::vec2> before = {{kLength - 0.05f, 1.0f}}, after = {{0.05f, 1.0f}};
  const std::vector<std::uint8_t> one = {kAgentActive};
  const std::vector<Segment> lines = {{{kLength - 0.02f, 2.0f}, {kLength - 0.02f, 0.0f}},
                                      {{0.02f, 2.0f}, {0.02f, 0.0f}},
                                      {{10.0f, 2.0f}, {10.0f, 0.0f}}};
  const Aabb bounds{{0.0f, 0.0f}, {kLength, 2.0f}};
  const std::vector<LineCrossing> found = line_crossings(before, one, after, one, lines, bounds, 0.0, 0.1, p);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].line, 0);
  EXPECT_EQ(found[1].line, 1);
  EXPECT_EQ(found[0].direction, found[1].direction);
  // Unwrapped, the step would sweep back across the middle line alone.
  const std::vector<LineCrossing> open = line_crossings(before, one, after, one, lines, bounds, 0.0, 0.1);
  ASSERT_EQ(open.size(), 1u);
  EXPECT_EQ(open[0].line, 2);
}

TEST(Periodic, VoronoiCellsByTheSeamAreCutByNeighboursAcrossIt) {
  // A lattice of spacing 0.5 m over the whole period: every cell is a 0.5 m
  // square, so an area straddling nothing but touching the seam measures 4 P/m^2.
  const Periodic p{{0.0f, 0.0f}, {kLength, 0.0f}};
  std::vector<glm::vec2> at, v, goal;
  for (float x = 0.25f; x < kLength; x += 0.5f)
    for (float y = 0.25f; y < kWidth; y += 0.5f) {
      at.push_back({x, y});
      v.push_back({1.0f, 0.0f});
      goal.push_back({x + 100.0f, y});
    }
  const std::vector<std::uint8_t> f(at.size(), kAgentActive);
  const Aabb by_seam{{0.0f, 1.0f}, {1.0f, 3.0f}};
  EXPECT_NEAR(measure_area_voronoi(at, v, goal, f, by_seam, 2.0f, p).density, 4.0, 1e-6);
  EXPECT_LT(measure_area_voronoi(at, v, goal, f, by_seam, 2.0f).density, 3.9);  // open: cells spill past the edge
}

TEST(Periodic, ScenarioErrorsNameTheField) {
  ScenarioSpec s = ring_corridor(ModelKind::CollisionFreeSpeed);
  s.groups = {filling(1.0)};
  // Not a rectangle.
  ScenarioSpec bent = s;
  bent.world.walkable.outer = {{0, 0}, {20, 0}, {20, 4}, {10, 6}, {0, 4}};
  EXPECT_NE(test::spawn_error(bent).find("world.periodic"), std::string::npos) << test::spawn_error(bent);
  ScenarioSpec none = s;
  none.world.has_walkable = false;
  EXPECT_NE(test::spawn_error(none).find("rectangular walkable"), std::string::npos) << test::spawn_error(none);
  // A point goal in a periodic world; a direction in an open one.
  ScenarioSpec point = s;
  point.groups[0].goal = GoalSpec::at({10.0f, 2.0f});
  EXPECT_NE(test::spawn_error(point).find("groups[0].goal"), std::string::npos) << test::spawn_error(point);
  ScenarioSpec open = s;
  open.world.periodic_x = false;
  EXPECT_NE(test::spawn_error(open).find("goal.direction"), std::string::npos) << test::spawn_error(open);
  // Spawning outside the rectangle (where the kernels see the copies).
  ScenarioSpec outside = s;
  outside.groups = {walkers({{kLength + 2.0f, 2.0f}}, {1.0f, 0.0f})};
  EXPECT_NE(test::spawn_error(outside).find("walkable"), std::string::npos) << test::spawn_error(outside);
  // A direction that runs along no periodic axis.
  ScenarioSpec across = s;
  across.groups[0].goal.value = {0.0f, 1.0f};
  EXPECT_NE(test::spawn_error(across).find("runs along no periodic axis"), std::string::npos)
      << test::spawn_error(across);
  // A period under four neighbour cells.
  ScenarioSpec short_ring = s;
  short_ring.world.walkable.outer = {{0, 0}, {3, 0}, {3, 4}, {0, 4}};
  short_ring.groups = {walkers({{1.0f, 2.0f}}, {1.0f, 0.0f})};
  try {
    Simulation sim(short_ring);
    ADD_FAILURE() << "a 3 m period must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("world.periodic"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace throng::sim
