// parallel_for(description, n, body): the one way stages launch work.
//
// `body(i)` is called once for every i in [0, n). On the CPU backend it runs
// on oneTBB's thread pool; on the CUDA backend, when this file is compiled by
// nvcc (see throng_kernel_sources in CMake), the same body is a CUDA kernel,
// launched asynchronously with the block size the occupancy calculator picks
// for it. Every launch is timed under its description (core/timing.h): CPU
// launches by the host clock, CUDA launches by a pair of CUDA events, read
// when the host next waits for the device (core/cuda_runtime.h).
#pragma once

#include "core/config.h"
#include "core/exec.h"
#include "core/span.h"
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

// The block size that keeps the most threads resident for this kernel, given
// the registers and shared memory it needs (asked once per body type), made
// smaller when n is too small to give every multiprocessor its blocks at
// that size: a launch should fill the device before it fills the blocks.
template <class Body>
int cuda_block_size(Index n) {
  struct Occupancy {
    int min_grid = 0, block = 256;
  };
  static const Occupancy best = [] {
    Occupancy o;
    if (cudaOccupancyMaxPotentialBlockSize(&o.min_grid, &o.block, generic_kernel<Body>) != cudaSuccess ||
        o.block <= 0) {
      cudaGetLastError();  // the launch reports a real fault; 256 threads is a safe size
      return Occupancy{};
    }
    return o;
  }();
  if (best.min_grid <= 0 || n >= Index{best.min_grid} * best.block) return best.block;
  const Index per_block = (n + best.min_grid - 1) / best.min_grid;
  const Index warps = (per_block + 31) / 32;
  return static_cast<int>(warps * 32 < best.block ? warps * 32 : best.block);
}

// Queues the kernel and returns; the host waits only where it reads results.
template <class Body>
void cuda_parallel_for(const char* description, Index n, const Body& body) {
  const int block = cuda_block_size<Body>(n);
  const Index blocks = (n + block - 1) / block;
  const int slot = cuda::launch_begin(description);
  generic_kernel<<<static_cast<unsigned>(blocks), static_cast<unsigned>(block)>>>(n, body);
  cuda::launch_end(slot);
}
#endif
}  // namespace detail

// Minimum indices per CPU task; larger bodies may pass a smaller grain.
inline constexpr Index kDefaultGrain = 1024;

template <class Body>
void parallel_for(const char* description, Index n, const Body& body, Index grain = kDefaultGrain) {
  if (n <= 0) return;
  if (current_backend() == Backend::Cuda) {
#if defined(__CUDACC__)
    detail::cuda_parallel_for(description, n, body);
    return;
#else
    detail::kernel_not_compiled_for_cuda(description);
#endif
  }
  ScopedTimer timer(description);
  detail::cpu_parallel_for(n, grain, &detail::run_range<Body>, &body);
}

// Counts what a launch moves under its description, estimated from the
// sizes of the arrays it passes over: each span it reads, and each it
// writes, once (a span read and written is passed twice). Called beside
// the launch, on the host (KernelTimings::count_bytes).
template <class... T>
void count_traffic(const char* description, const Span<T>&... spans) {
  KernelTimings::global().count_bytes(description, bytes_of(spans...));
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
