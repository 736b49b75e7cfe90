#pragma once
/// \file
/// The distance bound's separation of two Frames along the direction between a point of each
/// (PairContext::gap's last bound).

#include <algorithm>
#include <cmath>

#include "narrow/prepared.h"

namespace caliber::narrow {

/// A lower bound on the distance between two Frames, both in A's frame (d: b's center less
/// a's): how far apart they are along the direction from p to q, found by alternating between
/// the boxes: p the point of a's box nearest to b's center, q the point of b's box nearest to p,
/// then p the point of a's box nearest to q (a third step: armadillo node tests 1,297 -> 1,165
/// at gap 1e-6, a fourth saved little more). Along any unit direction
/// n, a Frame's triangles lie within center . n +- sum_k half_k |n . axis_k| (its axes
/// orthonormal: the hair covers their rounding), so the gap between the two intervals bounds
/// the distance; for n along the boxes' closest pair it is their distance, and p to q is near
/// that pair when the boxes are small beside their distance or one is flat and the other
/// beside it (the Frames' own axes miss those). 0 where the points meet. Each operation as
/// PairContext::gaps_2x2's AVX2 lanes take it. The separation is computed along n = q - p as it
/// is and divided by |n| once; `hair_per_length` |n| is added to each |n . axis| (the axes'
/// rounding), and `shrink` multiplies the result (the rounding of |n| and of the division).
inline double frames_apart(const Frame& a, const Frame& b, const double d[3], double hair_per_length, double shrink) {
  const auto clamp_into = [](const Frame& f, const double x[3], double out[3]) {
    const double r[3] = {x[0] - f.center[0], x[1] - f.center[1], x[2] - f.center[2]};
    double t[3];
    for (int k = 0; k < 3; ++k) t[k] = std::clamp(f.axis[k][0] * r[0] + f.axis[k][1] * r[1] + f.axis[k][2] * r[2], -f.half[k], f.half[k]);
    for (int i = 0; i < 3; ++i) out[i] = f.center[i] + t[0] * f.axis[0][i] + t[1] * f.axis[1][i] + t[2] * f.axis[2][i];
  };
  double p[3], q[3];
  clamp_into(a, b.center, p);
  clamp_into(b, p, q);
  clamp_into(a, q, p);
  const double n[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 0.0)) return 0.0;
  double at = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
  const double hair = hair_per_length * len;
  for (int k = 0; k < 3; ++k) {
    at -= a.half[k] * (std::abs(n[0] * a.axis[k][0] + n[1] * a.axis[k][1] + n[2] * a.axis[k][2]) + hair);
    at -= b.half[k] * (std::abs(n[0] * b.axis[k][0] + n[1] * b.axis[k][1] + n[2] * b.axis[k][2]) + hair);
  }
  return std::max(0.0, at / len * shrink);
}

}  // namespace caliber::narrow
