#pragma once
/// \file
/// The edge-axis test of the triangle kernel's reach (triangles_apart, and
/// closest_points_triangles_within for a pair its edge pairs do not settle): along the
/// cross product of an edge of A and an edge of B, the corners' projections can prove the
/// triangles farther apart than the reach, where neither triangle's plane does (edges passing
/// each other at a distance). The portable form is here; the AVX2 kernel computes the same
/// expressions in the same order, four axes at a time, so both give the same verdicts.
///
/// Why it is safe. Any nonzero vector n is a direction: the triangles are at least
/// gap / |n| apart, where gap is how far their projections n . x are apart. n is the float cross
/// product as computed (its rounding does not matter: it is simply the direction used). Each
/// projection n . (v - a0) is computed from the rounded difference and rounded products and sums:
/// within 4.5e-16 |n| |v - a0|_1 of the true value, so the computed gap is within 1e-15 |n| S
/// (S: the largest |v - a0|_1 of the six corners) plus its own rounding. The test asks for
/// gap > reach |n| (1 + 1e-12) + 1e-13 |n| S + 1e-300 (the last for products that underflow),
/// with |n| from a square root of n . n that is a normal number (so a few ulps off), and the gap
/// finite: then the true gap exceeds reach |n|, and the triangles are farther apart than reach.

#include <cfloat>
#include <cmath>

#include <Eigen/Core>

#include "geometry/triangle_kernel.h"

namespace caliber::geometry::kernel {

/// The smallest n . n the test trusts: far above where squares lose precision to underflow.
inline constexpr double kAxisLength2Floor = 1e-280;

/// x < y ? x : y and x > y ? x : y: what the AVX2 min and max instructions return (NaN and signed
/// zeros included), so the portable form takes the same values.
inline double lane_min(double x, double y) { return x < y ? x : y; }
inline double lane_max(double x, double y) { return x > y ? x : y; }

/// u . v as Eigen and the AVX2 lanes compute it: (x0 y0 + x1 y1) + x2 y2.
inline double dot3(const Eigen::Vector3d& u, const Eigen::Vector3d& v) { return (u.x() * v.x() + u.y() * v.y()) + u.z() * v.z(); }

/// What the axis test needs of a triangle pair: A's edge vectors from its first corner (its
/// frame's), B's corners less A's first, and S, the largest 1-norm among them (|a0 - a0| = 0 left
/// out).
struct EdgeAxesPair {
  const Eigen::Vector3d &ab, &ac;
  Eigen::Vector3d wb[3];
  double scale;

  EdgeAxesPair(const TriangleFrame& fa, const Eigen::Vector3d b[3])
      : ab(fa.ab), ac(fa.ac), wb{b[0] - fa.v[0], b[1] - fa.v[0], b[2] - fa.v[0]} {
    scale = lane_max(lane_max(one_norm(ab), one_norm(ac)), lane_max(lane_max(one_norm(wb[0]), one_norm(wb[1])), one_norm(wb[2])));
  }
};

/// The allowance the gap along n (of length len) must exceed: reach len (1 + 1e-12) + 1e-13 len S
/// + 1e-300.
inline double axis_need(double reach, double len, double scale) {
  return reach * len * (1.0 + 1e-12) + ((1e-13 * len) * scale + 1e-300);
}

/// Whether the projections on n put the pair farther apart than reach, certified.
inline bool axis_apart(const Eigen::Vector3d& n, const EdgeAxesPair& p, double reach) {
  const double pa1 = dot3(n, p.ab), pa2 = dot3(n, p.ac);
  const double pb0 = dot3(n, p.wb[0]), pb1 = dot3(n, p.wb[1]), pb2 = dot3(n, p.wb[2]);
  const double amin = lane_min(lane_min(0.0, pa1), pa2), amax = lane_max(lane_max(0.0, pa1), pa2);
  const double bmin = lane_min(lane_min(pb0, pb1), pb2), bmax = lane_max(lane_max(pb0, pb1), pb2);
  const double gap = lane_max(bmin - amax, amin - bmax);
  const double len2 = dot3(n, n);
  const double need = axis_need(reach, std::sqrt(len2), p.scale);
  return (len2 > kAxisLength2Floor) & (gap > need) & (gap <= DBL_MAX);
}

/// The cross product e x f, component by component as the AVX2 lanes compute it.
inline Eigen::Vector3d cross3(const Eigen::Vector3d& e, const Eigen::Vector3d& f) {
  return {e.y() * f.z() - e.z() * f.y(), e.z() * f.x() - e.x() * f.z(), e.x() * f.y() - e.y() * f.x()};
}

/// True when some edge pair's cross product certifiably puts triangle A (frame fa) and b farther
/// apart than reach (the axes in the kernel's edge-pair order: A's edge i = a[i] to a[i + 1], B's
/// edge j).
inline bool edges_apart(const TriangleFrame& fa, const Eigen::Vector3d b[3], double reach) {
  const Eigen::Vector3d* a = fa.v;
  const EdgeAxesPair p(fa, b);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = a[(i + 1) % 3] - a[i];
    for (int j = 0; j < 3; ++j) {
      if (axis_apart(cross3(e, b[(j + 1) % 3] - b[j]), p, reach)) return true;
    }
  }
  return false;
}

}  // namespace caliber::geometry::kernel
