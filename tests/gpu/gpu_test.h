// Shared plumbing of the CUDA-vs-CPU tests (tests/gpu/, executable
// gpu_tests): every test runs one job or stage twice on the same inputs,
// once on the CPU backend with host buffers (the reference) and once on the
// "device" side, then compares the results with the helpers below.
//
//   TEST(CudaSomething, MatchesCpu) {
//     THRONG_REQUIRE_GPU();  // skips, naming why, when no GPU is usable
//     const auto cpu = gpu_test::run_on(gpu_test::cpu_side(), [&](Memory m) { return run_it(m); });
//     const auto gpu = gpu_test::run_on(gpu_test::device_side(), [&](Memory m) { return run_it(m); });
//     EXPECT_TRUE(gpu_test::bitwise_equal(gpu.counts, cpu.counts));
//     EXPECT_TRUE(gpu_test::near(gpu.positions, cpu.positions, {1e-5, 1e-6}));
//   }
//
// The device side is Backend::Cuda with Memory::Device. Developer switch:
// THRONG_GPU_TESTS_ON_CPU=1 makes the device side Backend::Cpu with
// Memory::Host instead of skipping, so the plumbing (setup, both runs, the
// comparisons) can be exercised on a machine without a GPU. The two runs are
// then the same CPU code on the same inputs, so every comparison, near()
// included, demands bitwise equality: a tolerance only applies when the
// device side really is CUDA.
//
// Suite names start with "Cuda": CI treats skips of those (and only those)
// as expected on machines without a GPU.
//
// Test files are compiled by the host compiler: they must not launch
// parallel_for themselves (templates from core/parallel.h or core/reduce.h
// instantiated here have no CUDA version and throw on the CUDA backend).
// Only library functions whose kernels live in *_kernels.cpp run on the
// device; data moves with upload() / download().
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <span>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/buffer.h"
#include "core/exec.h"

namespace throng::gpu_test {

// THRONG_GPU_TESTS_ON_CPU=1: the device side runs on the CPU backend.
inline bool device_side_on_cpu() {
  const char* v = std::getenv("THRONG_GPU_TESTS_ON_CPU");
  return v != nullptr && std::string_view(v) == "1";
}

struct Side {
  Backend backend = Backend::Cpu;
  Memory memory = Memory::Host;
};
inline Side cpu_side() { return {Backend::Cpu, Memory::Host}; }
inline Side device_side() {
  return device_side_on_cpu() ? Side{Backend::Cpu, Memory::Host} : Side{Backend::Cuda, Memory::Device};
}

// True when the device side is CUDA, so floating-point comparisons may use
// their tolerance; false when both sides are the CPU: exact.
inline bool tolerant() { return device_side().backend == Backend::Cuda; }

// Runs fn(memory) under the side's backend (all CPU threads) and returns its
// result, which should be host data (download() what the run left on the device).
template <class Fn>
auto run_on(const Side& side, Fn&& fn) {
  ScopedExecution exec(side.backend, 0);
  return fn(side.memory);
}

// Host values into a buffer in memory m, and back.
template <class T>
Buffer<T> upload(const std::vector<T>& values, Memory m) {
  return Buffer<T>(std::span<const T>(values), m);
}
template <class T>
std::vector<std::remove_const_t<T>> download(Span<T> values, Memory m) {
  std::vector<std::remove_const_t<T>> out(static_cast<std::size_t>(values.size()));
  if (!out.empty()) throng::detail::copy_bytes(out.data(), Memory::Host, values.data(), m, out.size() * sizeof(T));
  return out;
}

namespace detail {
// Every element bitwise equal; names the first few that are not.
template <class T>
::testing::AssertionResult bitwise_equal_impl(const T* device, const T* cpu, std::size_t n) {
  std::size_t bad = 0;
  std::ostringstream where;
  for (std::size_t i = 0; i < n; ++i)
    if (std::memcmp(&device[i], &cpu[i], sizeof(T)) != 0) {
      if (bad < 5) where << " [" << i << "]";
      ++bad;
    }
  if (bad == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << bad << " of " << n << " elements differ, first at" << where.str();
}
}  // namespace detail

// Integer work, counting, sorting, copying: equal bit for bit.
template <class T>
::testing::AssertionResult bitwise_equal(const std::vector<T>& device, const std::vector<T>& cpu) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (device.size() != cpu.size())
    return ::testing::AssertionFailure() << "sizes differ: " << device.size() << " vs " << cpu.size();
  return detail::bitwise_equal_impl(device.data(), cpu.data(), device.size());
}

// |device - cpu| <= abs + rel * |cpu| for every float, with up to `outliers`
// floats allowed beyond that (for results behind a discrete decision, e.g. a
// threshold that a value one rounding away may fall on either side of; each
// use says why).
struct Tolerance {
  double rel = 0.0;
  double abs = 0.0;
  std::size_t outliers = 0;
};

// Floating-point results within a tolerance when the device side is CUDA,
// bitwise otherwise. T is float or a type made only of floats (glm::vecN,
// glm::quat, glm::mat4x3, anim::Mat3x4), compared float by float.
template <class T>
::testing::AssertionResult near(const std::vector<T>& device, const std::vector<T>& cpu, Tolerance tol) {
  static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(float) == 0, "compares floats");
  if (device.size() != cpu.size())
    return ::testing::AssertionFailure() << "sizes differ: " << device.size() << " vs " << cpu.size();
  if (!tolerant()) return detail::bitwise_equal_impl(device.data(), cpu.data(), device.size());
  const std::size_t n = device.size() * (sizeof(T) / sizeof(float));
  std::vector<float> a(n), b(n);
  if (n > 0) {
    std::memcpy(a.data(), device.data(), n * sizeof(float));
    std::memcpy(b.data(), cpu.data(), n * sizeof(float));
  }
  std::size_t bad = 0, worst = 0;
  double worst_excess = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::fabs(static_cast<double>(a[i]) - static_cast<double>(b[i]));
    const double allowed = tol.abs + tol.rel * std::fabs(static_cast<double>(b[i]));
    const bool same = a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i]));
    if (same || d <= allowed) continue;
    ++bad;
    const double excess = std::isfinite(d) ? d / (allowed > 0 ? allowed : 1e-30) : 1e300;
    if (excess > worst_excess) {
      worst_excess = excess;
      worst = i;
    }
  }
  if (bad <= tol.outliers) return ::testing::AssertionSuccess();
  const std::size_t per = sizeof(T) / sizeof(float);
  return ::testing::AssertionFailure() << bad << " of " << n << " floats beyond abs " << tol.abs << " + rel " << tol.rel
                                       << " (" << tol.outliers << " allowed); worst: element " << worst / per
                                       << " float " << worst % per << ": device " << a[worst] << " cpu " << b[worst];
}

// Angles in radians compared modulo 2 pi (a wrapped angle one rounding from
// the seam may come out as -pi on one side and just under pi on the other).
inline ::testing::AssertionResult near_angle(const std::vector<float>& device, const std::vector<float>& cpu,
                                             double abs) {
  if (device.size() != cpu.size())
    return ::testing::AssertionFailure() << "sizes differ: " << device.size() << " vs " << cpu.size();
  if (!tolerant()) return detail::bitwise_equal_impl(device.data(), cpu.data(), device.size());
  constexpr double kTwoPi = 6.283185307179586;
  std::size_t bad = 0, first = 0;
  for (std::size_t i = 0; i < device.size(); ++i) {
    double d = std::fmod(std::fabs(static_cast<double>(device[i]) - static_cast<double>(cpu[i])), kTwoPi);
    d = std::fmin(d, kTwoPi - d);
    if (d <= abs) continue;
    if (bad++ == 0) first = i;
  }
  if (bad == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << bad << " angles differ by more than " << abs << " rad, first [" << first
                                       << "]: device " << device[first] << " cpu " << cpu[first];
}

// Of two equal-length arrays, the indices where they differ (bitwise).
template <class T>
std::vector<std::size_t> differing(const std::vector<T>& a, const std::vector<T>& b) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(T)) != 0) out.push_back(i);
  return out;
}

}  // namespace throng::gpu_test

// First statement of every test: skips with the reason when the device side
// would need a GPU and none is usable.
#define THRONG_REQUIRE_GPU()                                                   \
  do {                                                                         \
    if (!::throng::gpu_test::device_side_on_cpu() && !::throng::cuda_usable()) \
      GTEST_SKIP() << "no usable GPU: " << ::throng::cuda_status();            \
  } while (0)
