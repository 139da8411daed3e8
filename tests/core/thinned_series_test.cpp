#include "core/thinned_series.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace throng {
namespace {

// The reference: of 0..n-1, the multiples of the final stride, plus n-1.
std::vector<std::uint64_t> expected(std::uint64_t n, std::uint64_t stride) {
  std::vector<std::uint64_t> v;
  for (std::uint64_t i = 0; i < n; i += stride) v.push_back(i);
  if (n > 0 && v.back() != n - 1) v.push_back(n - 1);
  return v;
}

TEST(ThinnedSeries, KeepsEverythingWhileThereIsRoom) {
  ThinnedSeries<int> s(8);
  EXPECT_TRUE(s.empty());
  for (int i = 0; i < 8; ++i) s.push(i);
  EXPECT_EQ(s.values(), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(s.stride(), 1u);
  EXPECT_EQ(s.newest(), 7);
}

TEST(ThinnedSeries, EvenlySpreadBoundedAndNewestLastForAnyLength) {
  for (const std::size_t capacity : {2u, 3u, 7u, 16u, 100u}) {
    ThinnedSeries<std::uint64_t> s(capacity);
    for (std::uint64_t n = 1; n <= 5000; ++n) {
      s.push(n - 1);
      const std::vector<std::uint64_t> got = s.values();
      ASSERT_LE(got.size(), capacity + 1) << "capacity " << capacity << ", n " << n;
      ASSERT_EQ(got, expected(n, s.stride())) << "capacity " << capacity << ", n " << n;
      ASSERT_EQ(s.newest(), n - 1);
      ASSERT_EQ(s.seen(), n);
      // The stride doubles only when needed: half of it would overflow.
      if (s.stride() > 1) {
        ASSERT_GT((n - 1) / (s.stride() / 2) + 1, capacity) << "capacity " << capacity << ", n " << n;
      }
    }
  }
}

// Values that own memory survive thinning whole (moved, never self-moved).
TEST(ThinnedSeries, ValuesOwningMemorySurviveThinning) {
  ThinnedSeries<std::vector<int>> s(4);
  for (int i = 0; i < 100; ++i) s.push(std::vector<int>(3, i));
  const std::vector<std::vector<int>> got = s.values();
  ASSERT_FALSE(got.empty());
  for (const std::vector<int>& v : got) EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(got.front(), std::vector<int>(3, 0));
  EXPECT_EQ(got.back(), std::vector<int>(3, 99));
}

// ThinnedSample: count, mean and maximum against sums over every value,
// the kept values those of a ThinnedSeries fed the same, and a copy that
// goes on independently.
TEST(ThinnedSample, ExactCountMeanAndMaxWithBoundedValues) {
  ThinnedSample s(64);
  ThinnedSeries<double> reference(64);
  EXPECT_EQ(s.count(), 0u);
  EXPECT_EQ(s.mean(), 0.0);
  double sum = 0.0, max = -1e300;
  for (int i = 0; i < 10000; ++i) {
    const double v = std::sin(0.37 * i) * 10.0 + (i == 7777 ? 50.0 : 0.0);
    s.push(v);
    reference.push(v);
    sum += v;
    max = std::max(max, v);
  }
  EXPECT_EQ(s.count(), 10000u);
  EXPECT_NEAR(s.mean(), sum / 10000.0, 1e-12);
  EXPECT_EQ(s.max(), max);
  EXPECT_EQ(s.values(), reference.values());
  EXPECT_LE(s.values().size(), 65u);
  ThinnedSample copy = s;
  copy.push(1000.0);
  EXPECT_EQ(copy.max(), 1000.0);
  EXPECT_EQ(s.max(), max);
  EXPECT_EQ(copy.count(), 10001u);
}

}  // namespace
}  // namespace throng
