#pragma once
/// \file
/// Everything one object pair's traversal needs: the relative pose, the query's limits and the
/// node-node and leaf tests. The leaf test is the single source of truth for what a query reports;
/// the node test only prunes, and must never prune a pair the leaf test would keep.

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

/// The per-pair state of a query: immutable while traversals run, so several threads may traverse
/// disjoint parts of one pair's CD tree with the same context.
class PairContext {
 public:
  /// Precomputes B's pose in A's frame and the safety margin. Validates the request.
  PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request);

  /// The node-node test: spheres within the tolerance, normal cones able to face each other
  /// (contact only), some compatible groups. Conservative: see the margins in the definition.
  [[nodiscard]] bool node_test(std::uint32_t ia, std::uint32_t ib) const {
    const BvhNode& na = mA.nodes[ia];
    const BvhNode& nb = mB.nodes[ib];
    const double* cb = nb.center;
    const double* ca = na.center;
    const double dx = ca[0] - (mRot(0, 0) * cb[0] + mRot(0, 1) * cb[1] + mRot(0, 2) * cb[2] + mTrans[0]);
    const double dy = ca[1] - (mRot(1, 0) * cb[0] + mRot(1, 1) * cb[1] + mRot(1, 2) * cb[2] + mTrans[1]);
    const double dz = ca[2] - (mRot(2, 0) * cb[0] + mRot(2, 1) * cb[1] + mRot(2, 2) * cb[2] + mTrans[2]);
    const double reach = na.radius + nb.radius + mReach;
    if (dx * dx + dy * dy + dz * dz > reach * reach) return false;
    if (!boxes_overlap(mA.boxes[ia], mB.boxes[ib])) return false;
    if (mKind == QueryKind::contact && !cones_can_face(na, nb)) return false;
    if (mGroups != nullptr && !groups_can_touch(na.groups, nb.groups)) return false;
    return true;
  }

  /// Separating-axis test of A's box against B's box (in B's frame) on the six face axes, with the
  /// tolerance and safety margin added: false only if some face axis separates them by more.
  [[nodiscard]] bool boxes_overlap(const BvhBox& ba, const BvhBox& bb) const {
    const double* cb = bb.center;
    const double* hb = bb.half;
    const double* ha = ba.half;
    double t[3];
    for (int i = 0; i < 3; ++i) {
      t[i] = mRot(i, 0) * cb[0] + mRot(i, 1) * cb[1] + mRot(i, 2) * cb[2] + mTrans[i] - ba.center[i];
    }
    for (int i = 0; i < 3; ++i) {  // A's axes
      const double rb = mAbsRot(i, 0) * hb[0] + mAbsRot(i, 1) * hb[1] + mAbsRot(i, 2) * hb[2];
      if (std::abs(t[i]) > ha[i] + rb + mReach) return false;
    }
    for (int j = 0; j < 3; ++j) {  // B's axes
      const double tj = mRot(0, j) * t[0] + mRot(1, j) * t[1] + mRot(2, j) * t[2];
      const double ra = mAbsRot(0, j) * ha[0] + mAbsRot(1, j) * ha[1] + mAbsRot(2, j) * ha[2];
      if (std::abs(tj) > hb[j] + ra + mReach) return false;
    }
    return true;
  }

  /// The leaf test on triangles (ta of A, tb of B); appends a Candidate when the pair is reported.
  /// Returns whether it did.
  bool leaf_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out) const;

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
  bool cones_can_face(const BvhNode& na, const BvhNode& nb) const;
  bool groups_can_touch(std::uint64_t ga, std::uint64_t gb) const;

  const Model& mA;
  const Model& mB;
  Pose mPoseA;
  QueryRequest mRequest;
  QueryKind mKind;
  const GroupCompatibility* mGroups;
  Eigen::Matrix3d mRot;
  Eigen::Matrix3d mAbsRot;  ///< |mRot|, grown by a relative hair (rounding in the rotation)
  Eigen::Vector3d mTrans;
  double mReach;       ///< tolerance + safety margin added to the sum of radii
  double mTheta;       ///< contact angle, radians
  double mCosTheta;    ///< cos(theta)
};

}  // namespace caliber::narrow
