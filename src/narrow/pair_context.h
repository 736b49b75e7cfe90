#pragma once
/// \file
/// Everything one object pair's traversal needs: the relative pose, the query's limits and the
/// node-node and leaf tests. The leaf test is the single source of truth for what a query reports;
/// the node test only prunes, and must never prune a pair the leaf test would keep.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber::narrow {

/// A triangle pair kept by the leaf test, in model A's frame.
struct Candidate {
  std::uint32_t tri_a;      ///< triangle of A
  std::uint32_t tri_b;      ///< triangle of B
  double distance;          ///< 0 when the triangles intersect
  Eigen::Vector3d point_a;  ///< closest point on A (A's frame); unset for interference
  Eigen::Vector3d point_b;  ///< closest point on B (A's frame); unset for interference
};

/// The order of closeness every traversal and the finalization agree on: closer first, then lower
/// triangle ids (a strict total order on a pair's candidates).
[[nodiscard]] inline bool closer(const Candidate& x, const Candidate& y) {
  if (x.distance != y.distance) return x.distance < y.distance;
  if (x.tri_a != y.tri_a) return x.tri_a < y.tri_a;
  return x.tri_b < y.tri_b;
}

/// The per-pair state of a query: immutable while traversals run, so several threads may traverse
/// disjoint parts of one pair's CD tree with the same context.
class PairContext {
  /// Added to |rotation . axis| terms: covers rounding in the rotation and in the products.
  static constexpr double kRotationHair = 1e-12;

 public:
  /// Precomputes B's pose in A's frame and the safety margin. Validates the request.
  PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request);

  /// A node of A with what the node-node test needs of it precomputed: its box center seen from
  /// B's frame and its box's extent along each of B's axes. Prepared once per node and reused
  /// against every node of B it meets (the traversal tests two children of A against two of B).
  struct SideA {
    std::uint32_t index;   ///< node index in A
    double center[3];      ///< sphere center (A's frame)
    double radius;         ///< sphere radius
    double box[3];         ///< box center (A's frame)
    double half[3];        ///< box half-extents (A's axes)
    double box_in_b[3];    ///< box center in B's frame
    double reach_on_b[3];  ///< half-extent of A's box along each of B's axes
    double slab_axis[3];   ///< slab axis (A's frame), 0 when the node has none
    double slab_on_b[3];   ///< |slab axis . B's axis k|: how much of B's half-extent k it sees
    double slab_lo, slab_hi;
  };
  /// A node of B, prepared the same way: centers brought into A's frame.
  struct SideB {
    std::uint32_t index;   ///< node index in B
    double center[3];      ///< sphere center in A's frame
    double radius;         ///< sphere radius
    double box[3];         ///< box center (B's own frame)
    double half[3];        ///< box half-extents (B's axes)
    double box_in_a[3];    ///< box center in A's frame
    double reach_on_a[3];  ///< half-extent of B's box along each of A's axes
    double slab_axis[3];   ///< slab axis (B's own frame), 0 when the node has none
    double slab_on_a[3];   ///< |slab axis . A's axis k|
    double slab_lo, slab_hi;
  };

  /// Prepares node ia of A for node tests.
  [[nodiscard]] SideA prepare_a(std::uint32_t ia) const {
    const BvhNode& n = mA.nodes[ia];
    SideA s;
    s.index = ia;
    s.radius = n.radius;
    for (int i = 0; i < 3; ++i) {
      s.center[i] = n.center[i];
      s.box[i] = n.box_center[i];
      s.half[i] = n.box_half[i];
    }
    // B's frame: x_b = R^T (x_a - T).
    const double rel[3] = {s.box[0] - mTrans[0], s.box[1] - mTrans[1], s.box[2] - mTrans[2]};
    for (int j = 0; j < 3; ++j) {
      s.box_in_b[j] = mRot(0, j) * rel[0] + mRot(1, j) * rel[1] + mRot(2, j) * rel[2];
      s.reach_on_b[j] = mAbsRot(0, j) * s.half[0] + mAbsRot(1, j) * s.half[1] + mAbsRot(2, j) * s.half[2];
    }
    const BvhNodeFilter& f = mA.filters[ia];
    for (int i = 0; i < 3; ++i) s.slab_axis[i] = f.cone_axis[i];
    for (int j = 0; j < 3; ++j) {
      s.slab_on_b[j] = std::abs(mRot(0, j) * s.slab_axis[0] + mRot(1, j) * s.slab_axis[1] + mRot(2, j) * s.slab_axis[2]) +
                       kRotationHair;
    }
    s.slab_lo = f.slab_lo;
    s.slab_hi = f.slab_hi;
    return s;
  }

  /// Prepares node ib of B for node tests.
  [[nodiscard]] SideB prepare_b(std::uint32_t ib) const {
    const BvhNode& n = mB.nodes[ib];
    SideB s;
    s.index = ib;
    s.radius = n.radius;
    const double c[3] = {n.center[0], n.center[1], n.center[2]};
    for (int i = 0; i < 3; ++i) {
      s.box[i] = n.box_center[i];
      s.half[i] = n.box_half[i];
    }
    for (int i = 0; i < 3; ++i) {
      s.center[i] = mRot(i, 0) * c[0] + mRot(i, 1) * c[1] + mRot(i, 2) * c[2] + mTrans[i];
      s.box_in_a[i] = mRot(i, 0) * s.box[0] + mRot(i, 1) * s.box[1] + mRot(i, 2) * s.box[2] + mTrans[i];
      s.reach_on_a[i] = mAbsRot(i, 0) * s.half[0] + mAbsRot(i, 1) * s.half[1] + mAbsRot(i, 2) * s.half[2];
    }
    const BvhNodeFilter& f = mB.filters[ib];
    for (int i = 0; i < 3; ++i) s.slab_axis[i] = f.cone_axis[i];
    for (int i = 0; i < 3; ++i) {
      s.slab_on_a[i] = std::abs(mRot(i, 0) * s.slab_axis[0] + mRot(i, 1) * s.slab_axis[1] + mRot(i, 2) * s.slab_axis[2]) +
                       kRotationHair;
    }
    s.slab_lo = f.slab_lo;
    s.slab_hi = f.slab_hi;
    return s;
  }

  /// The node-node test on prepared nodes: spheres within the tolerance, boxes not separated by a
  /// face axis, each box not separated from the other node's slab, some compatible groups, normal
  /// cones able to face each other (contact only).
  /// Conservative: every bound carries the safety margin (see the constructor).
  [[nodiscard]] bool node_test(const SideA& a, const SideB& b) const {
    if (!node_within(a, b, mReach, mSlabReach)) return false;
    if (mKind == QueryKind::contact && !cones_can_face(mA.filters[a.index], mB.filters[b.index])) return false;
    return true;
  }

  /// The node-node test on node ia of A and node ib of B (the same arithmetic as above).
  [[nodiscard]] bool node_test(std::uint32_t ia, std::uint32_t ib) const { return node_test(prepare_a(ia), prepare_b(ib)); }

  /// The distance within which the node and leaf tests keep what a distance d keeps: d plus the
  /// safety margin (rounding in the transformed centers and vertices, certified far below it).
  [[nodiscard]] double reach_for(double d) const { return d + kRelativeMargin * (mScale + d); }

  /// The geometric part of the node test (no cones), within `reach` (reach_for of a distance):
  /// false only when no triangle pair below the two nodes can be within it, or none may touch.
  [[nodiscard]] bool node_within(const SideA& a, const SideB& b, double reach) const {
    return node_within(a, b, reach, reach * (1.0 + 1e-6));
  }

  /// A lower bound on the distance between any triangles below the two nodes, before the safety
  /// margin: the largest of the gap between their spheres and the distances between one node's
  /// box and the box around the other's along the first one's axes (in A's frame, then in B's).
  [[nodiscard]] static double gap(const SideA& a, const SideB& b) {
    double dist2 = 0.0, in_a = 0.0, in_b = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double d = a.center[i] - b.center[i];
      dist2 += d * d;
      const double ga = std::max(0.0, std::abs(b.box_in_a[i] - a.box[i]) - a.half[i] - b.reach_on_a[i]);
      const double gb = std::max(0.0, std::abs(b.box[i] - a.box_in_b[i]) - b.half[i] - a.reach_on_b[i]);
      in_a += ga * ga;
      in_b += gb * gb;
    }
    return std::max({std::sqrt(dist2) - a.radius - b.radius, std::sqrt(in_a), std::sqrt(in_b), 0.0});
  }

  /// The leaf test on triangles (ta of A, tb of B); appends a Candidate when the pair is reported.
  /// Returns whether it did.
  bool leaf_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out) const;

  /// The leaf test of a distance traversal: when the triangles are within `bound` (and allowed by
  /// groups), writes their distance and closest points to `out` and returns true. The arithmetic of
  /// leaf_test, so a pair has the same distance whichever of the two computed it.
  bool leaf_distance(std::uint32_t ta, std::uint32_t tb, double bound, Candidate& out) const;

  /// Model A.
  [[nodiscard]] const Model& a() const { return mA; }
  /// Model B.
  [[nodiscard]] const Model& b() const { return mB; }
  /// The query.
  [[nodiscard]] const QueryRequest& request() const { return mRequest; }
  /// Pose of A (to bring results to world coordinates).
  [[nodiscard]] const Pose& pose_a() const { return mPoseA; }
  /// Rotation taking B's object frame to A's.
  [[nodiscard]] const Eigen::Matrix3d& rotation_b_to_a() const { return mRot; }
  /// Vertex k of triangle tb of B, in A's frame (the one formula every test uses).
  [[nodiscard]] Eigen::Vector3d b_vertex(std::uint32_t tb, int k) const {
    return mRot * mB.mesh.vertices[mB.mesh.triangles[tb][k]] + mTrans;
  }

 private:
  /// Relative safety margin on every bound: rounding in the transformed centers and vertices is a
  /// few ulps (~1e-16 relative) of the coordinates' magnitude; 1e-9 of it is far above that and far
  /// below any size that changes how much the prune prunes.
  static constexpr double kRelativeMargin = 1e-9;

  /// Spheres, boxes, slabs and groups within `reach` (slabs: `slab_reach`).
  [[nodiscard]] bool node_within(const SideA& a, const SideB& b, double reach, double slab_reach) const {
    double dist2 = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double d = a.center[i] - b.center[i];
      dist2 += d * d;
    }
    const double spheres = a.radius + b.radius + reach;
    if (dist2 > spheres * spheres) return false;
    for (int i = 0; i < 3; ++i) {  // A's axes
      if (std::abs(b.box_in_a[i] - a.box[i]) > a.half[i] + b.reach_on_a[i] + reach) return false;
    }
    for (int j = 0; j < 3; ++j) {  // B's axes
      if (std::abs(b.box[j] - a.box_in_b[j]) > b.half[j] + a.reach_on_b[j] + reach) return false;
    }
    if (box_beyond_slab(a.slab_axis, a.slab_on_b, a.slab_lo, a.slab_hi, b.box_in_a, b.half, slab_reach)) return false;
    if (box_beyond_slab(b.slab_axis, b.slab_on_a, b.slab_lo, b.slab_hi, a.box_in_b, a.half, slab_reach)) return false;
    if (mGroups != nullptr && !groups_can_touch(mA.filters[a.index].groups, mB.filters[b.index].groups)) return false;
    return true;
  }
  bool cones_can_face(const BvhNodeFilter& na, const BvhNodeFilter& nb) const;
  /// Whether the groups of triangles ta (of A) and tb (of B) may touch (always without groups).
  [[nodiscard]] bool groups_allow(std::uint32_t ta, std::uint32_t tb) const;
  /// The leaf test within `bound` (its reach given: leaf_test passes mReach, computed once): calls
  /// keep(candidate) and returns true when the triangles are within it. Defined in the .cpp, the
  /// only place that calls it.
  template <class Keep>
  bool leaf_within(std::uint32_t ta, std::uint32_t tb, double bound, double reach, Keep&& keep) const;
  bool groups_can_touch(std::uint64_t ga, std::uint64_t gb) const;
  /// Whether a box lies beyond the slab lo <= axis . x <= hi by more than the reach: `center` is the
  /// box's center in the slab's frame, `half` its half-extents along its own axes, and `on[k]` is
  /// |axis . box axis k|. A gap g along an axis up to 1 + 1e-6 long is a distance >= g / |axis|.
  [[nodiscard]] bool box_beyond_slab(const double axis[3], const double on[3], double lo, double hi, const double center[3],
                                     const double half[3], double slab_reach) const {
    const double at = axis[0] * center[0] + axis[1] * center[1] + axis[2] * center[2];
    const double reach = on[0] * half[0] + on[1] * half[1] + on[2] * half[2];
    return at - reach > hi + slab_reach || at + reach < lo - slab_reach;
  }

  const Model& mA;
  const Model& mB;
  Pose mPoseA;
  QueryRequest mRequest;
  QueryKind mKind;
  const GroupCompatibility* mGroups;
  Eigen::Matrix3d mRot;
  Eigen::Matrix3d mAbsRot;  ///< |mRot|, grown by a relative hair (rounding in the rotation)
  Eigen::Vector3d mTrans;
  double mScale;       ///< extents of A and B plus their distance: what the safety margin is relative to
  double mReach;       ///< tolerance + safety margin added to the sum of radii
  double mSlabReach;   ///< mReach for gaps along a slab axis (up to 1 + 1e-6 long)
  double mTheta;       ///< contact angle, radians
  double mCosTheta;    ///< cos(theta)
  double mSinTheta;    ///< sin(theta)
};

}  // namespace caliber::narrow
