#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "core/error.h"

namespace throng::detail {

namespace {
// One arena per thread count, made on first use and kept: making an arena is
// far dearer than a launch.
tbb::task_arena& arena_for(int threads) {
  static std::mutex mutex;
  static std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  std::lock_guard lock(mutex);
  auto& a = arenas[threads];
  if (!a) a = std::make_unique<tbb::task_arena>(threads);
  return *a;
}
}  // namespace

void cpu_parallel_for(Index n, Index grain, RangeFn fn, const void* body) {
  const int threads = current_threads();
  if (threads == 1 || n <= grain) {
    fn(body, 0, n);
    return;
  }
  arena_for(threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<Index>& r) { fn(body, r.begin(), r.end()); });
  });
}

void kernel_not_compiled_for_cuda(const char* description) {
  throw Error(
      std::string("kernel '") + description +
      "' runs on the CPU only: its source is not listed in throng_kernel_sources, so no CUDA version was compiled");
}

}  // namespace throng::detail
