#pragma once
/// \file
/// What the two forms of the triangle kernel (closest_points_triangles: portable in
/// triangle_distance.cpp, AVX2 in triangle_distance_avx2.cpp) share, so that both compute each
/// feature pair with the same operations and take the feature pairs in the same order: the same bits
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
  const Vec3* v;    ///< the three corners
  Vec3 ab, ac;      ///< v[1] - v[0], v[2] - v[0]
  Vec3 normal;      ///< ab x ac
  double normal2;   ///< |normal|^2
  double ab2, ac2;  ///< |ab|^2, |ac|^2
  bool solid;       ///< far enough from degenerate for closest_point_on_frame's region test (else: nearest edge point)

  explicit TriangleFrame(const Vec3 corners[3])
      : v(corners),
        ab(corners[1] - corners[0]),
        ac(corners[2] - corners[0]),
        normal(ab.cross(ac)),
        normal2(normal.squaredNorm()),
        ab2(ab.squaredNorm()),
        ac2(ac.squaredNorm()) {
    const double scale2 = std::max(ab2, ac2);
    solid = normal2 > 1e-24 * scale2 * scale2;
  }
};

/// b - a as hi + lo exactly (Knuth's two-sum of b and -a): hi the rounded difference.
inline void two_diff(double b, double a, double& hi, double& lo) {
  hi = b - a;
  const double bv = hi - b;
  lo = (b - (hi - bv)) - (a + bv);
}

/// p q - r s where each factor is a difference carried as hi + lo (two_diff): Kahan's difference of
/// products on the high parts (r1 s1's rounding error exact by FMA, so only the last addition
/// rounds where p1 q1 and r1 s1 cancel), plus the low parts' first-order terms. Within a few units
/// of rounding of the result itself, plus about 2^-104 |p| |q|: the cross product of a thin
/// triangle's edges keeps its direction, which the rounded products lose (and the rounded edges).
inline double cross_term(double p1, double p2, double q1, double q2, double r1, double r2, double s1, double s2) {
  const double w = r1 * s1;
  const double e = std::fma(-r1, s1, w);
  const double f = std::fma(p1, q1, -w);
  const double lo = std::fma(p1, q2, p2 * q1) - std::fma(r1, s2, r2 * s1);
  return (f + e) + lo;
}

/// What the kernel's face pairs read of a triangle (frame t): its normal ab x ac from the
/// corners to a few units of rounding of itself (cross_term), whatever the triangle's angles; the
/// edges' inward directions n x e_i (e_i = v[i + 1] - v[i]); and 1 / |n|^2. A point lies over the
/// face when it is on the inner side of the three edges, and projects along n (face_projection).
/// The face is taken where |n| exceeds 1e-15 of the longer of ab and ac squared (so the sine of the
/// angle at corner 0 exceeds 1e-15; the terms cross_term leaves out are then below half a unit of
/// rounding of n, whose direction stays within a few), and |n|^2 and its inverse are finite (sides
/// between about 1e-77 and 1e77): else the kernel takes the triangle by its edges alone.
struct FacePlane {
  Vec3 n;
  Vec3 inward[3];
  double inv2;
  bool solid;

  explicit FacePlane(const TriangleFrame& t) {
    double u[3][2], w[3][2];  // ab and ac, each coordinate as hi, lo
    for (int k = 0; k < 3; ++k) {
      two_diff(t.v[1][k], t.v[0][k], u[k][0], u[k][1]);
      two_diff(t.v[2][k], t.v[0][k], w[k][0], w[k][1]);
    }
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      n[k] = cross_term(u[i][0], u[i][1], w[j][0], w[j][1], u[j][0], u[j][1], w[i][0], w[i][1]);
    }
    inward[0] = n.cross(t.ab);
    inward[1] = n.cross(Vec3(t.v[2] - t.v[1]));
    inward[2] = n.cross(Vec3(t.v[0] - t.v[2]));
    const double n2 = n.squaredNorm(), scale2 = std::max(t.ab2, t.ac2);
    inv2 = 1.0 / n2;
    solid = (n2 > 1e-30 * scale2 * scale2) & (n2 <= 0x1.fffffffffffffp+1023) & (inv2 <= 0x1.fffffffffffffp+1023);
  }
};

/// beyond_plane's allowance for the three corners of q against the plane of p (frame fp), whose
/// normal has length `len`, with uv = sqrt(|ab|^2 |ac|^2): a corner w (relative to p's first
/// corner) is beyond the plane when |normal . w| exceeds reach len (1 + 1e-12) + 1e-13 uv |w|_1.
/// 1e-13 |ab| |ac| |w| is some hundred times the rounding error of normal . w (a cross product then
/// a 3-term dot product); uv is a few ulps off |ab| |ac|, and |w|_1 >= |w|, both well within that
/// slack. The AVX2 kernel computes the same expressions in the same order.
inline double plane_need(double reach, double len) { return reach * len * (1.0 + 1e-12); }
inline double plane_slack(double uv) { return 1e-13 * uv; }
inline double one_norm(const Vec3& w) { return (std::abs(w.x()) + std::abs(w.y())) + std::abs(w.z()); }

/// True when every corner of q lies on one side of the plane of p (frame fp), farther than `reach`
/// from it, certified: the float signed distances are trusted only beyond plane_slack's allowance.
/// Then every point of q is farther than `reach` from every point of p. False for a degenerate p.
inline bool beyond_plane(const TriangleFrame& fp, const Vec3 q[3], double reach) {
  const double len = std::sqrt(fp.normal2);
  if (!(len > 0.0)) return false;
  const double base = plane_need(reach, len), slack = plane_slack(std::sqrt(fp.ab2 * fp.ac2));
  // All three corners decided at once (& and |, not && and ||): which corner fails first is data,
  // and a branch on it mispredicts.
  bool above = true, below = true;
  for (int i = 0; i < 3; ++i) {
    const Vec3 w = q[i] - fp.v[0];
    const double s = fp.normal.dot(w);
    const double need = base + slack * one_norm(w);
    above &= s > need;
    below &= s < -need;
  }
  return above | below;
}

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

/// The kernel's early stop, once the edge pairs are taken: true when the best pair so far, p on A
/// and q on B (v = q - p), is proven the nearest. Every corner x of A must have
/// (p - x) . v >= -2^-49 |p - x| . |v|, and every corner y of B (y - q) . v >= -2^-49 |y - q| . |v|
/// (|w| . |v|: the dot product of the absolute values). The planes through p and q across v then
/// have A on one side and B on the other, but for 2^-49 |w| . |v| -- several times the rounding
/// error of the float dot product -- so no point of A is nearer to B than |v| less about 2^-46 of
/// the corners' distances to p and q: the pair is the nearest up to rounding. False where a bound
/// is not finite (an infinite corner, or products past the largest double) or a value is NaN.
/// The vector forms compute the same expressions in the same order.
inline bool slab_clear(const Vec3 a[3], const Vec3 b[3], const Vec3& p, const Vec3& q) {
  const Vec3 v = q - p;
  const Vec3 m(std::abs(v.x()), std::abs(v.y()), std::abs(v.z()));
  bool clear = true;
  for (int i = 0; i < 3; ++i) {
    for (const Vec3& w : {Vec3(p - a[i]), Vec3(b[i] - q)}) {
      const double bound = (std::abs(w.x()) * m.x() + std::abs(w.y()) * m.y()) + std::abs(w.z()) * m.z();
      clear &= (w.dot(v) >= bound * -0x1p-49) & (bound <= 0x1.fffffffffffffp+1023);
    }
  }
  return clear;
}

/// Closest point to x on the triangle of `t`.
Vec3 closest_point_on_frame(const Vec3& x, const TriangleFrame& t);

/// Where x projects into the face of triangle `t` (plane f, solid): true, and `out` the projection,
/// x less its height along f.n, where x lies on the inner side of the three edges (each
/// (x - v_i) . inward_i >= 0). Else false. Unlike closest_point_on_frame's barycentric region test,
/// this keeps its precision on a thin triangle, whose products of edges' dot products cancel. The
/// kernel's corner-face and crossing feature pairs: a point nearest an edge or a corner
/// of the other triangle lies on an edge of its own, so an edge pair is at least as near (up to
/// rounding), and the kernel takes no pair for it.
bool face_projection(const Vec3& x, const TriangleFrame& t, const FacePlane& f, Vec3& out);

/// Closest points c1 on p1 + s d1 and c2 on p2 + t d2 (s, t in [0, 1]), given a = |d1|^2 and
/// e = |d2|^2: the body of closest_points_segments with the edge terms computed by the caller.
void closest_points_edges(const Vec3& p1, const Vec3& d1, double a, const Vec3& p2, const Vec3& d2, double e, Vec3& c1, Vec3& c2);

}  // namespace caliber::geometry::kernel
