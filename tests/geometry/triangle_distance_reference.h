#pragma once
/// \file
/// The closest point on a triangle of 2a20389, the bit-for-bit reference of
/// geometry/triangle_distance.h's closest_point_on_triangle.

#include "geometry/triangle_distance.h"

namespace caliber::geometry::reference {

/// closest_point_on_triangle as of 2a20389.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

}  // namespace caliber::geometry::reference
