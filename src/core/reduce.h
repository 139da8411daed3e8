// Deterministic parallel reductions and prefix sums.
//
// The index range is cut into fixed blocks of kReduceBlock elements whatever
// the thread count or backend; each block is folded in index order and the
// block results are folded in block order. So a float sum is bitwise the
// same for 1, 2 or 64 threads (and on the GPU, up to its FMA contraction).
#pragma once

#include <vector>

#include "core/buffer.h"
#include "core/parallel.h"

namespace throng {

inline constexpr Index kReduceBlock = 4096;

namespace detail {
template <class T, class Map, class Combine>
struct FoldBlocks {
  Span<T> out;
  Index n;
  T identity;
  Map map;
  Combine combine;
  THRONG_HOST_DEVICE void operator()(Index b) const {
    const Index begin = b * kReduceBlock;
    const Index end = begin + kReduceBlock < n ? begin + kReduceBlock : n;
    T acc = identity;
    for (Index i = begin; i < end; ++i) acc = combine(acc, map(i));
    out[b] = acc;
  }
};

template <class T>
struct ScanBlocks {
  Span<const T> in;
  Span<T> out;
  Span<const T> block_offsets;
  THRONG_HOST_DEVICE void operator()(Index b) const {
    const Index begin = b * kReduceBlock;
    const Index end = begin + kReduceBlock < in.size() ? begin + kReduceBlock : in.size();
    T acc = block_offsets[b];
    for (Index i = begin; i < end; ++i) {
      const T v = in[i];  // read before write: in and out may alias
      out[i] = acc;
      acc = acc + v;
    }
  }
};

struct Plus {
  template <class T>
  THRONG_HOST_DEVICE T operator()(const T& a, const T& b) const {
    return a + b;
  }
};

template <class T>
struct Load {
  Span<const T> values;
  THRONG_HOST_DEVICE T operator()(Index i) const { return values[i]; }
};

inline Index block_count(Index n) { return (n + kReduceBlock - 1) / kReduceBlock; }
}  // namespace detail

// Folds map(i) for i in [0, n) with `combine` (associative), deterministically.
template <class T, class Map, class Combine>
T parallel_reduce(const char* description, Index n, T identity, const Map& map, const Combine& combine) {
  if (n <= 0) return identity;
  const Index blocks = detail::block_count(n);
  Buffer<T> partial(blocks, current_memory());
  parallel_for(description, blocks, detail::FoldBlocks<T, Map, Combine>{partial.span(), n, identity, map, combine}, 1);
  T acc = identity;
  for (const T& p : partial.to_vector()) acc = combine(acc, p);
  return acc;
}

template <class T>
T deterministic_sum(const char* description, Span<const T> values) {
  return parallel_reduce(description, values.size(), T{}, detail::Load<T>{values}, detail::Plus{});
}

// out[i] = in[0] + ... + in[i-1]; returns the total. `out` may alias `in`.
// Both spans must be in current_memory().
template <class T>
T exclusive_scan(const char* description, Span<const T> in, Span<T> out) {
  const Index n = in.size();
  if (n == 0) return T{};
  const Index blocks = detail::block_count(n);
  Buffer<T> sums(blocks, current_memory());
  parallel_for(description, blocks, detail::FoldBlocks<T, detail::Load<T>, detail::Plus>{sums.span(), n, T{}, {in}, {}}, 1);
  std::vector<T> offsets = sums.to_vector();
  T total{};
  for (T& o : offsets) {
    const T s = o;
    o = total;
    total = total + s;
  }
  const Buffer<T> offsets_buf(std::span<const T>(offsets), current_memory());
  parallel_for(description, blocks, detail::ScanBlocks<T>{in, out, offsets_buf.span()}, 1);
  return total;
}

}  // namespace throng
