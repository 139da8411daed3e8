// The two atomic operations the binning kernels need, on host and device.
// Host: GCC/Clang builtins on plain memory (the buffers are plain arrays).
#pragma once

#include <cstdint>

#include "core/config.h"

namespace throng::sim {

THRONG_HOST_DEVICE inline std::int32_t atomic_fetch_add(std::int32_t* p, std::int32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(reinterpret_cast<int*>(p), static_cast<int>(v));
#else
  return __atomic_fetch_add(p, v, __ATOMIC_RELAXED);
#endif
}

// Stores `desired` when *p == expected; returns the value found.
THRONG_HOST_DEVICE inline std::uint64_t atomic_compare_swap(std::uint64_t* p, std::uint64_t expected,
                                                            std::uint64_t desired) {
#if defined(__CUDA_ARCH__)
  return static_cast<std::uint64_t>(atomicCAS(reinterpret_cast<unsigned long long*>(p),
                                              static_cast<unsigned long long>(expected),
                                              static_cast<unsigned long long>(desired)));
#else
  __atomic_compare_exchange_n(p, &expected, desired, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED);
  return expected;
#endif
}

// A plain read of a slot other threads may be writing with the functions above.
THRONG_HOST_DEVICE inline std::uint64_t atomic_load(const std::uint64_t* p) {
#if defined(__CUDA_ARCH__)
  return *reinterpret_cast<const volatile unsigned long long*>(p);
#else
  return __atomic_load_n(p, __ATOMIC_RELAXED);
#endif
}

}  // namespace throng::sim
