#pragma once
/// \file
/// The lateral axes of a node's frame at build time (the distance bound's box, BvhNodeLateral):
/// the turn that fits them to the triangles below, and the axes the build measures ranges along.
/// A turn is a heuristic: any turn gives valid ranges, since they are measured along the turned
/// axes, which the query computes by the same formulas (caliber::lateral_axes).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include <Eigen/Core>

#include "bvh/model_data.h"

namespace caliber::bvh {

using Vec3 = Eigen::Vector3d;

/// The unturned lateral axes of a cone axis already rounded to float (Duff et al.'s basis of the
/// stored axis): what a turn is measured from.
inline void unturned_axes(const Vec3& axis, Vec3& u0, Vec3& v0) {
  const float stored[3] = {static_cast<float>(axis.x()), static_cast<float>(axis.y()), static_cast<float>(axis.z())};
  caliber::unturned_lateral_axes(stored, u0.data(), v0.data());
}

/// The lateral axes the query computes from the stored axis and turn (`turn` holds the stored
/// integers), from the unturned ones: the same turn_lateral_axes that caliber::lateral_axes ends
/// with.
inline void turned_axes(const Vec3& u0, const Vec3& v0, const double turn[2], Vec3& u, Vec3& v) {
  const std::int16_t stored_turn[2] = {static_cast<std::int16_t>(turn[0]), static_cast<std::int16_t>(turn[1])};
  u = u0;
  v = v0;
  caliber::turn_lateral_axes(stored_turn, u.data(), v.data());
}

/// The turn, as (cos, sin) times 32767 rounded to integers (BvhNodeLateral::turn), of the
/// direction (x, y) in the (u0, v0) plane; no turn where it vanishes.
inline void turn_towards(double x, double y, double turn[2]) {
  turn[0] = 1.0;
  turn[1] = 0.0;
  const double len = std::sqrt(x * x + y * y);
  if (!(len > 0.0) || !std::isfinite(len)) return;
  turn[0] = std::nearbyint(32767.0 * std::clamp(x / len, -1.0, 1.0));
  turn[1] = std::nearbyint(32767.0 * std::clamp(y / len, -1.0, 1.0));
}

/// A triangle's turn: along the principal direction of its corners' spread in the (u0, v0)
/// plane. The covariance's principal angle is half of atan2(2 c_uv, c_uu - c_vv); (r + x, y)
/// points along it with no trigonometry (x <= 0 and y = 0: a quarter turn).
inline void triangle_turn(const Vec3& u0, const Vec3& v0, const Vec3& a, const Vec3& b, const Vec3& c, double turn[2]) {
  const double pu[3] = {u0.dot(a), u0.dot(b), u0.dot(c)}, pv[3] = {v0.dot(a), v0.dot(b), v0.dot(c)};
  const double mu = (pu[0] + pu[1] + pu[2]) / 3.0, mv = (pv[0] + pv[1] + pv[2]) / 3.0;
  double cuu = 0.0, cvv = 0.0, cuv = 0.0;
  for (int i = 0; i < 3; ++i) {
    cuu += (pu[i] - mu) * (pu[i] - mu);
    cvv += (pv[i] - mv) * (pv[i] - mv);
    cuv += (pu[i] - mu) * (pv[i] - mv);
  }
  const double x = cuu - cvv, y = 2.0 * cuv;
  const double r = std::sqrt(x * x + y * y);
  if (r + x > 0.0 || y != 0.0) {
    turn_towards(r + x, y, turn);
  } else {
    turn_towards(x < 0.0 ? 0.0 : 1.0, x < 0.0 ? 1.0 : 0.0, turn);
  }
}

/// An internal node's turn: along the line between its children's box centers (across which
/// the build partitioned it), projected on the (u0, v0) plane.
inline void partition_turn(const Vec3& u0, const Vec3& v0, const Vec3& direction, double turn[2]) {
  turn_towards(direction.dot(u0), direction.dot(v0), turn);
}

/// A node's lateral ranges lo[k] .. hi[k] (along its lateral axes as the query computes them from
/// the stored axis and turn, `lateral.turn` set already), grown by `pad`, in steps
/// (caliber::lateral_range): the nearest steps whose decoded ends still hold them.
inline void lateral_steps(const BvhNode& node, const BvhNodeFilter& filter, const double lo[2], const double hi[2], double pad,
                          BvhNodeLateral& lateral) {
  for (int k = 0; k < 2; ++k) lateral.lo[k] = lateral.hi[k] = 0;
  double axes[2][3];
  lateral_axes(filter.cone_axis, lateral.turn, axes[0], axes[1]);
  const double step = lateral_step(node);
  if (!(step > 0.0)) return;  // a box of size 0 at the origin: every range is [0, 0]
  for (int k = 0; k < 2; ++k) {
    const double mid = lateral_middle(node, axes[k]), low = lo[k] - pad, high = hi[k] + pad;
    double q_lo = std::floor((low - mid) / step), q_hi = std::ceil((high - mid) / step);
    while (mid + q_lo * step > low) q_lo -= 1.0;
    while (mid + q_hi * step < high) q_hi += 1.0;
    // The ranges lie within the box, which a unit axis sees within 32000 steps of the middle.
    if (!(q_lo >= -32767.0 && q_lo <= 32767.0 && q_hi >= -32767.0 && q_hi <= 32767.0)) {
      throw std::logic_error("caliber: a lateral range outside its node's box");
    }
    lateral.lo[k] = static_cast<std::int16_t>(q_lo);
    lateral.hi[k] = static_cast<std::int16_t>(q_hi);
  }
}

}  // namespace caliber::bvh
