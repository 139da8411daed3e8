// anim/between_steps on CUDA against the CPU: InterpolateAgentsJob.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "anim/between_steps.h"
#include "tests/gpu/gpu_test.h"

namespace throng::anim {
namespace {

struct Out {
  std::vector<glm::vec2> p, v;
  std::vector<float> h;
};

TEST(CudaInterpolateAgents, MatchesCpu) {
  THRONG_REQUIRE_GPU();
  constexpr Index kN = 3000;
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> pos(-50.0f, 50.0f), angle(-3.14159f, 3.14159f);
  std::vector<glm::vec2> p0, p1;
  std::vector<float> h0, h1;
  for (Index i = 0; i < kN; ++i) {
    p0.emplace_back(pos(rng), pos(rng));
    p1.push_back(p0.back() + glm::vec2(0.05f * pos(rng), 0.05f * pos(rng)));
    h0.push_back(angle(rng));
    h1.push_back(angle(rng));
  }
  h1[0] = 3.14159f;  // across the seam
  h0[0] = -3.14159f;
  const auto run = [&](Memory m) {
    Buffer<glm::vec2> b_p0 = gpu_test::upload(p0, m), b_p1 = gpu_test::upload(p1, m), out_p(kN, m), out_v(kN, m);
    Buffer<float> b_h0 = gpu_test::upload(h0, m), b_h1 = gpu_test::upload(h1, m), out_h(kN, m);
    InterpolateAgentsJob job;
    job.alpha = 0.37f;
    job.previous_positions = b_p0.span();
    job.positions = b_p1.span();
    job.previous_headings = b_h0.span();
    job.headings = b_h1.span();
    job.out_positions = out_p.span();
    job.out_headings = out_h.span();
    job.step_seconds = 0.1f;
    job.out_velocities = out_v.span();
    job.run();
    return Out{out_p.to_vector(), out_v.to_vector(), out_h.to_vector()};
  };
  const Out cpu = gpu_test::run_on(gpu_test::cpu_side(), run);
  const Out gpu = gpu_test::run_on(gpu_test::device_side(), run);
  // p0 + a * (p1 - p0) may become one FMA on the GPU: one rounding of a
  // value of at most ~50 m, so 1e-6 relative plus 1e-5 m absolute covers it.
  EXPECT_TRUE(gpu_test::near(gpu.p, cpu.p, {1e-6, 1e-5})) << "positions";
  // (p1 - p0) / step: a subtraction and a multiply, nothing to contract;
  // allow one rounding all the same.
  EXPECT_TRUE(gpu_test::near(gpu.v, cpu.v, {1e-6, 1e-6})) << "velocities";
  // Two wraps with floor and a few FMA-able products: a few roundings of
  // values up to 2 pi; compared modulo 2 pi because a result on the seam may
  // land on either side.
  EXPECT_TRUE(gpu_test::near_angle(gpu.h, cpu.h, 1e-5)) << "headings";
}

}  // namespace
}  // namespace throng::anim
