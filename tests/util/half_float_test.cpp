// util::half_toward_zero / half_value against the compiler's own binary16 (_Float16): every half
// read back as the compiler reads it, and every float cut to the largest half not above it in
// magnitude (0 below the least normal half).

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "util/half_float.h"

namespace caliber::util {
namespace {

float reference_value(std::uint16_t h) { return static_cast<float>(std::bit_cast<_Float16>(h)); }

TEST(HalfFloat, EveryFiniteHalfReadsAsTheCompilersDoes) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    if ((h >> 10 & 0x1Fu) == 0x1Fu) continue;  // infinities and NaNs: never stored
    const auto half = static_cast<std::uint16_t>(h);
    ASSERT_EQ(std::bit_cast<std::uint32_t>(half_value(half)), std::bit_cast<std::uint32_t>(reference_value(half))) << h;
  }
}

TEST(HalfFloat, EveryNormalHalfIsItsOwnCut) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    const std::uint32_t exponent = h >> 10 & 0x1Fu;
    if (exponent == 0 || exponent == 0x1Fu) continue;
    ASSERT_EQ(half_toward_zero(half_value(static_cast<std::uint16_t>(h))), h) << h;
  }
}

TEST(HalfFloat, AFloatIsCutToTheLargestHalfNotAboveIt) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.5f, 1.5f);
  std::uniform_int_distribution<int> exponent(-20, 0);
  for (int i = 0; i < 200000; ++i) {
    const float x = std::ldexp(unit(rng), exponent(rng));
    const std::uint16_t h = half_toward_zero(x);
    const float v = half_value(h);
    ASSERT_LE(std::abs(v), std::abs(x)) << x;
    if (std::abs(x) < 0x1p-14f) {
      ASSERT_EQ(h, 0u) << x;
      continue;
    }
    ASSERT_EQ(std::signbit(v), std::signbit(x)) << x;
    // The next half away from zero is above x in magnitude.
    ASSERT_GT(std::abs(reference_value(static_cast<std::uint16_t>(h + 1u))), std::abs(x)) << x;
  }
  EXPECT_EQ(half_value(half_toward_zero(1.0f)), 1.0f);
  EXPECT_EQ(half_value(half_toward_zero(-1.0f)), -1.0f);
  EXPECT_EQ(half_toward_zero(0.0f), 0u);
  EXPECT_EQ(half_toward_zero(-0.0f), 0u);
}

}  // namespace
}  // namespace caliber::util
