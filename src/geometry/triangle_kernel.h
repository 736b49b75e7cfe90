#pragma once
/// \file
/// What the two forms of the triangle kernel (closest_points_triangles: portable in
/// triangle_distance.cpp, AVX2 in triangle_distance_avx2.cpp) share, so that both compute each
/// candidate with the same operations and take the candidates in the same order: the same bits
/// either way.

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "geometry/triangle_distance.h"

namespace caliber::geometry::kernel {

using Vec3 = Eigen::Vector3d;

/// A triangle with what the closest-point query on it needs of its own: computed once per triangle
/// and reused for every point (the same expressions as a single query, so the same values).
struct TriangleFrame {
  const Vec3* v;   ///< the three corners
  Vec3 ab, ac;     ///< v[1] - v[0], v[2] - v[0]
  bool solid;      ///< far enough from degenerate for the region test (else: nearest edge point)

  explicit TriangleFrame(const Vec3 corners[3]) : v(corners), ab(corners[1] - corners[0]), ac(corners[2] - corners[0]) {
    const double area2 = ab.cross(ac).squaredNorm();
    const double scale2 = std::max(ab.squaredNorm(), ac.squaredNorm());
    solid = area2 > 1e-24 * scale2 * scale2;
  }
};

/// The nearest pair found so far. A new pair replaces it when its distance (the square root of its
/// squared length, as Eigen's norm() computes it) is strictly smaller; the square root is taken
/// only when the squared length is smaller, since sqrt is monotone and correctly rounded
/// (d2 >= best_d2 implies sqrt(d2) >= best.distance), so the winner is the same as comparing
/// every distance.
struct Nearest {
  ClosestPoints best;
  double best_d2;

  Nearest(const Vec3& p, const Vec3& q) : best{p, q, 0.0}, best_d2((q - p).squaredNorm()) { best.distance = std::sqrt(best_d2); }

  void consider(const Vec3& p, const Vec3& q) {
    const double d2 = (q - p).squaredNorm();
    if (d2 < best_d2) consider(p, q, d2, std::sqrt(d2));
  }

  /// The same, given also d = sqrt(d2) (correctly rounded, as std::sqrt is), with d2 < best_d2.
  void consider(const Vec3& p, const Vec3& q, double d2, double d) {
    if (d < best.distance) {
      best = ClosestPoints{p, q, d};
      best_d2 = d2;
    }
  }
};

/// Closest point to x on the triangle of `t`.
Vec3 closest_point_on_frame(const Vec3& x, const TriangleFrame& t);

/// Closest points c1 on p1 + s d1 and c2 on p2 + t d2 (s, t in [0, 1]), given a = |d1|^2 and
/// e = |d2|^2: the body of closest_points_segments with the edge terms computed by the caller.
void closest_points_edges(const Vec3& p1, const Vec3& d1, double a, const Vec3& p2, const Vec3& d2, double e, Vec3& c1,
                          Vec3& c2);

}  // namespace caliber::geometry::kernel
