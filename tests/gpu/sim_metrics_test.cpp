// sim/metrics on CUDA against the CPU: measure_overlaps,
// count_obstacle_penetrations, measure_area, mean_speed and
// density_histogram over a random crowd in a built-in scenario's world, and
// line_crossings of a random step.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

#include "sim/crowd.h"
#include "sim/metrics.h"
#include "sim/world.h"
#include "tests/gpu/gpu_test.h"
#include "tests/sim/test_scenarios.h"

namespace throng::sim {
namespace {

struct Result {
  OverlapStats overlaps;
  Index penetrations = 0;
  AreaSample area;
  double speed = 0.0;
  DensityHistogram density;
};

TEST(CudaMetrics, MatchCpu) {
  THRONG_REQUIRE_GPU();
  const ScenarioSpec spec = test::builtin("bottleneck");  // a room, a door in a wall, a yard
  constexpr Index kN = 4000;
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> x(-2.0f, 42.0f), y(-7.0f, 27.0f), r(0.18f, 0.3f), v(-1.5f, 1.5f);
  std::vector<glm::vec2> positions, velocities, goals;
  std::vector<float> radii;
  std::vector<std::uint8_t> flags;
  for (Index i = 0; i < kN; ++i) {
    positions.emplace_back(x(rng), y(rng));
    velocities.emplace_back(v(rng), v(rng));
    goals.emplace_back(x(rng), y(rng));
    radii.push_back(r(rng));
    flags.push_back(i % 9 == 0 ? 0 : kAgentActive);
  }
  const Aabb area{{17.0f, 8.0f}, {20.0f, 12.0f}};
  const auto run = [&](Memory m) {
    const World world = World::build(spec.world, spec.model.query_radius(), {}, m);
    const Buffer<glm::vec2> bp = gpu_test::upload(positions, m), bv = gpu_test::upload(velocities, m),
                            bg = gpu_test::upload(goals, m);
    const Buffer<float> br = gpu_test::upload(radii, m);
    const Buffer<std::uint8_t> bf = gpu_test::upload(flags, m);
    Result out;
    out.overlaps = measure_overlaps(bp.span(), br.span(), bf.span(), 0.01f, 0.6f);
    out.penetrations = count_obstacle_penetrations(world, bp.span(), br.span(), bf.span(), 0.01f);
    out.area = measure_area(bp.span(), bv.span(), bg.span(), bf.span(), area);
    out.speed = mean_speed(bv.span(), bf.span());
    out.density = density_histogram(bp.span(), bf.span(), 2.0f, 0.5f);
    return out;
  };
  const Result cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Result gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_GT(cpu.overlaps.touching, 0);
  ASSERT_GT(cpu.penetrations, 0);
  ASSERT_GT(cpu.area.agents, 0);

  // Counts of pairs and penetrations: integer sums of per-agent decisions,
  // each a distance (sqrt of an FMA-able sum of squares) against radii and
  // a tolerance. A decision flips only for a pair within a rounding (~1e-6
  // m) of the threshold: about 4,000 pairs are within reach here, their
  // gaps spread over ~0.5 m, so ~2% odds that one pair is that close. At
  // most one count of difference on CUDA; exact CPU against CPU.
  const Index slack = gpu_test::tolerant() ? 1 : 0;
  EXPECT_LE(std::abs(gpu.overlaps.touching - cpu.overlaps.touching), slack);
  EXPECT_LE(std::abs(gpu.overlaps.pairs - cpu.overlaps.pairs), slack);
  EXPECT_LE(std::abs(gpu.penetrations - cpu.penetrations), slack);
  EXPECT_EQ(gpu.area.agents, cpu.area.agents);        // inside a rectangle: comparisons only
  EXPECT_EQ(gpu.density.agents, cpu.density.agents);  // counts per cell times 1/cell^2: one multiply, no add
  // Depths and separations: one distance and two subtractions: a rounding
  // or two of values below a metre.
  const double tol = gpu_test::tolerant() ? 1e-6 : 0.0;
  EXPECT_NEAR(gpu.overlaps.max_depth, cpu.overlaps.max_depth, tol);
  EXPECT_NEAR(gpu.overlaps.min_separation, cpu.overlaps.min_separation, tol);
  // Mean speeds: |v| per agent (FMA-able), summed in double in a fixed
  // order on both: 1e-6 relative per term, so 1e-6 relative in the mean.
  EXPECT_NEAR(gpu.area.mean_speed, cpu.area.mean_speed, tol * (1.0 + std::abs(cpu.area.mean_speed)));
  EXPECT_NEAR(gpu.area.mean_speed_magnitude, cpu.area.mean_speed_magnitude,
              tol * (1.0 + cpu.area.mean_speed_magnitude));
  EXPECT_NEAR(gpu.speed, cpu.speed, tol * (1.0 + cpu.speed));
  if (!gpu_test::tolerant()) {
    EXPECT_EQ(gpu.overlaps.max_depth, cpu.overlaps.max_depth);
    EXPECT_EQ(gpu.overlaps.min_separation, cpu.overlaps.min_separation);
    EXPECT_EQ(gpu.area.mean_speed, cpu.area.mean_speed);
    EXPECT_EQ(gpu.area.mean_speed_magnitude, cpu.area.mean_speed_magnitude);
    EXPECT_EQ(gpu.speed, cpu.speed);
  }
}

TEST(CudaMetrics, LineCrossingsMatchCpu) {
  THRONG_REQUIRE_GPU();
  const std::vector<Segment> lines{{{-10, -10}, {10, 10}}, {{0, -15}, {0, 15}}, {{-5, 3}, {12, 3}}};
  Aabb bounds;
  for (const Segment& l : lines) bounds.add(l.a), bounds.add(l.b);
  // A random step of 20,000 agents, every 9th inactive.
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> x(-20.0f, 20.0f), v(-1.5f, 1.5f);
  std::vector<glm::vec2> before(20000), after(20000);
  std::vector<std::uint8_t> flags(20000);
  for (std::size_t i = 0; i < before.size(); ++i) {
    before[i] = {x(rng), x(rng)};
    after[i] = before[i] + glm::vec2(v(rng), v(rng));
    flags[i] = i % 9 == 0 ? 0 : kAgentActive;
  }
  const auto run = [&](Memory m) {
    const Buffer<glm::vec2> b0 = gpu_test::upload(before, m), b1 = gpu_test::upload(after, m);
    const Buffer<std::uint8_t> bf = gpu_test::upload(flags, m);
    const Buffer<Segment> bl = gpu_test::upload(lines, m);
    return line_crossings(b0.span(), bf.span(), b1.span(), bf.span(), bl.span(), bounds, 1.0, 1.1);
  };
  const std::vector<LineCrossing> cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const std::vector<LineCrossing> gpu = gpu_test::run_on(gpu_test::device_side(), run);
  ASSERT_GT(cpu.size(), 500u);
  // Each decision is two sides in double of float inputs and a position
  // along the line: it flips only for a step ending within ~1e-15 m of a
  // line or an end, which these random steps do not. The same list; times
  // within an FMA's rounding on CUDA.
  ASSERT_EQ(gpu.size(), cpu.size());
  const double tol = gpu_test::tolerant() ? 1e-12 : 0.0;
  for (std::size_t k = 0; k < cpu.size(); ++k) {
    EXPECT_EQ(gpu[k].agent, cpu[k].agent);
    EXPECT_EQ(gpu[k].line, cpu[k].line);
    EXPECT_EQ(gpu[k].direction, cpu[k].direction);
    EXPECT_NEAR(gpu[k].time, cpu[k].time, tol);
  }
}

}  // namespace
}  // namespace throng::sim
