#pragma once
// The programs' wall clock: a steady clock, milliseconds and seconds since a point, and a median
// of repeated measurements.

#include <algorithm>
#include <chrono>
#include <vector>

namespace caliber::cli {

using Clock = std::chrono::steady_clock;

/// Milliseconds since `start`.
inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// Seconds since `start`.
inline double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// Median of a list (the mean of the middle two for an even count; 0 when empty).
inline double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace caliber::cli
