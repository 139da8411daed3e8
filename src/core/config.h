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

// A job's kernel body, inside its run(): the job travels by value (it owns
// nothing: spans and parameters), so the body reads its members by name
// with no local copies first.
//   void SaxpyJob::run() const { parallel_for("saxpy", x.size(), THRONG_JOB_LAMBDA(Index i) { y[i] += a * x[i]; }); }
#define THRONG_JOB_LAMBDA(...) [ =, *this ] THRONG_HOST_DEVICE(__VA_ARGS__)

// Small helpers on the per-neighbour paths (vector arithmetic, the nearest
// periodic image, a model's pairwise term): GCC keeps some of them as calls
// at -O2/-O3 once a kernel grows, and a call per candidate neighbour costs
// more than the arithmetic. Inlining changes no result (-ffp-contract=off).
#if defined(__CUDACC__)
#define THRONG_INLINE __forceinline__
#elif defined(__GNUC__)
#define THRONG_INLINE inline __attribute__((always_inline))
#else
#define THRONG_INLINE inline
#endif

#include <cstdint>

namespace throng {
using Index = std::int64_t;
}  // namespace throng
