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

// Counts keys of a range of items into one row of bins per block.
template <class KeyOf>
struct CountBlocks {
  Span<std::int32_t> rows;
  Index n;
  Index per_block;
  std::int32_t bins;
  KeyOf key_of;
  THRONG_HOST_DEVICE void operator()(Index b) const {
    std::int32_t* row = rows.data() + b * bins;
    for (std::int32_t k = 0; k < bins; ++k) row[k] = 0;
    const Index begin = b * per_block;
    const Index end = begin + per_block < n ? begin + per_block : n;
    for (Index i = begin; i < end; ++i) {
      const std::int32_t k = key_of(i);
      if (k >= 0 && k < bins) ++row[k];
    }
  }
};
}  // namespace detail

// The sum as parallel_reduce's `combine`.
using Plus = detail::Plus;

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

// How many i in [0, n) have key_of(i) == k, for every bin k in [0, bins)
// (keys outside are not counted). Each block of items counts into its own
// row of bins (at most 4 M counters in all) and the rows are summed in order
// on the host: the same counts for any thread count or backend.
template <class KeyOf>
std::vector<Index> deterministic_histogram(const char* description, Index n, std::int32_t bins, const KeyOf& key_of) {
  std::vector<Index> counts(static_cast<std::size_t>(bins > 0 ? bins : 0), 0);
  if (n <= 0 || bins <= 0) return counts;
  const Index max_blocks = detail::block_count(n);
  const Index room = (Index{1} << 22) / bins;
  const Index blocks = max_blocks < room ? max_blocks : (room > 0 ? room : 1);
  const Index per_block = (n + blocks - 1) / blocks;
  Buffer<std::int32_t> partial(blocks * bins, current_memory());
  parallel_for(description, blocks, detail::CountBlocks<KeyOf>{partial.span(), n, per_block, bins, key_of}, 1);
  const std::vector<std::int32_t> all = partial.to_vector();
  for (Index b = 0; b < blocks; ++b)
    for (std::int32_t k = 0; k < bins; ++k)
      counts[static_cast<std::size_t>(k)] += all[static_cast<std::size_t>(b * bins + k)];
  return counts;
}

// out[i] = in[0] + ... + in[i-1]; returns the total. `out` may alias `in`.
// Both spans must be in current_memory().
template <class T>
T exclusive_scan(const char* description, Span<const T> in, Span<T> out) {
  const Index n = in.size();
  if (n == 0) return T{};
  const Index blocks = detail::block_count(n);
  Buffer<T> sums(blocks, current_memory());
  parallel_for(description, blocks, detail::FoldBlocks<T, detail::Load<T>, detail::Plus>{sums.span(), n, T{}, {in}, {}},
               1);
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
