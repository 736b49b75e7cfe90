#pragma once
/// \file
/// An independent oracle for the distance between two triangles: every feature pair in 113-bit
/// floating point (GCC's __float128; long double where the compiler has none), each computed by a
/// formula that stays accurate at any angle, and 0 where the exact intersection test says the
/// triangles meet.

#include <Eigen/Core>

namespace caliber::geometry::oracle {

/// The distance between the closed triangles a and b (either may be degenerate), to within about
/// 2^-100 of their coordinates' magnitude (2^-60 with long double), rounded to a double (through
/// long double's square root). Squared distances are kept: the square of any double is within
/// __float128's range (and long double's).
double triangles_distance(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3]);

}  // namespace caliber::geometry::oracle
