#pragma once
/// \file
/// Exact intersection tests between closed triangles, segments and points in 3-D.

#include <Eigen/Core>

namespace caliber::geometry {

/// True when the closed triangles (a0, a1, a2) and (b0, b1, b2) share at least one point.
/// Exact for the given double coordinates (every decision is an exact orientation sign), and
/// defined for degenerate triangles too: a collinear triangle is its segment, a repeated point a point.
bool triangles_intersect(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                         const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);

/// True when the closed segment pq meets the closed triangle abc (exact; degenerate cases included).
bool segment_intersects_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                                 const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace caliber::geometry
