// SPDX-License-Identifier: MIT
// float16 conversion: exact round trips and round-to-nearest-even, checked against GCC's _Float16.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>

#include "report/float16.h"

namespace cbrdf::report {
namespace {

bool is_nan_half(std::uint16_t h) {
  return (h & 0x7C00u) == 0x7C00u && (h & 0x3FFu) != 0;
}

TEST(Float16, EveryHalfRoundTripsExactly) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    const auto bits = std::uint16_t(h);
    const float f = half_to_float(bits);
    if (is_nan_half(bits)) {
      EXPECT_TRUE(std::isnan(f));
      EXPECT_TRUE(is_nan_half(float_to_half(f)));
      continue;
    }
    ASSERT_EQ(float_to_half(f), bits) << "half 0x" << std::hex << h << " -> " << f;
  }
}

TEST(Float16, KnownValues) {
  EXPECT_EQ(float_to_half(1.0f), 0x3C00u);
  EXPECT_EQ(float_to_half(-2.0f), 0xC000u);
  EXPECT_EQ(float_to_half(65504.0f), 0x7BFFu);
  EXPECT_EQ(float_to_half(65519.0f), 0x7BFFu);  // below the halfway point to 65536
  EXPECT_EQ(float_to_half(65520.0f), 0x7C00u);  // halfway: ties to even, which is infinity
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -24)), 0x0001u);  // smallest subnormal
  EXPECT_EQ(float_to_half(std::ldexp(1.0f, -25)), 0x0000u);  // half of it: ties to even zero
  EXPECT_EQ(float_to_half(std::ldexp(1.5f, -25)), 0x0001u);  // above half: rounds up
  EXPECT_EQ(float_to_half(std::ldexp(3.0f, -25)), 0x0002u);  // 1.5 units: ties to even 2
  EXPECT_EQ(float_to_half(-0.0f), 0x8000u);
  EXPECT_EQ(half_to_float(0x3555u), 0.333251953125f);
  // 1 + 2^-11 is halfway between 1 and 1 + 2^-10: ties to the even 1.
  EXPECT_EQ(float_to_half(1.0f + std::ldexp(1.0f, -11)), 0x3C00u);
  EXPECT_EQ(float_to_half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3C02u);
}

// Where the compiler has _Float16 (GCC on x86-64, which the release suite uses; clang 14, which
// the sanitizer suite uses, has not).
#ifdef __FLT16_MAX__
TEST(Float16, MatchesTheCompilersConversion) {
  // Every 97th float bit pattern (44 million of them), both signs, all exponents.
  for (std::uint64_t u = 0; u <= 0xFFFFFFFFull; u += 97) {
    const float f = std::bit_cast<float>(std::uint32_t(u));
    const auto want = std::bit_cast<std::uint16_t>(static_cast<_Float16>(f));
    const std::uint16_t got = float_to_half(f);
    if (std::isnan(f)) {
      ASSERT_TRUE(is_nan_half(got));
      continue;
    }
    ASSERT_EQ(got, want) << "float bits 0x" << std::hex << u;
  }
}
#endif

}  // namespace
}  // namespace cbrdf::report
