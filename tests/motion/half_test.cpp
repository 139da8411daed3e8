// fp16 conversion against a brute-force nearest-half search and, where the
// compiler has it, the compiler's own _Float16.
#include "motion/half.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace throng::motion {
namespace {

float from_bits(std::uint32_t b) {
  float f;
  std::memcpy(&f, &b, sizeof f);
  return f;
}

bool is_nan_half(std::uint16_t h) { return (h & 0x7c00u) == 0x7c00u && (h & 0x03ffu) != 0; }

// Every finite non-negative half value in increasing order (bits 0 .. 0x7bff
// are ordered like their values), plus infinity.
const std::vector<double>& positive_halves() {
  static const std::vector<double> v = [] {
    std::vector<double> out;
    for (std::uint32_t h = 0; h <= 0x7bffu; ++h) {
      const std::uint32_t e = h >> 10, m = h & 0x3ffu;
      out.push_back(e == 0 ? std::ldexp(static_cast<double>(m), -24)
                           : std::ldexp(1.0 + m / 1024.0, static_cast<int>(e) - 15));
    }
    return out;
  }();
  return v;
}

// Reference rounding: nearest half, ties to even mantissa, beyond the
// largest finite half by half an ulp (65520) -> infinity.
std::uint16_t reference_half(float f) {
  const std::uint16_t sign = std::signbit(f) ? 0x8000u : 0u;
  const double a = std::abs(static_cast<double>(f));
  if (a >= 65520.0) return static_cast<std::uint16_t>(sign | 0x7c00u);
  const auto& v = positive_halves();
  auto hi = static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), a) - v.begin());
  if (hi == 0) return sign;
  if (hi == v.size()) return static_cast<std::uint16_t>(sign | 0x7bffu);
  const std::size_t lo = hi - 1;
  const double dlo = a - v[lo], dhi = v[hi] - a;
  std::size_t pick = dlo < dhi ? lo : (dhi < dlo ? hi : ((lo & 1u) == 0 ? lo : hi));
  return static_cast<std::uint16_t>(sign | pick);
}

TEST(Half, EveryHalfRoundTripsThroughFloat) {
  for (std::uint32_t h = 0; h <= 0xffffu; ++h) {
    const auto x = static_cast<std::uint16_t>(h);
    const float f = half_to_float(x);
    if (is_nan_half(x)) {
      EXPECT_TRUE(std::isnan(f));
      EXPECT_TRUE(is_nan_half(float_to_half(f)));
      continue;
    }
    ASSERT_EQ(float_to_half(f), x) << std::hex << h;
    if ((h & 0x7fffu) < 0x7c00u) {  // finite: value by the formula
      const double want = (h & 0x8000u ? -1.0 : 1.0) * positive_halves()[h & 0x7fffu];
      ASSERT_EQ(static_cast<double>(f), want) << std::hex << h;
    }
  }
}

TEST(Half, SpecialValues) {
  EXPECT_EQ(float_to_half(0.0f), 0x0000u);
  EXPECT_EQ(float_to_half(-0.0f), 0x8000u);
  EXPECT_EQ(float_to_half(1.0f), 0x3c00u);
  EXPECT_EQ(float_to_half(-2.0f), 0xc000u);
  EXPECT_EQ(float_to_half(65504.0f), 0x7bffu);
  EXPECT_EQ(float_to_half(65519.99f), 0x7bffu);
  EXPECT_EQ(float_to_half(65520.0f), 0x7c00u);  // the tie rounds to even = infinity
  EXPECT_EQ(float_to_half(std::numeric_limits<float>::infinity()), 0x7c00u);
  EXPECT_EQ(float_to_half(-std::numeric_limits<float>::infinity()), 0xfc00u);
  EXPECT_TRUE(is_nan_half(float_to_half(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -24)), 0x0001u);             // smallest subnormal
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -25)), 0x0000u);             // tie -> even (zero)
  EXPECT_EQ(float_to_half(std::ldexp(1.5f, -25)), 0x0001u);             // above the tie
  EXPECT_EQ(float_to_half(std::ldexp(3.0f, -25)), 0x0002u);             // 1.5 ulp tie -> even (2)
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -14)), 0x0400u);             // smallest normal
  EXPECT_EQ(float_to_half(1.0f + std::ldexp(1.0f, -11)), 0x3c00u);      // tie -> even (1.0)
  EXPECT_EQ(float_to_half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02u);  // tie -> even (up)
  EXPECT_EQ(half_to_float(0x3555u), 0.333251953125f);
}

TEST(Half, FloatToHalfMatchesNearestSearch) {
  // Every 4099th float bit pattern (all exponents, both signs), plus random ones.
  for (std::uint64_t b = 0; b <= 0xffffffffull; b += 4099) {
    const float f = from_bits(static_cast<std::uint32_t>(b));
    if (std::isnan(f)) continue;
    ASSERT_EQ(float_to_half(f), reference_half(f)) << std::hex << b;
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-70000.0f, 70000.0f);
  for (int i = 0; i < 200000; ++i) {
    const float f = u(rng) * std::ldexp(1.0f, -static_cast<int>(rng() % 40));
    ASSERT_EQ(float_to_half(f), reference_half(f)) << f;
  }
}

#if defined(__FLT16_MAX__)
TEST(Half, MatchesCompilerFloat16) {
  for (std::uint64_t b = 0; b <= 0xffffffffull; b += 4093) {
    const float f = from_bits(static_cast<std::uint32_t>(b));
    if (std::isnan(f)) continue;
    const _Float16 h = static_cast<_Float16>(f);
    std::uint16_t bits;
    std::memcpy(&bits, &h, sizeof bits);
    ASSERT_EQ(float_to_half(f), bits) << std::hex << b;
  }
}
#endif

}  // namespace
}  // namespace throng::motion
