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

/// True when the float evaluation, its rounding bounded, proves that a plane with normal n (any
/// vector; the difference of two triangles' closest points is the one that works when they are
/// apart) strictly separates triangle p from triangle q: the largest n . p_i is below the smallest
/// n . q_i. Strictly separated closed triangles do not meet, so triangles_intersect would say
/// false: a cheap way to skip it. False does not mean they meet.
/// Each n . v computed is within gamma_3 sum |n_k v_k| (about 3.4e-16 of that sum) of the true
/// value; the 1e-14 of it allowed here also covers rounding the allowance and the sum, and 1e-300
/// more covers products that underflow (absolute errors of 1e-323 or so). NaN or infinite input
/// certifies nothing.
inline bool certainly_separated(const Eigen::Vector3d& n, const Eigen::Vector3d p[3], const Eigen::Vector3d q[3]) {
  constexpr double kDotError = 1e-14, kUnderflow = 1e-300;
  const Eigen::Vector3d abs_n = n.cwiseAbs();
  double p_hi[3], q_lo[3];
  for (int i = 0; i < 3; ++i) {
    p_hi[i] = n.dot(p[i]) + (kDotError * abs_n.dot(p[i].cwiseAbs()) + kUnderflow);
    q_lo[i] = n.dot(q[i]) - (kDotError * abs_n.dot(q[i].cwiseAbs()) + kUnderflow);
  }
  // Every pair compared (not a max and a min: std::max drops a NaN), so a NaN anywhere says false.
  bool apart = true;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) apart &= p_hi[i] < q_lo[j];
  }
  return apart;
}

struct TriangleBatch;

/// triangles_intersect of every pair of `batch` (triangle_distance.h): bit i set where pair i's
/// triangles meet. Eight AVX-512 lanes where the CPU has them, else four AVX2 lanes twice (the
/// filters in every lane, a lane they cannot decide through triangles_intersect), else pair by
/// pair: the same verdicts every way, since every sign any form uses is exact. Pads the batch
/// first.
unsigned triangles_intersect_batch(TriangleBatch& batch);

namespace detail {
using IntersectBatch = unsigned (*)(const TriangleBatch& batch);
/// triangles_intersect_batch pair by pair, and its AVX-512 and AVX2 forms (nullptr where this
/// build or this CPU has none).
unsigned triangles_intersect_batch_by_pair(const TriangleBatch& batch);
/// triangles_intersect of the pairs of `batch` whose bits `lanes` has: bit i set where pair i's
/// triangles meet (what the lane forms run where their filters decide nothing).
unsigned triangles_intersect_lanes(const TriangleBatch& batch, unsigned lanes);
IntersectBatch triangles_intersect_batch_avx512_if_supported();
IntersectBatch triangles_intersect_batch_avx2_if_supported();
/// The form triangles_intersect_batch runs: AVX-512 where the CPU has it, else AVX2, else nullptr
/// (pair by pair).
IntersectBatch triangles_intersect_batch_lanes_if_supported();

/// triangles_intersect by the edge tests alone (every sign from orient3d, then each edge of one
/// triangle against the other), the form it takes where a corner lies in the other's plane: the
/// reference for the planes-crossing case's two-orientation test.
bool triangles_intersect_by_edges(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                                  const Eigen::Vector3d& b0, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2);
}  // namespace detail

}  // namespace caliber::geometry
