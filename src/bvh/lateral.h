#pragma once
/// \file
/// The lateral axes of a node's frame at build time (the distance bound's box, BvhNodeLateral):
/// the axes the build measures ranges along, and the turn that fits them to the vertices.

#include <cmath>

#include <Eigen/Core>

#include "caliber/model.h"

namespace caliber::bvh {

using Vec3 = Eigen::Vector3d;

/// lateral_axes of a cone axis and a turn already rounded to float (so exactly the stored ones).
inline void lateral_axes(const Vec3& axis, const double turn[2], Vec3& u, Vec3& v) {
  const float stored[3] = {static_cast<float>(axis.x()), static_cast<float>(axis.y()), static_cast<float>(axis.z())};
  const float stored_turn[2] = {static_cast<float>(turn[0]), static_cast<float>(turn[1])};
  caliber::lateral_axes(stored, stored_turn, u.data(), v.data());
}

/// The turn of the lateral axes that follows the vertices' spread: the principal direction, in the
/// plane of the unturned lateral axes, of the vertices' second moments (sum of p, of p p^T, and
/// their count), as (cos, sin) rounded to float. A heuristic: any turn gives valid ranges, since
/// they are measured along the turned axes.
inline void principal_turn(const Vec3& axis, const Vec3& sum, const Eigen::Matrix3d& sum2, double count, double turn[2]) {
  turn[0] = 1.0;
  turn[1] = 0.0;
  if (!(count > 0.0)) return;
  const double none[2] = {1.0, 0.0};
  Vec3 u, v;
  lateral_axes(axis, none, u, v);
  if (u.squaredNorm() == 0.0) return;
  const Vec3 mean = sum / count;
  const Eigen::Matrix3d cov = sum2 / count - mean * mean.transpose();
  const Vec3 cov_u = cov * u;
  const double x = u.dot(cov_u) - v.dot(cov * v), y = 2.0 * v.dot(cov_u);
  // The principal angle is half of atan2(y, x); (r + x, y) points along it, with no trigonometry.
  const double r = std::sqrt(x * x + y * y);
  const double cx = r + x, sy = y;
  const double len = std::sqrt(cx * cx + sy * sy);
  if (!(len > 0.0) || !std::isfinite(len)) {
    // x <= 0 and y = 0: a quarter turn, or no spread at all (any turn).
    if (x < 0.0) turn[0] = 0.0, turn[1] = 1.0;
    return;
  }
  turn[0] = static_cast<float>(cx / len);
  turn[1] = static_cast<float>(sy / len);
}

}  // namespace caliber::bvh
