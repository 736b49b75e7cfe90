// The closest point on a triangle as it was at 2a20389, kept verbatim as the reference: the kernel's
// region test in src/geometry/triangle_distance.cpp must return the same bits on every input.

#include "geometry/triangle_distance_reference.h"

#include <algorithm>

#include <Eigen/Geometry>

namespace caliber::geometry::reference {

using Vec3 = Eigen::Vector3d;

double clamp01(double t) {
  // NaN (from 0/0 on a degenerate input) falls to 0 as well.
  return t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
}

Vec3 closest_point_on_segment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double len2 = d.squaredNorm();
  if (!(len2 > 0.0)) return p;
  return p + clamp01((x - p).dot(d) / len2) * d;
}

Vec3 closest_point_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5, with guards: a degenerate triangle, or any
  // division that cannot be trusted, falls back to the nearest point on the three edges.
  const Vec3 ab = b - a, ac = c - a, ax = x - a;
  const double area2 = ab.cross(ac).squaredNorm();
  const double scale2 = std::max(ab.squaredNorm(), ac.squaredNorm());
  if (area2 > 1e-24 * scale2 * scale2) {
    const double d1 = ab.dot(ax), d2 = ac.dot(ax);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec3 bx = x - b;
    const double d3 = ab.dot(bx), d4 = ac.dot(bx);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) return a + (d1 / (d1 - d3)) * ab;
    const Vec3 cx = x - c;
    const double d5 = ab.dot(cx), d6 = ac.dot(cx);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
      return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    }
    if (va >= 0.0 && vb >= 0.0 && vc >= 0.0 && va + vb + vc > 0.0) {
      const double denom = 1.0 / (va + vb + vc);
      const double v = vb * denom, w = vc * denom;
      if (v >= 0.0 && w >= 0.0 && v + w <= 1.0) return a + v * ab + w * ac;
    }
  }
  Vec3 best = closest_point_on_segment(x, a, b);
  double best_d = (best - x).squaredNorm();
  for (const auto& [p, q] : {std::pair<const Vec3&, const Vec3&>{b, c}, std::pair<const Vec3&, const Vec3&>{c, a}}) {
    const Vec3 y = closest_point_on_segment(x, p, q);
    const double d = (y - x).squaredNorm();
    if (d < best_d) {
      best = y;
      best_d = d;
    }
  }
  return best;
}

}  // namespace caliber::geometry::reference
