// util::half_toward_zero / half_value: every half read back as its definition (sign, exponent,
// mantissa) and the CPU's F16C conversion read it, and every float cut to the largest half not
// above it in magnitude (0 below the least normal half).

#include <bit>
#include <cmath>
#include <cpuid.h>
#include <immintrin.h>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "util/half_float.h"

namespace caliber::util {
namespace {

/// A finite half's value by its definition: (-1)^s 2^(e - 15) (1 + m / 1024), or 2^-14 m / 1024
/// where e is 0.
float reference_value(std::uint16_t h) {
  const int e = h >> 10 & 0x1F, m = h & 0x3FF;
  const double magnitude = e == 0 ? std::ldexp(m, -24) : std::ldexp(1024 + m, e - 25);
  return static_cast<float>((h & 0x8000u) != 0 ? -magnitude : magnitude);
}

bool has_f16c() {
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __get_cpuid(1, &a, &b, &c, &d) != 0 && (c & bit_F16C) != 0;
}
__attribute__((target("f16c"))) float cpu_value(std::uint16_t h) { return _cvtsh_ss(h); }

TEST(HalfFloat, EveryFiniteHalfReadsAsDefinedAndAsTheCpuReadsIt) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    if ((h >> 10 & 0x1Fu) == 0x1Fu) continue;  // infinities and NaNs: never stored
    const auto half = static_cast<std::uint16_t>(h);
    ASSERT_EQ(std::bit_cast<std::uint32_t>(half_value(half)), std::bit_cast<std::uint32_t>(reference_value(half))) << h;
    if (has_f16c()) ASSERT_EQ(std::bit_cast<std::uint32_t>(half_value(half)), std::bit_cast<std::uint32_t>(cpu_value(half))) << h;
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
  EXPECT_EQ(half_value(half_toward_zero(1e6f)), 65504.0f) << "beyond the largest half: the largest";
  EXPECT_EQ(half_value(half_toward_zero(-INFINITY)), -65504.0f);
  EXPECT_EQ(half_toward_zero(NAN), 0u);
}

}  // namespace
}  // namespace caliber::util
