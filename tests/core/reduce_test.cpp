#include "core/reduce.h"

#include <gtest/gtest.h>

#include <random>

#include "core/array_kernels.h"

namespace throng {

TEST(Reduce, FloatSumIsBitwiseIndependentOfThreads) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> d(-1e3f, 1e3f);
  std::vector<float> v(1234567);
  for (auto& x : v) x = d(rng);
  Buffer<float> b(v, Memory::Host);
  float first = 0;
  for (int t : {1, 2, 3, hardware_threads()}) {
    ScopedExecution exec(Backend::Cpu, t);
    const float s = sum(b.span());
    if (t == 1) first = s;
    EXPECT_EQ(s, first) << "threads=" << t;
  }
  double exact = 0;
  for (float x : v) exact += x;
  EXPECT_NEAR(first, exact, 1e-4 * 1e3 * 1234567 / 1e3);
}

TEST(Reduce, CustomCombineMaxWithIndex) {
  std::vector<double> v(50001);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(static_cast<double>(i));
  Span<const double> s(v);
  struct ArgMax {
    double value;
    Index index;
  };
  for (int t : {1, 2, 4}) {
    ScopedExecution exec(Backend::Cpu, t);
    const ArgMax m = parallel_reduce(
        "test.argmax", s.size(), ArgMax{-1e300, -1},
        [s](Index i) {
          return ArgMax{s[i], i};
        },
        [](ArgMax a, ArgMax b) { return b.value > a.value || (b.value == a.value && b.index < a.index) ? b : a; });
    const auto it = std::max_element(v.begin(), v.end());
    EXPECT_EQ(m.index, it - v.begin());
    EXPECT_EQ(m.value, *it);
  }
}

TEST(Reduce, EmptyGivesIdentity) {
  EXPECT_EQ(sum(Span<const double>()), 0.0);
  std::vector<std::int64_t> none;
  EXPECT_EQ(exclusive_scan(Span<const std::int64_t>(none), Span<std::int64_t>(none)), 0);
}

TEST(Reduce, ScanAcrossBlockBoundaries) {
  for (Index n : {Index{1}, kReduceBlock - 1, kReduceBlock, kReduceBlock + 1, 3 * kReduceBlock + 17}) {
    std::vector<std::int64_t> v(static_cast<std::size_t>(n), 2), out(static_cast<std::size_t>(n));
    EXPECT_EQ(exclusive_scan(Span<const std::int64_t>(v), Span<std::int64_t>(out)), 2 * n);
    for (Index i = 0; i < n; ++i) ASSERT_EQ(out[static_cast<std::size_t>(i)], 2 * i);
  }
}

TEST(Reduce, HistogramAndCountMatchBruteForceForAnyThreads) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::int32_t> key(-3, 40);  // some keys outside [0, 37)
  const Index n = 3 * kReduceBlock + 101;
  std::vector<std::int32_t> keys(static_cast<std::size_t>(n));
  std::vector<std::uint8_t> flags(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    keys[i] = key(rng);
    flags[i] = static_cast<std::uint8_t>(keys[i] % 3 == 0 ? 2 : 0);
  }
  const std::int32_t bins = 37;
  std::vector<Index> expected(static_cast<std::size_t>(bins), 0);
  Index nonzero = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] >= 0 && keys[i] < bins) ++expected[static_cast<std::size_t>(keys[i])];
    nonzero += flags[i] != 0 ? 1 : 0;
  }
  for (int t : {1, 2, 5}) {
    ScopedExecution exec(Backend::Cpu, t);
    EXPECT_EQ(histogram(Span<const std::int32_t>(keys), bins), expected) << "threads=" << t;
    EXPECT_EQ(count_nonzero(Span<const std::uint8_t>(flags)), nonzero) << "threads=" << t;
  }
  EXPECT_TRUE(histogram(Span<const std::int32_t>(keys), 0).empty());
  EXPECT_EQ(histogram(Span<const std::int32_t>(), 4), std::vector<Index>(4, 0));
}

}  // namespace throng
