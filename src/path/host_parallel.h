// Host-only parallel loops for work that cannot run as a kernel (A* with its
// heaps, dynamic programming over std containers): the same oneTBB arena and
// thread count as parallel_for, timed under `description`, always on the CPU.
// Each index must write only its own outputs, so results do not depend on
// the thread count.
#pragma once

#include "core/parallel.h"

namespace throng::path {

template <class Fn>
void host_parallel_for(const char* description, Index n, const Fn& fn, Index grain = 1) {
  if (n <= 0) return;
  ScopedTimer timer(description);
  detail::cpu_parallel_for(n, grain, &detail::run_range<Fn>, &fn);
}

}  // namespace throng::path
