// Host/device annotations: one kernel source for CPU threads and CUDA.
#pragma once

#if defined(__CUDACC__)
#define THRONG_HOST_DEVICE __host__ __device__
#define THRONG_DEVICE __device__
#else
#define THRONG_HOST_DEVICE
#define THRONG_DEVICE
#endif

// A kernel body: captures by value, callable on host and device.
//   parallel_for("saxpy", n, THRONG_LAMBDA(int64_t i) { y[i] += a * x[i]; });
#define THRONG_LAMBDA(...) [=] THRONG_HOST_DEVICE(__VA_ARGS__)

#include <cstdint>

namespace throng {
using Index = std::int64_t;
}  // namespace throng
