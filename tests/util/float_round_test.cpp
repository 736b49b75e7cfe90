// util::round_up / round_down against std::nextafter's rounding: the same float for doubles of
// every magnitude and sign, at float boundaries, around zero and the denormals, and past FLT_MAX.

#include <cmath>
#include <limits>
#include <bit>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "util/float_round.h"

namespace caliber::util {
namespace {

float reference_up(double x) {
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
float reference_down(double x) {
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

void expect_same(double x) {
  const float up = round_up(x), down = round_down(x);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(up), std::bit_cast<std::uint32_t>(reference_up(x))) << x;
  EXPECT_EQ(std::bit_cast<std::uint32_t>(down), std::bit_cast<std::uint32_t>(reference_down(x))) << x;
  EXPECT_GE(static_cast<double>(up), x);
  EXPECT_LE(static_cast<double>(down), x);
}

TEST(FloatRound, SameAsNextafter) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-160, 140);
  for (int i = 0; i < 200000; ++i) {
    const double x = std::ldexp(mantissa(rng), exponent(rng)) * (i % 2 == 0 ? 1.0 : -1.0);
    expect_same(x);
  }
  const double fmax = std::numeric_limits<float>::max(), fmin = std::numeric_limits<float>::denorm_min();
  for (const double x : {0.0, -0.0, fmin, -fmin, 0.5 * fmin, -0.5 * fmin, 1e-300, -1e-300, fmax, -fmax, fmax * (1 + 1e-12),
                         -fmax * (1 + 1e-12), 1.0, -1.0, 1.0 + 1e-12, -1.0 - 1e-12, 1.0 - 1e-12}) {
    expect_same(x);
  }
}

}  // namespace
}  // namespace caliber::util
