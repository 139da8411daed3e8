// parallel_for(description, n, body): the one way stages launch work.
//
// `body(i)` is called once for every i in [0, n). On the CPU backend it runs
// on oneTBB's thread pool; on the CUDA backend, when this file is compiled by
// nvcc (see throng_kernel_sources in CMake), the same body is a CUDA kernel.
// Every launch is timed under its description (core/timing.h).
#pragma once

#include "core/config.h"
#include "core/exec.h"
#include "core/timing.h"

#if defined(__CUDACC__)
#include "core/cuda_runtime.h"
#endif

namespace throng {

namespace detail {
using RangeFn = void (*)(const void* body, Index begin, Index end);
// Splits [0, n) into chunks of at least `grain` indices over current_threads().
void cpu_parallel_for(Index n, Index grain, RangeFn fn, const void* body);
[[noreturn]] void kernel_not_compiled_for_cuda(const char* description);

template <class Body>
void run_range(const void* body, Index begin, Index end) {
  const Body& f = *static_cast<const Body*>(body);
  for (Index i = begin; i < end; ++i) f(i);
}

#if defined(__CUDACC__)
template <class Body>
__global__ void generic_kernel(Index n, Body body) {
  const Index i = static_cast<Index>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) body(i);
}

template <class Body>
void cuda_parallel_for(const char* description, Index n, const Body& body) {
  constexpr int kBlock = 256;
  const Index blocks = (n + kBlock - 1) / kBlock;
  generic_kernel<<<static_cast<unsigned>(blocks), kBlock>>>(n, body);
  cuda::synchronize(description);
}
#endif
}  // namespace detail

// Minimum indices per CPU task; larger bodies may pass a smaller grain.
inline constexpr Index kDefaultGrain = 1024;

template <class Body>
void parallel_for(const char* description, Index n, const Body& body, Index grain = kDefaultGrain) {
  if (n <= 0) return;
  ScopedTimer timer(description);
  if (current_backend() == Backend::Cuda) {
#if defined(__CUDACC__)
    detail::cuda_parallel_for(description, n, body);
    return;
#else
    detail::kernel_not_compiled_for_cuda(description);
#endif
  }
  detail::cpu_parallel_for(n, grain, &detail::run_range<Body>, &body);
}

// Host-only parallel loops for work that cannot run as a kernel (A* with its
// heaps, dynamic programming or polygon clipping over std containers): the
// same oneTBB arena and thread count as parallel_for, timed under
// `description`, always on the CPU. Each index must write only its own
// outputs, so results do not depend on the thread count.
template <class Fn>
void host_parallel_for(const char* description, Index n, const Fn& fn, Index grain = 1) {
  if (n <= 0) return;
  ScopedTimer timer(description);
  detail::cpu_parallel_for(n, grain, &detail::run_range<Fn>, &fn);
}

}  // namespace throng
