#pragma once
/// \file
/// Closest points between triangles, segments and points (floating point, robust to degeneracy).
/// Every point returned is a convex combination of the input vertices (weights clamped to [0, 1]),
/// so a reported distance is never below the true distance by more than rounding: the BVH prune
/// (which bounds the true distance with a safety margin) stays conservative against it.

#include <Eigen/Core>

#include "util/assert.h"

namespace caliber::geometry {

/// Closest point to x on the closed segment pq (pq may be a point).
Eigen::Vector3d closest_point_on_segment(const Eigen::Vector3d& x, const Eigen::Vector3d& p, const Eigen::Vector3d& q);

/// Closest point to x on the closed triangle abc (which may be degenerate).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

/// Closest points c1 on p1q1 and c2 on p2q2 (segments may be points).
void closest_points_segments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                             const Eigen::Vector3d& q2, Eigen::Vector3d& c1, Eigen::Vector3d& c2);

/// A pair of points, one on each triangle, and their distance.
struct ClosestPoints {
  Eigen::Vector3d on_a;  ///< point on triangle A
  Eigen::Vector3d on_b;  ///< point on triangle B
  double distance;       ///< |on_b - on_a|
};

/// Closest points between triangles A and B: the nearest of the edge-edge, vertex-face and
/// edge-through-face feature pairs (the last ones find the crossing point of intersecting triangles).
/// The edge pairs come first; when the planes through the nearest of them, across the line joining
/// it, have A on one side and B on the other (up to rounding), it is the nearest pair and the kernel
/// stops there. Of several pairs at the same distance, the first in the kernel's order is
/// reported: edge i of A against edge j of B in the order (i, j) = (0, 0), (0, 1), ..., (2, 2)
/// (edge i runs from corner i to corner i + 1), then, if not stopped, corner i of A onto B's face
/// and corner i of B onto A's face for i = 0, 1, 2, then the crossings, each where it projects into
/// the face (a point nearest an edge or corner of the other lies on an edge of its own: an edge pair
/// is as near). Its distance is the triangles' within rounding (at most about 2^-46 of the
/// triangles' extent above it where the kernel stops early), thin triangles (caps, needles) too: a
/// face's normal is computed to more than double precision from the corners (kernel::FacePlane), and
/// a point is over the face where it is inside its three edges' planes across it. A triangle whose
/// normal is shorter than 1e-15 of its longer side at corner 0 squared, or whose sides are beyond
/// about 1e77 or below 1e-77 (the squared normal or its inverse overflows), is taken by its edges
/// alone (bench/results/amd-epyc-2c/kernels/hostile_accuracy/: an oracle's distance on hostile pairs).
/// Runs on AVX2 and FMA where the CPU has them (x86-64), else portable code: the same bits either way.
ClosestPoints closest_points_triangles(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3]);

/// Up to kLanes triangle pairs for closest_points_triangles_batch, corner by corner, coordinate by
/// coordinate, lane by lane (so that a kernel loads a coordinate of every pair at once).
struct TriangleBatch {
  static constexpr int kLanes = 8;
  alignas(64) double a[3][3][kLanes];  ///< [corner][coordinate][pair]: triangle A of each pair
  alignas(64) double b[3][3][kLanes];  ///< the same for triangle B
  int size = 0;                        ///< pairs added (0..kLanes)

  [[nodiscard]] bool full() const { return size == kLanes; }
  /// Appends a pair (the batch must not be full).
  void add(const Eigen::Vector3d pa[3], const Eigen::Vector3d pb[3]);
  /// Appends pair `lane` of `from` (inline: a leaf buffer moves most pairs it refuses none of).
  void add(const TriangleBatch& from, int lane) {
    CALIBER_ASSERT(size < kLanes && lane >= 0 && lane < from.size, "a triangle batch takes at most kLanes pairs");
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) {
        a[k][c][size] = from.a[k][c][lane];
        b[k][c][size] = from.b[k][c][lane];
      }
    }
    ++size;
  }
  /// Copies pair 0 into the lanes past `size`, so that a kernel reads only defined values.
  void pad();
  /// The corners of pair `lane`.
  void get(int lane, Eigen::Vector3d pa[3], Eigen::Vector3d pb[3]) const;
};

/// closest_points_triangles_batch's results, coordinate by coordinate, lane by lane.
struct ClosestPointsBatch {
  alignas(64) double on_a[3][TriangleBatch::kLanes];  ///< [coordinate][pair]: the point on A
  alignas(64) double on_b[3][TriangleBatch::kLanes];  ///< the point on B
  alignas(64) double distance[TriangleBatch::kLanes];

  /// Pair `lane`'s result.
  [[nodiscard]] ClosestPoints get(int lane) const {
    return {{on_a[0][lane], on_a[1][lane], on_a[2][lane]}, {on_b[0][lane], on_b[1][lane], on_b[2][lane]}, distance[lane]};
  }
  void set(int lane, const ClosestPoints& c) {
    for (int k = 0; k < 3; ++k) {
      on_a[k][lane] = c.on_a[k];
      on_b[k][lane] = c.on_b[k];
    }
    distance[lane] = c.distance;
  }
};

/// closest_points_triangles of every pair of `batch`: out.get(i) is exactly (the same bits) what
/// closest_points_triangles returns for pair i. One pair per lane (the kernel's feature pairs in its
/// order, each lane's the same IEEE operations): eight AVX-512 lanes, or four AVX2 lanes twice where
/// the CPU has no AVX-512; else pair by pair.
/// Pads the batch (TriangleBatch::pad) first.
void closest_points_triangles_batch(TriangleBatch& batch, ClosestPointsBatch& out);

/// closest_points_triangles for a caller that wants only pairs within `reach`: false (and `out`
/// untouched) when a direction certifiably puts the triangles farther apart than `reach`, else true
/// with `out` exactly what closest_points_triangles returns. The directions: a plane of one
/// triangle with the whole other triangle beyond it (tested first, on the normal ab x ac; the
/// face pairs use kernel::FacePlane's), then, unless the kernel's edge pairs settle the pair (its early stop:
/// then true, whatever the distance), the cross product of an edge of each with the corners'
/// projections apart (edge_axes.h). It may return true for pairs farther apart than `reach`.
bool closest_points_triangles_within(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach, ClosestPoints& out);

/// closest_points_triangles_within's refusal alone, without computing the closest points: true
/// where the triangles are certifiably farther apart than `reach` along one of its directions.
/// There closest_points_triangles_within returns false, or a pair its early stop settled, whose
/// distance then exceeds `reach` (less rounding).
bool triangles_apart(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach);

/// triangles_apart of every pair of `batch` (reach >= 0): bit i set where pair i is apart. Eight
/// AVX-512 lanes where the CPU has them, four AVX2 lanes twice where it has AVX2 alone, else pair
/// by pair; the same verdicts every way. Pads the batch (TriangleBatch::pad) first.
unsigned triangles_apart_batch(TriangleBatch& batch, double reach);

/// The plane test alone: true when every corner of q is on one side of the plane of triangle p,
/// certifiably farther than `reach` from it (false for a degenerate p).
bool beyond_plane(const Eigen::Vector3d p[3], const Eigen::Vector3d q[3], double reach);

namespace detail {
/// The two forms of closest_points_triangles and of closest_points_triangles_within, for tests and
/// benchmarks.
using TriangleKernel = ClosestPoints (*)(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3]);
using WithinKernel = bool (*)(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach, ClosestPoints& out);
ClosestPoints closest_points_triangles_portable(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3]);
bool closest_points_triangles_within_portable(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach,
                                              ClosestPoints& out);
using BatchKernel = void (*)(const TriangleBatch& batch, ClosestPointsBatch& out);
/// The batch kernel pair by pair, through closest_points_triangles.
void closest_points_triangles_batch_by_pair(const TriangleBatch& batch, ClosestPointsBatch& out);
/// The AVX-512 batch kernel, or nullptr where this build or this CPU has none.
BatchKernel closest_points_triangles_batch_avx512_if_supported();
/// The AVX2 batch kernel (four lanes at a time), or nullptr where this build or this CPU has none.
BatchKernel closest_points_triangles_batch_avx2_if_supported();
using ApartBatchTest = unsigned (*)(const TriangleBatch& batch, double reach);
/// triangles_apart_batch pair by pair, through triangles_apart.
unsigned triangles_apart_batch_by_pair(const TriangleBatch& batch, double reach);
/// Its AVX-512 form, or nullptr where this build or this CPU has none.
ApartBatchTest triangles_apart_batch_avx512_if_supported();
/// Its AVX2 form (four lanes at a time), or nullptr where this build or this CPU has none.
ApartBatchTest triangles_apart_batch_avx2_if_supported();
using ApartTest = bool (*)(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach);
bool triangles_apart_portable(const Eigen::Vector3d a[3], const Eigen::Vector3d b[3], double reach);
/// The AVX2 forms, or nullptr where this build or this CPU has none.
ApartTest triangles_apart_avx2_if_supported();
TriangleKernel closest_points_triangles_avx2_if_supported();
WithinKernel closest_points_triangles_within_avx2_if_supported();
}  // namespace detail

}  // namespace caliber::geometry
