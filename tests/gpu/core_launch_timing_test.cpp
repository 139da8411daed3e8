// CUDA launches are asynchronous and timed by events (core/parallel.h,
// core/cuda_runtime.h): results still match the CPU once the host reads them,
// and every launch is counted under its description with a GPU time.
#include <algorithm>
#include <vector>

#include "core/array_kernels.h"
#include "core/timing.h"
#include "tests/gpu/gpu_test.h"

namespace throng {
namespace {

constexpr Index kN = 1 << 20;
constexpr int kLaunches = 7;

std::vector<float> ramp(float scale) {
  std::vector<float> v(static_cast<std::size_t>(kN));
  for (Index i = 0; i < kN; ++i) v[static_cast<std::size_t>(i)] = scale * static_cast<float>(i % 1000);
  return v;
}

// kLaunches saxpy launches back to back, read once at the end.
std::vector<float> chained_saxpy(Memory m) {
  const Buffer<float> x = gpu_test::upload(ramp(0.001f), m);
  Buffer<float> y = gpu_test::upload(ramp(-0.5f), m);
  for (int k = 0; k < kLaunches; ++k) saxpy(0.25f, x.span(), y.span());
  return gpu_test::download(y.span(), m);
}

const KernelStat* find(const std::vector<KernelStat>& stats, const char* name) {
  const auto it = std::find_if(stats.begin(), stats.end(), [&](const KernelStat& s) { return s.name == name; });
  return it == stats.end() ? nullptr : &*it;
}

TEST(CudaLaunches, QueuedLaunchesGiveTheCpuResultAndAreTimedUnderTheirDescription) {
  THRONG_REQUIRE_GPU();
  const std::vector<float> cpu = gpu_test::run_on(gpu_test::cpu_side(), chained_saxpy);
  KernelTimings::global().reset();
  const std::vector<float> gpu = gpu_test::run_on(gpu_test::device_side(), chained_saxpy);
  // a * x + y may be one fused multiply-add on the GPU: one rounding per launch.
  EXPECT_TRUE(gpu_test::near(gpu, cpu, {1e-5, 1e-5}));

  const std::vector<KernelStat> stats = KernelTimings::global().stats();
  const KernelStat* s = find(stats, "core.saxpy");
  ASSERT_NE(s, nullptr) << "no timing recorded under core.saxpy";
  EXPECT_EQ(s->count, kLaunches);
  EXPECT_GT(s->min_ms, 0.0) << "a launch over 2^20 floats took no measurable time";
  EXPECT_LE(s->min_ms, s->median_ms);
  EXPECT_LE(s->median_ms, s->max_ms);
}

TEST(CudaLaunches, StatsWaitForLaunchesTheHostNeverRead) {
  THRONG_REQUIRE_GPU();
  gpu_test::run_on(gpu_test::device_side(), [](Memory m) {
    const Buffer<float> x = gpu_test::upload(ramp(1.0f), m);
    Buffer<float> y = gpu_test::upload(ramp(2.0f), m);
    KernelTimings::global().reset();
    saxpy(2.0f, x.span(), y.span());  // nothing reads y: the launch may still be queued
    const std::vector<KernelStat> stats = KernelTimings::global().stats();
    const KernelStat* s = find(stats, "core.saxpy");
    EXPECT_TRUE(s != nullptr && s->count == 1) << "stats() must count the launch still in flight";
    finish_device_work();
    return 0;
  });
}

}  // namespace
}  // namespace throng
