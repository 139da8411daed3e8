// Core kernels: the cost of a parallel_for launch and of the array kernels.
#include <vector>

#include "bench/registry.h"
#include "core/array_kernels.h"
#include "core/buffer.h"
#include "core/exec.h"

namespace throng::bench {

namespace {
void register_core(const Options& options) {
  const std::vector<Index> sizes = {1000, 100000, 1000000, 10000000};
  add(options, {"core/saxpy", sizes,
                [](benchmark::State& state, Index n) {
                  Buffer<float> x(std::vector<float>(static_cast<std::size_t>(n), 1.5f), current_memory());
                  Buffer<float> y = Buffer<float>::zeros(n, current_memory());
                  for (auto _ : state) {
                    saxpy(0.5f, x.span(), y.span());
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});
  add(options, {"core/sum_f32", sizes,
                [](benchmark::State& state, Index n) {
                  Buffer<float> x(std::vector<float>(static_cast<std::size_t>(n), 0.25f), current_memory());
                  for (auto _ : state) benchmark::DoNotOptimize(sum(x.span()));
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});
  add(options, {"core/exclusive_scan_i32", sizes,
                [](benchmark::State& state, Index n) {
                  Buffer<std::int32_t> x(std::vector<std::int32_t>(static_cast<std::size_t>(n), 3), current_memory());
                  Buffer<std::int32_t> y(n, current_memory());
                  for (auto _ : state) {
                    benchmark::DoNotOptimize(exclusive_scan(x.span(), y.span()));
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n);
                },
                true});
}

}  // namespace

static const bool registered = register_suite("core", &register_core);

}  // namespace throng::bench
