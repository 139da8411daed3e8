// Basic array kernels over spans in current_memory(): the first users of
// parallel_for and the reference for testing backends against each other.
#pragma once

#include <cstdint>
#include <vector>

#include "core/span.h"

namespace throng {

// y[i] = a * x[i] + y[i]
void saxpy(float a, Span<const float> x, Span<float> y);

// Deterministic sums (see core/reduce.h).
float sum(Span<const float> x);
double sum(Span<const double> x);

// out[i] = in[0] + ... + in[i-1]; returns the total; out may alias in.
std::int32_t exclusive_scan(Span<const std::int32_t> in, Span<std::int32_t> out);
std::int64_t exclusive_scan(Span<const std::int64_t> in, Span<std::int64_t> out);
float exclusive_scan(Span<const float> in, Span<float> out);

// How many flags are non-zero (deterministic).
Index count_nonzero(Span<const std::uint8_t> flags);

// counts[k] = how many keys equal k, for k in [0, bins); other keys are not
// counted (deterministic_histogram).
std::vector<Index> histogram(Span<const std::int32_t> keys, std::int32_t bins);

}  // namespace throng
