#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <random>

#include "core/array_kernels.h"
#include "core/buffer.h"
#include "core/error.h"

namespace throng {

namespace {
constexpr Index kN = 1000000;

std::vector<float> random_floats(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-100.f, 100.f);
  std::vector<float> v(static_cast<std::size_t>(n));
  for (auto& x : v) x = d(rng);
  return v;
}

std::vector<int> thread_counts() { return {1, 2, hardware_threads(), 7}; }

bool bitwise_equal(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}
}  // namespace

TEST(ParallelFor, VisitsEveryIndexExactlyOnce) {
  for (int t : thread_counts()) {
    ScopedExecution exec(Backend::Cpu, t);
    std::vector<std::atomic<int>> hits(100003);
    parallel_for(
        "test.visit", static_cast<Index>(hits.size()), [&](Index i) { hits[static_cast<std::size_t>(i)]++; }, 7);
    for (auto& h : hits) ASSERT_EQ(h.load(), 1) << "threads=" << t;
  }
}

TEST(ParallelFor, EmptyAndNegativeRangesDoNothing) {
  int calls = 0;
  parallel_for("test.empty", 0, [&](Index) { ++calls; });
  parallel_for("test.empty", -5, [&](Index) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, ExceptionsPropagate) {
  ScopedExecution exec(Backend::Cpu, 2);
  EXPECT_THROW(parallel_for("test.throw", 100000,
                            [](Index i) {
                              if (i == 77777) throw Error("boom");
                            }),
               Error);
}

TEST(ParallelFor, CpuOnlyKernelOnCudaBackendIsAClearError) {
  // This test file is compiled by the host compiler, so its kernels have no CUDA version.
  ScopedExecution exec(Backend::Cuda, 0);
  try {
    parallel_for("test.host_only", 10, [](Index) {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("test.host_only"), std::string::npos);
  }
}

TEST(ParallelFor, SaxpyBitwiseIdenticalForAnyThreadCount) {
  const auto x = random_floats(kN, 1), y0 = random_floats(kN, 2);
  std::vector<float> reference;
  for (int t : thread_counts()) {
    ScopedExecution exec(Backend::Cpu, t);
    Buffer<float> xb(x, Memory::Host), yb(y0, Memory::Host);
    saxpy(1.75f, xb.span(), yb.span());
    auto y = yb.to_vector();
    if (reference.empty()) {
      reference = y;
      // Independent reference: a plain serial loop.
      for (std::size_t i = 0; i < y.size(); ++i) ASSERT_EQ(y[i], 1.75f * x[i] + y0[i]);
    } else {
      EXPECT_TRUE(bitwise_equal(y, reference)) << "threads=" << t;
    }
  }
}

TEST(ParallelFor, PrefixSumBitwiseIdenticalForAnyThreadCount) {
  const auto x = random_floats(kN, 3);
  std::vector<float> reference;
  float reference_total = 0;
  for (int t : thread_counts()) {
    ScopedExecution exec(Backend::Cpu, t);
    Buffer<float> in(x, Memory::Host), out(kN, Memory::Host);
    const float total = exclusive_scan(in.span(), out.span());
    auto y = out.to_vector();
    if (reference.empty()) {
      reference = y;
      reference_total = total;
    } else {
      EXPECT_TRUE(bitwise_equal(y, reference)) << "threads=" << t;
      EXPECT_EQ(total, reference_total);
    }
  }
  // Against a serial double-precision scan: close, not bitwise (other order).
  double acc = 0;
  for (Index i = 0; i < kN; ++i) {
    ASSERT_NEAR(reference[static_cast<std::size_t>(i)], acc, 1e-3 * (1 + std::abs(acc)) + 0.5) << i;
    acc += x[static_cast<std::size_t>(i)];
  }
}

TEST(ParallelFor, IntegerPrefixSumMatchesSerial) {
  std::vector<std::int32_t> v(kN + 13);
  std::mt19937 rng(5);
  for (auto& e : v) e = static_cast<std::int32_t>(rng() % 5);
  std::vector<std::int32_t> expect(v.size());
  std::int32_t acc = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    expect[i] = acc;
    acc += v[i];
  }
  for (int t : thread_counts()) {
    ScopedExecution exec(Backend::Cpu, t);
    Buffer<std::int32_t> b(v, Memory::Host);
    EXPECT_EQ(exclusive_scan(b.span(), b.span()), acc) << "in place, threads=" << t;
    EXPECT_EQ(b.to_vector(), expect);
  }
}

TEST(ParallelFor, CudaBackendMatchesCpu) {
  if (!cuda_usable()) GTEST_SKIP() << "no usable GPU: " << cuda_status();
  const auto x = random_floats(kN, 1), y0 = random_floats(kN, 2);
  std::vector<float> cpu_y, cpu_scan;
  {
    ScopedExecution exec(Backend::Cpu, 0);
    Buffer<float> xb(x, Memory::Host), yb(y0, Memory::Host), sb(kN, Memory::Host);
    saxpy(1.75f, xb.span(), yb.span());
    exclusive_scan(xb.span(), sb.span());
    cpu_y = yb.to_vector();
    cpu_scan = sb.to_vector();
  }
  ScopedExecution exec(Backend::Cuda, 0);
  Buffer<float> xb(x, Memory::Device), yb(y0, Memory::Device), sb(kN, Memory::Device);
  saxpy(1.75f, xb.span(), yb.span());
  exclusive_scan(xb.span(), sb.span());
  const auto gpu_y = yb.to_vector(), gpu_scan = sb.to_vector();
  for (Index i = 0; i < kN; ++i) {
    const auto k = static_cast<std::size_t>(i);
    // The GPU may fuse a*x+y into one FMA: equal up to one rounding.
    ASSERT_NEAR(gpu_y[k], cpu_y[k], 1e-5f * (1 + std::abs(cpu_y[k]))) << i;
    ASSERT_EQ(gpu_scan[k], cpu_scan[k]) << "the scan has no multiply, so it must be bitwise equal; i=" << i;
  }
  std::vector<std::int32_t> v(kN, 3);
  Buffer<std::int32_t> vb(v, Memory::Device);
  EXPECT_EQ(exclusive_scan(vb.span(), vb.span()), 3 * static_cast<std::int32_t>(kN));
  EXPECT_EQ(vb.to_vector()[kN - 1], 3 * static_cast<std::int32_t>(kN - 1));
}

}  // namespace throng
