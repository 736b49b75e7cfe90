#pragma once
/// \file
/// Everything one object pair's traversal needs: the relative pose, the query's limits and the
/// node-node and leaf tests. The leaf test is the single source of truth for what a query reports;
/// the node test only prunes, and must never prune a pair the leaf test would keep.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"
#include "geometry/rigid_move.h"
#include "narrow/candidate.h"
#include "narrow/disks.h"
#include "narrow/distance_bound_avx2.h"
#include "narrow/frames_apart.h"
#include "narrow/leaf_buffer.h"
#include "narrow/node_test_avx2.h"
#include "narrow/prepared.h"

namespace caliber::narrow {

/// In the binary CD tree, a node whose sphere is more than this many times larger than its
/// partner's descends alone (its partner waits): the swept query's traversal.
inline constexpr double kDescendAloneRatio = 2.0;
/// The distance query's: its one-sided visits cost nearly as much as two-sided ones (four lanes of
/// bounds for two children); against 2 (bench_fcl_distance), 4 was faster on the bunny at gap 1, as
/// fast or faster on the armadillo and dragon, mixed on turbine × blade and fandisk × rotor.
inline constexpr double kDescendAloneRatioDistance = 4.0;

/// The per-pair state of a query: immutable while traversals run, so several threads may traverse
/// disjoint parts of one pair's CD tree with the same context.
class PairContext {
  /// Added to |rotation . axis| terms: covers rounding in the rotation and in the products.
  static constexpr double kRotationHair = 1e-12;
  /// Margin on the cosine in the cone test: covers float-rounded cone axes (|axis| = 1 +- 2e-7).
  static constexpr double kConeCosMargin = 1e-6;
  /// The distance bound's Frames have axes orthonormal to about 1e-15, and frames_apart divides
  /// its separation once by its direction's length (a square root and a division, each rounded):
  /// dividing by 1 + 1e-9 covers both; multiplying by 1 - 3e-9, below 1 / (1 + 1e-9) by far more
  /// than a rounding, shrinks it a little more and costs no division.
  static constexpr double kApartShrink = 1.0 - 3e-9;

 public:
  /// Precomputes B's pose in A's frame and the safety margin. Validates the request and the poses.
  PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request);
  /// Says that the caller has validated the request and the poses (validate_request,
  /// validate_pose): an engine's frame, a batch's poses, checked once for all their pairs.
  struct Validated {};
  /// The same context, made without validating again.
  PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request, Validated);
  /// The same pair and poses (and group table) asked for interference that stops at its first
  /// pair (max_pairs 1): what a distance traversal from the root tries first (traverse_nearest).
  [[nodiscard]] PairContext first_hit() const;

  using BoxA = narrow::BoxA;
  using BoxB = narrow::BoxB;
  using NodeA = narrow::NodeA;
  using NodeB = narrow::NodeB;
  using SideA = narrow::SideA;
  using SideB = narrow::SideB;
  /// Prepares node ia of A for node tests.
  [[nodiscard]] SideA prepare_a(std::uint32_t ia) const {
    SideA s;
    fill_a(ia, s);
    const BvhNodeFilter& f = mA.filters[ia];
    for (int i = 0; i < 3; ++i) s.slab_axis[i] = f.cone_axis[i];
    for (int j = 0; j < 3; ++j) {
      s.slab_on_b[j] =
          std::abs(mRot(0, j) * s.slab_axis[0] + mRot(1, j) * s.slab_axis[1] + mRot(2, j) * s.slab_axis[2]) + kRotationHair;
    }
    s.slab_lo = f.slab_lo;
    s.slab_hi = f.slab_hi;
    return s;
  }
  /// Prepares node ib of B for node tests.
  [[nodiscard]] SideB prepare_b(std::uint32_t ib) const {
    SideB s;
    fill_b(ib, s);
    const BvhNodeFilter& f = mB.filters[ib];
    for (int i = 0; i < 3; ++i) s.slab_axis[i] = f.cone_axis[i];
    for (int i = 0; i < 3; ++i) {
      s.axis_in_a[i] = mRot(i, 0) * s.slab_axis[0] + mRot(i, 1) * s.slab_axis[1] + mRot(i, 2) * s.slab_axis[2];
      s.slab_on_a[i] = std::abs(s.axis_in_a[i]) + kRotationHair;
    }
    s.slab_lo = f.slab_lo;
    s.slab_hi = f.slab_hi;
    return s;
  }
  /// Adds its disk to a prepared node of A (for node_test_2x2_lane).
  void prepare_disk_a(SideA& s) const;
  /// Adds its disk to a prepared node of B (its sphere's center in B's own frame).
  void prepare_disk_b(SideB& s) const;
  /// The node-node test on prepared nodes: spheres within the tolerance, boxes not separated by a
  /// face axis, each box not separated from the other node's slab, some compatible groups, normal
  /// cones able to face each other (contact only). (node_test_2x2_lane adds the disks.)
  /// Conservative: every bound carries the safety margin (see the constructor).
  [[nodiscard]] bool node_test(const SideA& a, const SideB& b) const {
    return node_within(a, b, mReach, mSlabReach) &&
           (mKind != QueryKind::contact || cones_can_face(mA.filters[a.index], mB.filters[b.index]));
  }

  /// The node test of a visit where both sides descend: node_test, and neither node's disk beyond
  /// the other's slab (disks_beyond_slabs; both nodes prepared with their disks). One-sided visits
  /// use node_test alone: on turbine × blade the disks refused none of them and cost noticeably.
  [[nodiscard]] bool node_test_2x2_lane(const SideA& a, const SideB& b) const {
    return node_test(a, b) && !narrow::disks_beyond_slabs(a, b, mSlabReach);
  }
  /// The same on node ia of A and node ib of B, prepared here.
  [[nodiscard]] bool node_test_2x2_lane(std::uint32_t ia, std::uint32_t ib) const;
  /// node_test_2x2_lane on the four pairs of nodes a0 or a1 of A with b0 or b1 of B (the children
  /// of a visit where both sides descend): bit 2i + j set where ai and bj pass; four at a time in
  /// AVX2 where the CPU has it (node_test_avx2.cpp), the same decisions. `lanes`: node_lanes(),
  /// made once by a traversal (else made here).
  [[nodiscard]] int node_tests_2x2(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                   const detail::NodeLanes* lanes = nullptr) const;
  /// The same, one pair at a time: what node_tests_2x2 runs where the CPU has no AVX2.
  [[nodiscard]] int node_tests_2x2_scalar(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) const;
  /// node_test on a one-sided visit's children: a0 with b0 (bit 0), a1 with b1 (bit 3), the node that
  /// stays given twice; node_tests_2x2's lanes without disks (1 and 2 cleared), else pair by pair.
  [[nodiscard]] int node_tests_one_side(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                        const detail::NodeLanes* lanes = nullptr) const;
  /// What the four-lane forms read of this context, its pose in their lanes (make_lanes), and the
  /// scale of their float stage's slack (the wide test's too: narrow::wide_lanes).
  [[nodiscard]] const detail::NodeTestFrame& node_test_frame() const { return mNodeFrame; }
  [[nodiscard]] detail::NodeLanes node_lanes() const { return detail::make_lanes(mNodeFrame, lanes_scale()); }
  [[nodiscard]] double lanes_scale() const;
  /// Whether groups or normal cones may refuse a pair (a table of groups, or the contact kind), and
  /// whether they let node ia of A and node ib of B touch.
  [[nodiscard]] bool refuses_by_groups_or_cones() const { return mGroups != nullptr || mKind == QueryKind::contact; }
  [[nodiscard]] bool groups_and_cones_allow(std::uint32_t ia, std::uint32_t ib) const;
  /// The node-node test on node ia of A and node ib of B (the same arithmetic as above).
  [[nodiscard]] bool node_test(std::uint32_t ia, std::uint32_t ib) const { return node_test(prepare_a(ia), prepare_b(ib)); }

  /// How far apart the spheres of node ia of A and node ib of B are, relative to their size:
  /// |c_a - c_b|^2 / (r_a + r_b)^2 (below 1 where they overlap, the less the deeper). Orders the
  /// distance traversal's pieces that stop at contact: they enter the most overlapping touching children
  /// first (visit_order.h).
  [[nodiscard]] double sphere_apart(std::uint32_t ia, std::uint32_t ib) const;

  /// The CD tree's ratio for descending alone (cd_descend): kDescendAloneRatioDistance in a
  /// distance query, kDescendAloneRatio in the others.
  [[nodiscard]] double descend_alone_ratio() const { return mDescendAlone; }

  /// The distance within which the node and leaf tests keep what a distance d keeps: d plus the
  /// safety margin (rounding in the transformed centers and vertices, certified far below it).
  /// mScale: the extents of A and B about their volume origins plus the distance between those;
  /// where a model's volumes have an origin of their own (ModelData::origin), plus a thousandth of
  /// the absolute scale (extents about the origins and distance), for the vertices and the
  /// translation between the volume origins round at that scale: a margin of 1e-12 of it.
  [[nodiscard]] double reach_for(double d) const { return d + kRelativeMargin * (mScale + d); }

  using OrientedBox = narrow::OrientedBox;
  using NearA = narrow::NearA;
  using NearB = narrow::NearB;

  /// Prepares node ia of A for the distance bound, in s (where a distance traversal keeps it).
  void near(std::uint32_t ia, NearA& s) const {
    fill_box_a(ia, s);
    OrientedBox computed;
    s.frame = own_frame(mA, ia, computed);
  }
  /// Prepares node ib of B for the distance bound, in s (its frame brought into A's).
  void near(std::uint32_t ib, NearB& s) const;

  /// A lower bound on the distance between any triangles below two nodes, before the safety
  /// margin, when it is at most `reach` (reach_for of a distance); otherwise some number above
  /// `reach` (the boxes' bound is tried first and ends the test when beyond), and +infinity when
  /// groups forbid every pair below. The bound is the larger of the distances between one node's
  /// box and the box around the other's along the first one's axes (in A's frame, then in B's;
  /// along orthonormal axes the squared gaps add up to a squared distance) and, when that is within
  /// `reach`, the Frames' separation along the direction between a point of each (frames_apart).
  /// (The spheres' gap and the Frames' gaps along their own six axes refused almost none of the
  /// child pairs these two let through on bench_fcl_distance's cases: not part of it.)
  [[nodiscard]] double gap(const NearA& a, const NearB& b, double reach) const {
    double boxes_a = 0.0, boxes_b = 0.0;
    for (int i = 0; i < 3; ++i) {
      boxes_a += square(std::max(0.0, std::abs(b.box_in_a[i] - a.box[i]) - a.half[i] - b.reach_on_a[i]));
      boxes_b += square(std::max(0.0, std::abs(b.box[i] - a.box_in_b[i]) - b.half[i] - a.reach_on_b[i]));
    }
    const double boxes = std::sqrt(std::max(boxes_a, boxes_b));
    if (boxes > reach) return boxes;
    if (mGroups != nullptr && !groups_can_touch(mA.group_mask(a.index), mB.group_mask(b.index))) {
      return std::numeric_limits<double>::infinity();
    }
    double d[3], r[3][3], t[3];
    for (int i = 0; i < 3; ++i) d[i] = b.frame.center[i] - a.frame.center[i];
    frames_relative(a.frame, b.frame, d, r, t);
    return std::max(boxes, frames_apart(a.frame.half, b.frame.half, r, t, kRotationHair, kApartShrink));
  }

  /// gap on the four pairs of prepared nodes a0 or a1 of A with b0 or b1 of B (a visit's children
  /// where both sides descend): out[2i + j] for ai and bj. The same value as gap(ai, bj, reach)
  /// wherever that is within `reach`, and beyond `reach` where that is; four lanes of AVX2 where the
  /// CPU has it (distance_bound_avx2.cpp).
  void gaps_2x2(const NearA& a0, const NearA& a1, const NearB& b0, const NearB& b1, double reach, double out[4]) const;

  /// The leaf test on triangles (ta of A, tb of B); appends a Candidate when the pair is reported.
  /// Returns whether it did.
  bool leaf_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out) const;
  /// The same, the pair waiting in `buffer` for the batch kernels: once they run (a full batch, or
  /// flush_leaves), `out` has what leaf_test would have appended, in the same order (interference
  /// without groups, where the CPU has the batch kernels, inlined here: the pair waits, its
  /// triangles' corner ids asked of memory).
  void leaf_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out, LeafBuffer& buffer) const {
    if (!mIntersectWaits) return wait_or_test(ta, tb, out, buffer);
    wait_to_intersect(ta, tb, out, buffer.refusal);
  }
  /// Finishes the pairs waiting in `buffer` (their candidates appended to `out`) and empties it.
  void flush_leaves(LeafBuffer& buffer, std::vector<Candidate>& out) const;
  /// The same within `bound` (not the tolerance): leaf_distance's verdicts and candidates, in the
  /// order the pairs came, for pairs put there by wait_leaf.
  void flush_leaves(LeafBuffer& buffer, std::vector<Candidate>& out, double bound) const;
  /// Puts (ta, tb) in `buffer` unless groups refuse it: true when the batch is now full.
  bool wait_leaf(std::uint32_t ta, std::uint32_t tb, LeafBuffer& buffer) const;

  /// The leaf test of a distance traversal: when the triangles are within `bound` (and allowed by
  /// groups), writes their distance and closest points to `out` and returns true. The arithmetic of
  /// leaf_test, so a pair has the same distance whichever of the two computed it.
  bool leaf_distance(std::uint32_t ta, std::uint32_t tb, double bound, Candidate& out) const;

  [[nodiscard]] const ModelData& a() const { return mA; }                 ///< Model A.
  [[nodiscard]] const ModelData& b() const { return mB; }                 ///< Model B.
  [[nodiscard]] const QueryRequest& request() const { return mRequest; }  ///< The query.
  [[nodiscard]] const Pose& pose_a() const { return mPoseA; }             ///< Pose of A (for world coordinates).
  /// Rotation taking B's object frame to A's.
  [[nodiscard]] const Eigen::Matrix3d& rotation_b_to_a() const { return mRot; }
  /// The move of B's vertices into A's frame (the one formula every test uses: geometry::RigidMove).
  [[nodiscard]] geometry::RigidMove b_move() const { return {mRot, mTrans}; }
  /// Vertex k of triangle tb of B, in A's frame (b_move).
  [[nodiscard]] Eigen::Vector3d b_vertex(std::uint32_t tb, int k) const {
    return b_move()(mB.mesh.vertices[mB.mesh.triangles[tb][k]]);
  }
  /// Reads the corners of the pairs waiting in `waiting` (their ids, batch.size of them) into its
  /// batch, B's moved into A's frame with b_vertex's arithmetic: the same bits as corners().
  void gather_corners(BufferedPairs& waiting) const;
  /// The contact kind's normal test on a leaf pair (true for other kinds): a leaf test's first step.
  [[nodiscard]] bool normals_allow(std::uint32_t ta, std::uint32_t tb) const;

 private:
  /// Relative safety margin on every bound: rounding in the transformed centers and vertices is a
  /// few ulps (~1e-16 relative) of the coordinates' magnitude; 1e-9 of it is far above that and far
  /// below any size that changes how much the prune prunes.
  static constexpr double kRelativeMargin = 1e-9;
  /// The share of the absolute scale in mScale where volumes have an origin of their own: a margin
  /// of 1e-12 of it, a thousand times the few ulps (~1e-15 relative) its rounding costs.
  static constexpr double kAbsoluteShare = 1e-3;

  /// `pass` (bit 2i + j: ai and bj) less the pairs that groups or normal cones refuse (where some can).
  [[nodiscard]] int groups_and_cones(int pass, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) const;
  /// node_tests_2x2 (or, `one_side`, node_tests_one_side) with its form `within` (or none) where the
  /// lanes are not given or groups or cones may refuse.
  [[nodiscard]] int node_tests_otherwise(detail::NodeWithin2x2 within, bool one_side, std::uint32_t a0, std::uint32_t a1,
                                         std::uint32_t b0, std::uint32_t b1, const detail::NodeLanes* lanes) const;
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
    if (mGroups != nullptr && !groups_can_touch(mA.group_mask(a.index), mB.group_mask(b.index))) return false;
    return true;
  }
  bool cones_can_face(const BvhNodeFilter& na, const BvhNodeFilter& nb) const;
  /// The corners of triangle ta of A and of tb of B, B's in A's frame (b_vertex).
  void corners(std::uint32_t ta, std::uint32_t tb, Eigen::Vector3d a[3], Eigen::Vector3d b[3]) const;
  /// Whether the groups of triangles ta (of A) and tb (of B) may touch (always without groups).
  [[nodiscard]] bool groups_allow(std::uint32_t ta, std::uint32_t tb) const;
  /// The leaf test within `bound` (its reach given: leaf_test passes mReach, computed once): calls
  /// keep(candidate) and returns true when the triangles are within it. Defined in the .cpp, the
  /// only place that calls it.
  template <class Keep>
  bool leaf_within(std::uint32_t ta, std::uint32_t tb, double bound, double reach, Keep&& keep) const;
  /// The buffered refusal beyond `reach` (the pairs it does not refuse move on), the buffered
  /// closest points (the pairs within `bound` appended to `out`).
  void refuse_buffered(LeafBuffer& buffer, std::vector<Candidate>& out, double bound, double reach) const;
  void finish_buffered(LeafBuffer& buffer, std::vector<Candidate>& out, double bound) const;
  /// The buffered interference tests (gather_corners, triangles_intersect_batch): the pairs that meet to `out`.
  void intersect_buffered(BufferedPairs& waiting, std::vector<Candidate>& out) const;
  bool groups_can_touch(std::uint64_t ga, std::uint64_t gb) const;
  static double square(double x) { return x * x; }
  /// The box of a prepared node of A (SideA or NearA).
  void fill_box_a(std::uint32_t ia, BoxA& s) const {
    const BvhNode& n = mA.nodes[ia];
    s.index = ia;
    for (int i = 0; i < 3; ++i) {
      s.box[i] = n.box_center[i];
      s.half[i] = n.box_half[i];
    }
    // B's frame: x_b = R^T (x_a - T).
    const double rel[3] = {s.box[0] - mNodeFrame.trans[0], s.box[1] - mNodeFrame.trans[1], s.box[2] - mNodeFrame.trans[2]};
    for (int j = 0; j < 3; ++j) {
      s.box_in_b[j] = mRot(0, j) * rel[0] + mRot(1, j) * rel[1] + mRot(2, j) * rel[2];
      s.reach_on_b[j] = mAbsRot(0, j) * s.half[0] + mAbsRot(1, j) * s.half[1] + mAbsRot(2, j) * s.half[2];
    }
  }
  /// The NodeA part of a prepared node of A (SideA): its box and its sphere.
  void fill_a(std::uint32_t ia, NodeA& s) const {
    fill_box_a(ia, s);
    const BvhNode& n = mA.nodes[ia];
    s.radius = n.radius;
    for (int i = 0; i < 3; ++i) s.center[i] = n.center[i];
  }
  /// The box of a prepared node of B (SideB or NearB), brought into A's frame.
  void fill_box_b(std::uint32_t ib, BoxB& s) const {
    const BvhNode& n = mB.nodes[ib];
    s.index = ib;
    for (int i = 0; i < 3; ++i) {
      s.box[i] = n.box_center[i];
      s.half[i] = n.box_half[i];
    }
    for (int i = 0; i < 3; ++i) {
      s.box_in_a[i] = mRot(i, 0) * s.box[0] + mRot(i, 1) * s.box[1] + mRot(i, 2) * s.box[2] + mNodeFrame.trans[i];
      s.reach_on_a[i] = mAbsRot(i, 0) * s.half[0] + mAbsRot(i, 1) * s.half[1] + mAbsRot(i, 2) * s.half[2];
    }
  }
  /// The NodeB part of a prepared node of B (SideB): its box and its sphere, brought into A's frame.
  void fill_b(std::uint32_t ib, NodeB& s) const {
    fill_box_b(ib, s);
    const BvhNode& n = mB.nodes[ib];
    s.radius = n.radius;
    const double c[3] = {n.center[0], n.center[1], n.center[2]};
    for (int i = 0; i < 3; ++i) s.center[i] = mRot(i, 0) * c[0] + mRot(i, 1) * c[1] + mRot(i, 2) * c[2] + mNodeFrame.trans[i];
  }
  /// A node's oriented box in its own model's frame: the model's oriented box where it keeps them, else
  /// computed by the same function.
  static const OrientedBox& own_frame(const ModelData& m, std::uint32_t i, OrientedBox& computed) {
    if (!m.oriented_boxes.empty()) return m.oriented_boxes[i];
    node_oriented_box(m.nodes[i], m.filters[i], m.laterals[i], computed);
    return computed;
  }
  /// Whether a box lies beyond the slab lo <= axis . x <= hi by more than the reach: `center` is the
  /// box's center in the slab's frame, `half` its half-extents along its own axes, and `on[k]` is
  /// |axis . box axis k|. A gap g along an axis up to 1 + 1e-6 long is a distance >= g / |axis|.
  [[nodiscard]] bool box_beyond_slab(const double axis[3], const double on[3], double lo, double hi, const double center[3],
                                     const double half[3], double slab_reach) const {
    const double at = axis[0] * center[0] + axis[1] * center[1] + axis[2] * center[2];
    const double reach = on[0] * half[0] + on[1] * half[1] + on[2] * half[2];
    return at - reach > hi + slab_reach || at + reach < lo - slab_reach;
  }

  /// Sets what depends on the request: its kind, reach, angle and group table.
  void ask(const QueryRequest& request);
  /// An interference pair waiting for the batch kernels (its triangles' corner ids asked of memory,
  /// read when the batch is full: gather_corners).
  void wait_to_intersect(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out, BufferedPairs& waiting) const {
    waiting.ta[waiting.batch.size] = ta;
    waiting.tb[waiting.batch.size] = tb;
    __builtin_prefetch(&mA.mesh.triangles[ta]);
    __builtin_prefetch(&mB.mesh.triangles[tb]);
    if (++waiting.batch.size == geometry::TriangleBatch::kLanes) intersect_buffered(waiting, out);
  }
  /// leaf_test with a buffer where the inlined steps do not apply.
  void wait_or_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out, LeafBuffer& buffer) const;

  const ModelData& mA;
  const ModelData& mB;
  Pose mPoseA;
  QueryRequest mRequest;
  QueryKind mKind;
  bool mIntersectWaits;  ///< interference without groups where the CPU has the batch kernels: its pairs wait for them
  const GroupCompatibility* mGroups;
  Eigen::Matrix3d mRot;
  Eigen::Matrix3d mAbsRot;           ///< |mRot|, grown by a relative hair (rounding in the rotation)
  Eigen::Vector3d mTrans;            ///< B's origin in A's frame: what B's vertices are moved by (B's nodes: mNodeFrame.trans)
  double mDescendAlone;              ///< descend_alone_ratio()
  double mScale;                     ///< what the safety margin is relative to (see reach_for)
  double mReach;                     ///< tolerance + safety margin added to the sum of radii
  double mSlabReach;                 ///< mReach for gaps along a slab axis (up to 1 + 1e-6 long)
  double mTheta;                     ///< contact angle, radians
  double mCosTheta;                  ///< cos(theta) (contact only; 1 otherwise)
  double mSinTheta;                  ///< sin(theta) (contact only; 0 otherwise)
  detail::NodeTestFrame mNodeFrame;  ///< what node_tests_2x2's AVX2 form reads of the above
};

/// A step's pair contexts, one per pair of the frame, in the frame's pair order.
using PairContexts = std::span<const PairContext>;

}  // namespace caliber::narrow
