// path/match on CUDA against the CPU: MatchGridJob (the motions x curves
// cost grid) and BestMotionJob (the best motion per curve).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "path/match.h"
#include "tests/gpu/gpu_test.h"

namespace throng::path {
namespace {

constexpr std::int32_t kK = 16, kMotions = 40;
constexpr Index kCurves = 2000;

struct Grid {
  std::vector<glm::vec2> motion_points, curve_points, curve_tangents;
  std::vector<std::int32_t> motion_state, curve_state;
  std::vector<float> motion_speed, curve_speed;
};

Grid random_grid(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), speed(0.5f, 2.5f), angle(-3.14159f, 3.14159f);
  Grid g;
  for (std::int32_t m = 0; m < kMotions; ++m) {
    // A motion's path in its own frame: from the origin along +x, bending.
    const float bend = 0.1f * u(rng), step = 0.2f + 0.1f * u(rng);
    glm::vec2 p(0.0f);
    float heading = 0.0f;
    for (std::int32_t i = 0; i < kK; ++i) {
      g.motion_points.push_back(p);
      p += step * glm::vec2(std::cos(heading), std::sin(heading));
      heading += bend;
    }
    g.motion_state.push_back(m % 4);
    g.motion_speed.push_back(speed(rng));
  }
  for (Index c = 0; c < kCurves; ++c) {
    const float a = angle(rng), bend = 0.1f * u(rng);
    glm::vec2 p(50.0f * u(rng), 50.0f * u(rng));
    float heading = a;
    g.curve_tangents.emplace_back(std::cos(a), std::sin(a));
    for (std::int32_t i = 0; i < kK; ++i) {
      g.curve_points.push_back(p);
      p += 0.25f * glm::vec2(std::cos(heading), std::sin(heading));
      heading += bend;
    }
    g.curve_state.push_back(c % 5 == 0 ? static_cast<std::int32_t>(c % 4) : -1);  // some curves require a state
    g.curve_speed.push_back(c % 3 == 0 ? 0.0f : speed(rng));                      // some any speed
  }
  return g;
}

TEST(CudaMatchGrid, CostsAndBestMotionsMatchCpu) {
  THRONG_REQUIRE_GPU();
  const Grid g = random_grid(37);
  struct Out {
    std::vector<float> cost, best_cost, best_cost_of_cpu_grid;
    std::vector<std::int32_t> best, best_of_cpu_grid;
  };
  std::vector<float> cpu_cost;  // the CPU's grid, given to both sides' BestMotionJob
  const auto best_of = [&](const Buffer<float>& cost, Memory m, std::vector<std::int32_t>& best,
                           std::vector<float>& best_cost) {
    Buffer<std::int32_t> b(kCurves, m);
    Buffer<float> bc(kCurves, m);
    BestMotionJob job;
    job.motions = kMotions;
    job.cost = cost.span();
    job.best = b.span();
    job.best_cost = bc.span();
    job.run();
    best = b.to_vector();
    best_cost = bc.to_vector();
  };
  const auto run = [&](Memory m) {
    Buffer<glm::vec2> mp = gpu_test::upload(g.motion_points, m), cp = gpu_test::upload(g.curve_points, m),
                      ct = gpu_test::upload(g.curve_tangents, m);
    Buffer<std::int32_t> ms = gpu_test::upload(g.motion_state, m), cs = gpu_test::upload(g.curve_state, m);
    Buffer<float> mv = gpu_test::upload(g.motion_speed, m), cv = gpu_test::upload(g.curve_speed, m),
                  cost(kCurves * kMotions, m);
    MatchGridJob job;
    job.k = kK;
    job.motions = kMotions;
    job.speed_weight = 0.2f;
    job.motion_points = mp.span();
    job.motion_state = ms.span();
    job.motion_speed = mv.span();
    job.curve_points = cp.span();
    job.curve_tangents = ct.span();
    job.curve_state = cs.span();
    job.curve_speed = cv.span();
    job.cost = cost.span();
    job.run();
    Out o;
    o.cost = cost.to_vector();
    best_of(cost, m, o.best, o.best_cost);
    if (cpu_cost.empty()) cpu_cost = o.cost;
    best_of(gpu_test::upload(cpu_cost, m), m, o.best_of_cpu_grid, o.best_cost_of_cpu_grid);
    return o;
  };
  const Out cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Out gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // Forbidden pairs are the constant kNoMatch, bitwise.
  for (std::size_t i = 0; i < cpu.cost.size(); ++i)
    if (cpu.cost[i] == kNoMatch) {
      ASSERT_EQ(gpu.cost[i], kNoMatch) << i;
    }
  // A cost sums k = 16 distances (each a rotation of a motion point, two
  // FMA-able products, and a sqrt of a sum of squares) plus a speed term:
  // ~100 roundings of values up to a few metres each; 1e-5 relative plus
  // 1e-5 absolute.
  EXPECT_TRUE(gpu_test::near(gpu.cost, cpu.cost, {1e-5, 1e-5})) << "costs";
  // The arg-min over a row only compares: on the same grid, bitwise.
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.best_of_cpu_grid, cpu.best_of_cpu_grid)) << "best motion on the CPU's grid";
  EXPECT_TRUE(gpu_test::bitwise_equal(gpu.best_cost_of_cpu_grid, cpu.best_cost_of_cpu_grid))
      << "best cost on the CPU's grid";
  // On each side's own grid the best costs agree within the grid's
  // tolerance; the chosen motion may differ only where two motions' costs
  // are within that tolerance of each other.
  EXPECT_TRUE(gpu_test::near(gpu.best_cost, cpu.best_cost, {1e-5, 1e-5})) << "best costs";
  for (Index c = 0; c < kCurves; ++c) {
    const auto i = static_cast<std::size_t>(c);
    if (gpu.best[i] == cpu.best[i]) continue;
    const float other = cpu.cost[i * kMotions + static_cast<std::size_t>(gpu.best[i])];
    EXPECT_NEAR(other, cpu.best_cost[i], 2e-5 * cpu.best_cost[i] + 2e-5)
        << "curve " << c << " chose a motion that is not a near tie";
  }
}

}  // namespace
}  // namespace throng::path
