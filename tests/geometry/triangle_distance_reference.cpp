// The closest-point kernel as it was at 2a20389 (per-query edge terms, a square root per feature pair),
// kept verbatim as the reference: the optimized kernel in src/geometry/triangle_distance.cpp must
// return the same bits (points and distance) on every input, so that every contact stays
// byte-identical to the results of earlier versions.

#include "geometry/triangle_distance_reference.h"

#include <algorithm>

#include <Eigen/Geometry>

namespace caliber::geometry::reference {

using Vec3 = Eigen::Vector3d;

double clamp01(double t) {
  // NaN (from 0/0 on a degenerate input) falls to 0 as well.
  return t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
}

/// Keeps the closer of the current best pair and (p, q).
void consider(ClosestPoints& best, const Vec3& p, const Vec3& q) {
  const double d = (q - p).norm();
  if (d < best.distance) best = ClosestPoints{p, q, d};
}

/// Where segment pq crosses the plane through a with normal n (floating point), if it does.
bool crossing_point(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& n, Vec3& out) {
  const double sp = n.dot(p - a);
  const double sq = n.dot(q - a);
  if ((sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) || sp == sq) return false;
  const double t = clamp01(sp / (sp - sq));
  out = p + t * (q - p);
  return true;
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

void closest_points_segments(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Vec3& c1, Vec3& c2) {
  // Ericson 5.1.9, with the parameters always clamped to [0, 1].
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (!(a > 0.0) && !(e > 0.0)) {
    s = t = 0.0;
  } else if (!(a > 0.0)) {
    t = clamp01(f / e);
  } else {
    const double c = d1.dot(r);
    if (!(e > 0.0)) {
      s = clamp01(-c / a);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      s = denom > 0.0 ? clamp01((b * f - c * e) / denom) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = clamp01(-c / a);
      } else if (t > 1.0) {
        t = 1.0;
        s = clamp01((b - c) / a);
      }
      t = clamp01(t);
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

ClosestPoints closest_points_triangles(const Vec3 a[3], const Vec3 b[3]) {
  ClosestPoints best{a[0], b[0], (b[0] - a[0]).norm()};
  Vec3 c1, c2;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      closest_points_segments(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3], c1, c2);
      consider(best, c1, c2);
    }
  }
  for (int i = 0; i < 3; ++i) {
    consider(best, a[i], closest_point_on_triangle(a[i], b[0], b[1], b[2]));
    consider(best, closest_point_on_triangle(b[i], a[0], a[1], a[2]), b[i]);
  }
  // Intersecting triangles: an edge of one pierces the other; its crossing point, on both triangles, is a feature pair.
  const Vec3 na = (a[1] - a[0]).cross(a[2] - a[0]);
  const Vec3 nb = (b[1] - b[0]).cross(b[2] - b[0]);
  Vec3 x;
  for (int i = 0; i < 3; ++i) {
    if (crossing_point(a[i], a[(i + 1) % 3], b[0], nb, x)) consider(best, x, closest_point_on_triangle(x, b[0], b[1], b[2]));
    if (crossing_point(b[i], b[(i + 1) % 3], a[0], na, x)) consider(best, closest_point_on_triangle(x, a[0], a[1], a[2]), x);
  }
  return best;
}

}  // namespace caliber::geometry::reference
