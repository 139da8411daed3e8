// Compiled by nvcc in CUDA builds (throng_kernel_sources), by g++ otherwise.
#include "core/array_kernels.h"

#include "core/error.h"
#include "core/reduce.h"

namespace throng {

void saxpy(float a, Span<const float> x, Span<float> y) {
  if (x.size() != y.size()) throw Error("saxpy: x and y differ in length");
  parallel_for(
      "core.saxpy", x.size(), THRONG_LAMBDA(Index i) { y[i] = a * x[i] + y[i]; });
}

float sum(Span<const float> x) { return deterministic_sum("core.sum_f32", x); }
double sum(Span<const double> x) { return deterministic_sum("core.sum_f64", x); }

template <class T>
static T scan_checked(Span<const T> in, Span<T> out) {
  if (in.size() != out.size()) throw Error("exclusive_scan: input and output differ in length");
  return exclusive_scan("core.exclusive_scan", in, out);
}

std::int32_t exclusive_scan(Span<const std::int32_t> in, Span<std::int32_t> out) { return scan_checked(in, out); }
std::int64_t exclusive_scan(Span<const std::int64_t> in, Span<std::int64_t> out) { return scan_checked(in, out); }
float exclusive_scan(Span<const float> in, Span<float> out) { return scan_checked(in, out); }

Index count_nonzero(Span<const std::uint8_t> flags) {
  return parallel_reduce(
      "core.count_nonzero", flags.size(), Index{0},
      THRONG_LAMBDA(Index i) { return static_cast<Index>(flags[i] != 0 ? 1 : 0); }, detail::Plus{});
}

namespace {
struct KeyAt {
  Span<const std::int32_t> keys;
  THRONG_HOST_DEVICE std::int32_t operator()(Index i) const { return keys[i]; }
};
}  // namespace

std::vector<Index> histogram(Span<const std::int32_t> keys, std::int32_t bins) {
  return deterministic_histogram("core.histogram", keys.size(), bins, KeyAt{keys});
}

}  // namespace throng
