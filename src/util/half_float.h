#pragma once
/// \file
/// IEEE 754 half-precision floats (binary16) as 16-bit words: a float cut to one (toward zero) and
/// one read back as a float (exact), as F16C's vcvtph2ps reads it.

#include <bit>
#include <cmath>
#include <cstdint>

namespace caliber::util {

/// The half nearest x toward zero (so no larger in magnitude): 0 below 2^-14 in magnitude (and for
/// NaN), so that no half made here is subnormal; the largest half (65504) beyond it.
inline std::uint16_t half_toward_zero(float x) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  const auto sign = static_cast<std::uint16_t>(bits >> 16 & 0x8000u);
  const std::uint32_t magnitude = bits & 0x7FFFFFFFu;
  if (!(std::abs(x) >= 0x1p-14f)) return 0;                                          // (NaN too)
  if (!(std::abs(x) < 65520.0f)) return static_cast<std::uint16_t>(sign | 0x7BFFu);  // (never asked: the largest half)
  const std::uint32_t exponent = (magnitude >> 23) - 127u + 15u, mantissa = (magnitude >> 13) & 0x3FFu;
  return static_cast<std::uint16_t>(sign | exponent << 10 | mantissa);
}

/// The value of half h (exact: every half is a float), for a finite h.
inline float half_value(std::uint16_t h) {
  const std::uint32_t sign = std::uint32_t{h & 0x8000u} << 16, exponent = h >> 10 & 0x1Fu, mantissa = h & 0x3FFu;
  if (exponent == 0) {
    const float f = static_cast<float>(mantissa) * 0x1p-24f;  // 0 or subnormal: exact
    return sign != 0 ? -f : f;
  }
  return std::bit_cast<float>(sign | (exponent + 112u) << 23 | mantissa << 13);
}

}  // namespace caliber::util
