#pragma once
/// \file
/// Doubles rounded to floats outward (the BVH's stored bounds never shrink), without a library call.

#include <bit>
#include <cstdint>
#include <limits>

namespace caliber::util {

/// The float after f towards +infinity (up) or -infinity: std::nextafter's value, without the
/// library call, for a non-NaN f short of that infinity (the callers' case).
inline float float_step(float f, bool up) {
  if (f == 0.0f) return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
  const auto bits = std::bit_cast<std::uint32_t>(f);
  // Away from zero: one more in the magnitude's bits; towards it, one less.
  return std::bit_cast<float>((f > 0.0f) == up ? bits + 1 : bits - 1);
}

/// A float that is >= x, so that a stored bound never shrinks.
inline float round_up(double x) {
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = float_step(f, true);
  return f;
}

/// A float that is <= x.
inline float round_down(double x) {
  auto f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = float_step(f, false);
  return f;
}

}  // namespace caliber::util
