#pragma once
/// \file
/// The distance bound's separation of two Frames along the direction between a point of each
/// (PairContext::gap's last bound), worked out in the first OrientedBox's coordinates.

#include <algorithm>
#include <cmath>

#include "narrow/prepared.h"

namespace caliber::narrow {

/// How OrientedBox b lies against OrientedBox a (both in A's frame; d: b's center less a's): r[i][k], a's
/// axis i . b's axis k, and t[i], a's axis i . d (b's center in a's coordinates). What
/// frames_apart reads.
inline void frames_relative(const OrientedBox& a, const OrientedBox& b, const double d[3], double r[3][3], double t[3]) {
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) r[i][k] = a.axis[i][0] * b.axis[k][0] + a.axis[i][1] * b.axis[k][1] + a.axis[i][2] * b.axis[k][2];
    t[i] = a.axis[i][0] * d[0] + a.axis[i][1] * d[1] + a.axis[i][2] * d[2];
  }
}

/// A lower bound on the distance between two Frames (a's and b's half-extents; r and t from
/// frames_relative): how far apart they are along the direction from p to q, found by alternating
/// between the boxes in a's coordinates, where a's box is [-half, half] and b's center is t: p the
/// point of a's box nearest to b's center, q the point of b's box nearest to p (through b's
/// coordinates, r^T (p - t), clamped and brought back), then p the point of a's box nearest to q
/// (the third step cut the armadillo's node tests at gap 1e-6; a fourth saved little more).
///
/// For any n, the world direction N = sum_i n_i a_i has N . a_k = n_k, N . b_k = (r^T n)_k,
/// N . d = n . t and |N| = |n|, each up to the axes' rounding (orthonormal to about 1e-15) and
/// the products' (a few ulps of |n|, and of |n| |d| for n . t); along N, a OrientedBox's triangles
/// lie within center . N +- sum_k half_k |N . axis_k|, so the gap between the two intervals over
/// |N| bounds the distance. For n along the boxes' closest pair it is their distance, and p to q
/// is near that pair when the boxes are small beside their distance or one is flat and the other
/// beside it (the Frames' own axes miss those). 0 where the points meet. `hair_per_length` |n| is
/// added to each |N . axis| (the axes' and the products' rounding), `shrink` multiplies the
/// result (|N| against |n|, the rounding of |n| and of the division); n . t's rounding is far
/// below the query's safety margin. Each operation as PairContext::gaps_2x2's AVX2 lanes take it.
inline double frames_apart(const double a_half[3], const double b_half[3], const double r[3][3], const double t[3],
                           double hair_per_length, double shrink) {
  double p[3], u[3], q[3];
  for (int i = 0; i < 3; ++i) p[i] = std::clamp(t[i], -a_half[i], a_half[i]);
  const double v[3] = {p[0] - t[0], p[1] - t[1], p[2] - t[2]};
  for (int k = 0; k < 3; ++k) u[k] = std::clamp(r[0][k] * v[0] + r[1][k] * v[1] + r[2][k] * v[2], -b_half[k], b_half[k]);
  for (int i = 0; i < 3; ++i) q[i] = t[i] + r[i][0] * u[0] + r[i][1] * u[1] + r[i][2] * u[2];
  for (int i = 0; i < 3; ++i) p[i] = std::clamp(q[i], -a_half[i], a_half[i]);
  const double n[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 0.0)) return 0.0;
  // The hair's share, hair_per_length |n| (sum of the half-extents), comes off after the division:
  // the same bound, and the square root and the division no longer wait for each other's terms.
  const double at = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
  double spread_a = 0.0, spread_b = 0.0;
  for (int k = 0; k < 3; ++k) {
    spread_a += a_half[k] * std::abs(n[k]);
    spread_b += b_half[k] * std::abs(r[0][k] * n[0] + r[1][k] * n[1] + r[2][k] * n[2]);
  }
  const double halves = (a_half[0] + a_half[1] + a_half[2]) + (b_half[0] + b_half[1] + b_half[2]);
  return std::max(0.0, ((at - (spread_a + spread_b)) / len - hair_per_length * halves) * shrink);
}

}  // namespace caliber::narrow
