#include "narrow/pair_context.h"

#include <numbers>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Geometry>

#include "geometry/triangle_distance.h"
#include "narrow/finalize.h"
#include "geometry/triangle_intersect.h"

namespace caliber::narrow {
namespace {
/// The request, once it and both poses are validated.
const QueryRequest& validated(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b,
                              const QueryRequest& request) {
  validate_request(request);
  validate_pose(pose_a, "pose of A");
  validate_pose(pose_b, "pose of B");
  check_contact_models(request, a, b, "model A", "model B");
  return request;
}
bool intersect_in_batches();
}  // namespace

PairContext::PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request)
    : PairContext(a, pose_a, b, pose_b, validated(a, pose_a, b, pose_b, request), Validated{}) {}

PairContext::PairContext(const Model& a, const Pose& pose_a, const Model& b, const Pose& pose_b, const QueryRequest& request,
                         Validated)
    : mA(data(a)), mB(data(b)), mPoseA(pose_a), mRequest(request), mKind(request.kind), mGroups(request.groups) {
  const Eigen::Matrix3d ra = pose_a.rotation_matrix();
  const Eigen::Matrix3d rb = pose_b.rotation_matrix();
  mRot = ra.transpose() * rb;
  mTrans = ra.transpose() * (pose_b.translation - pose_a.translation);
  // A point x of B's volumes (x + origin_B in B's frame) is at R (x + origin_B) + T in A's frame,
  // at R x + (R origin_B + T - origin_A) from A's volume origin. Both origins zero: mTrans itself.
  const bool local = mA.origin != Eigen::Vector3d::Zero() || mB.origin != Eigen::Vector3d::Zero();
  const Eigen::Vector3d node_trans = local ? Eigen::Vector3d(mRot * mB.origin + mTrans - mA.origin) : mTrans;
  mAbsRot = mRot.cwiseAbs().array() + kRotationHair;
  mScale = mA.local_extent + mB.local_extent + node_trans.norm();
  if (local) mScale += kAbsoluteShare * (mA.extent + mB.extent + mTrans.norm());
  mNodeFrame = {mA.nodes.data(), mA.filters.data(), mB.nodes.data(), mB.filters.data(), {}, {}, {}, kRotationHair, 0.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      mNodeFrame.rot[i][j] = mRot(i, j);
      mNodeFrame.abs_rot[i][j] = mAbsRot(i, j);
    }
    mNodeFrame.trans[i] = node_trans[i];
  }
  ask(request);
}

void PairContext::ask(const QueryRequest& request) {
  mRequest = request;
  mKind = request.kind;
  mGroups = request.groups;
  mDescendAlone = request.kind == QueryKind::distance ? kDescendAloneRatioDistance : kDescendAloneRatio;
  mReach = reach_for(reach(request));
  mSlabReach = mReach * (1.0 + 1e-6);
  mIntersectWaits = request.kind == QueryKind::interference && request.groups == nullptr && intersect_in_batches();
  mNodeFrame.reach = mReach;
  mNodeFrame.slab_reach = mSlabReach;
  // The angle is read by the contact kind's tests alone (cones_can_face, normals_allow): the
  // other kinds skip the cosine and sine (a noticeable part of a small query's context).
  mTheta = request.angle_deg * std::numbers::pi / 180.0;
  mCosTheta = 1.0;
  mSinTheta = 0.0;
  if (request.kind == QueryKind::contact) {
    mCosTheta = std::cos(mTheta);
    mSinTheta = std::sin(mTheta);
  }
}

PairContext PairContext::first_hit() const {
  QueryRequest request;
  request.kind = QueryKind::interference;
  request.max_pairs = 1;
  request.groups = mRequest.groups;
  PairContext out = *this;
  out.ask(request);
  return out;
}

bool PairContext::node_test_2x2_lane(std::uint32_t ia, std::uint32_t ib) const {
  SideA a = prepare_a(ia);
  SideB b = prepare_b(ib);
  prepare_disk_a(a);
  prepare_disk_b(b);
  return node_test_2x2_lane(a, b);
}

double PairContext::lanes_scale() const {
  // What the float stages' values are at most in magnitude: the extents about the volume origins,
  // the distance between those and the slab reach (not mScale's share of the absolute scale: the
  // lanes compute from the local values alone).
  const double* t = mNodeFrame.trans;
  const double between = std::sqrt((t[0] * t[0] + t[1] * t[1]) + t[2] * t[2]);
  return mA.local_extent + mB.local_extent + between + mSlabReach;
}

namespace {
/// The four-lane forms this CPU runs (with and without the disks), chosen when the library loads:
/// a function's own static would be checked, behind a frame, at every call. (Null before that, or
/// where the CPU has no AVX2: the scalar forms, the same decisions.)
const detail::NodeWithin2x2 kWithin2x2 = detail::node_within_2x2_avx2_if_supported();
const detail::NodeWithin2x2 kWithinOneSide = detail::node_within_2x2_avx2_if_supported(false);
const detail::ConesFace2x2 kConesFace = detail::cones_face_2x2_avx2_if_supported();

}  // namespace

int PairContext::node_tests_2x2(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                const detail::NodeLanes* lanes) const {
  // Without groups or cones (a traversal's common case), the form's bits are the answer: a tail
  // call, the other cases out of line so that this path sets up no frame.
  const detail::NodeWithin2x2 within = kWithin2x2;
  if (within != nullptr && lanes != nullptr && !refuses_by_groups_or_cones()) return within(mNodeFrame, *lanes, a0, a1, b0, b1);
  return node_tests_otherwise(within, false, a0, a1, b0, b1, lanes);
}

int PairContext::node_tests_one_side(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                     const detail::NodeLanes* lanes) const {
  // The form sets bits 0 and 3 alone. As node_tests_2x2.
  const detail::NodeWithin2x2 within = kWithinOneSide;
  if (within != nullptr && lanes != nullptr && !refuses_by_groups_or_cones()) return within(mNodeFrame, *lanes, a0, a1, b0, b1);
  return node_tests_otherwise(within, true, a0, a1, b0, b1, lanes);
}

[[gnu::noinline]] int PairContext::node_tests_otherwise(detail::NodeWithin2x2 within, bool one_side, std::uint32_t a0,
                                                        std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                                        const detail::NodeLanes* lanes) const {
  if (within == nullptr) {
    if (!one_side) return node_tests_2x2_scalar(a0, a1, b0, b1);
    return (node_test(a0, b0) ? 1 : 0) | (node_test(a1, b1) ? 8 : 0);
  }
  detail::NodeLanes made;
  if (lanes == nullptr) {
    made = node_lanes();
    lanes = &made;
  }
  const int pass = within(mNodeFrame, *lanes, a0, a1, b0, b1);
  if (!refuses_by_groups_or_cones() || pass == 0) return pass;
  // A contact query without groups: the four pairs' cones at once (the one-sided form's bits 0
  // and 3 are its pairs a0 b0 and a1 b1).
  if (mGroups == nullptr && kConesFace != nullptr) {
    return pass & kConesFace(mNodeFrame, *lanes, a0, a1, b0, b1, detail::ConeAngle{mTheta, mCosTheta, mSinTheta, kConeCosMargin});
  }
  return groups_and_cones(pass, a0, a1, b0, b1);
}

void PairContext::prepare_disk_a(SideA& s) const {
  for (int i = 0; i < 3; ++i) s.center_from_b[i] = s.center[i] - mNodeFrame.trans[i];
  const double mid = s.slab_axis[0] * s.center[0] + s.slab_axis[1] * s.center[1] + s.slab_axis[2] * s.center[2];
  s.disk_lo = s.slab_lo - mid;
  s.disk_hi = s.slab_hi - mid;
  s.axis_len2 = s.slab_axis[0] * s.slab_axis[0] + s.slab_axis[1] * s.slab_axis[1] + s.slab_axis[2] * s.slab_axis[2];
}

void PairContext::prepare_disk_b(SideB& s) const {
  const float* c = mB.nodes[s.index].center;
  const double mid = s.slab_axis[0] * c[0] + s.slab_axis[1] * c[1] + s.slab_axis[2] * c[2];
  s.disk_lo = s.slab_lo - mid;
  s.disk_hi = s.slab_hi - mid;
  s.axis_len2 = s.slab_axis[0] * s.slab_axis[0] + s.slab_axis[1] * s.slab_axis[1] + s.slab_axis[2] * s.slab_axis[2];
}

int PairContext::node_tests_2x2_scalar(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) const {
  SideA sa[2] = {prepare_a(a0), prepare_a(a1)};
  SideB sb[2] = {prepare_b(b0), prepare_b(b1)};
  for (int i = 0; i < 2; ++i) {
    prepare_disk_a(sa[i]);
    prepare_disk_b(sb[i]);
  }
  int pass = 0;
  for (int k = 0; k < 4; ++k) pass |= node_test_2x2_lane(sa[k / 2], sb[k % 2]) ? 1 << k : 0;
  return pass;
}

void PairContext::corners(std::uint32_t ta, std::uint32_t tb, Eigen::Vector3d a[3], Eigen::Vector3d b[3]) const {
  const auto& tri_a = mA.mesh.triangles[ta];
  for (int k = 0; k < 3; ++k) {
    a[k] = mA.mesh.vertices[tri_a[k]];
    b[k] = b_vertex(tb, k);
  }
}

namespace {
/// The pair at its closest points (at 0 where the triangles meet) if within `bound`:
/// keep(candidate), true.
template <class Keep>
bool keep_within(std::uint32_t ta, std::uint32_t tb, const geometry::ClosestPoints& closest, bool intersecting, double bound,
                 Keep&& keep) {
  const double distance = intersecting ? 0.0 : closest.distance;
  if (!(distance <= bound)) return false;
  keep(Candidate{ta, tb, distance, closest.on_a, closest.on_b});
  return true;
}

/// The leaf test after the closest points: whether the pair intersects (the exact test decides; a
/// plane between the closest points that certifiably separates the triangles says "no" without
/// it), then whether it is within `bound`; keep(candidate) where it is.
template <class Keep>
bool finish_leaf(std::uint32_t ta, std::uint32_t tb, const Eigen::Vector3d a[3], const Eigen::Vector3d b[3],
                 const geometry::ClosestPoints& closest, double bound, Keep&& keep) {
  const bool intersecting = !geometry::certainly_separated(closest.on_b - closest.on_a, a, b) &&
                            geometry::triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2]);
  return keep_within(ta, tb, closest, intersecting, bound, keep);
}

/// Whether leaf tests decide "do they meet" with triangles_intersect_batch (interference pairs
/// waiting for it, buffered closest points): where it has lanes, AVX-512 or AVX2 (pair by pair,
/// the batch would only add copies).
const bool kIntersectInBatches = geometry::detail::triangles_intersect_batch_lanes_if_supported() != nullptr;
bool intersect_in_batches() { return kIntersectInBatches; }
}  // namespace

template <class Keep>
bool PairContext::leaf_within(std::uint32_t ta, std::uint32_t tb, double bound, double reach, Keep&& keep) const {
  if (!groups_allow(ta, tb)) return false;
  Eigen::Vector3d a[3], b[3];
  corners(ta, tb, a, b);
  // A plane of one triangle with the other triangle beyond it by more than the bound (plus the
  // margin, with the rounding certified) proves the true distance exceeds it, so the full
  // computation would reject the pair too: the kernel tests that first, with its own normals.
  geometry::ClosestPoints closest;
  if (!geometry::closest_points_triangles_within(a, b, reach, closest)) return false;
  return finish_leaf(ta, tb, a, b, closest, bound, keep);
}

namespace {
/// PairContext::normals_allow's test on the two normals (na in A's frame, nb in B's), inlined into
/// the leaf tests.
[[gnu::always_inline]] inline bool normals_face(const Eigen::Vector3d& na, const Eigen::Vector3d& nb, const Eigen::Matrix3d& rot,
                                                double cos_theta) {
  // A degenerate triangle has no normal (a zero vector, adjacency.cpp) and is refused. Up to 90
  // degrees (cos(theta) > 0; 6e-17 at 90), the product's zero exceeds -cos(theta) and refuses it
  // without a test of its own.
  if (!(cos_theta > 0.0) && (na.squaredNorm() == 0.0 || nb.squaredNorm() == 0.0)) return false;
  return !(na.dot(rot * nb) > -cos_theta);
}
}  // namespace

bool PairContext::normals_allow(std::uint32_t ta, std::uint32_t tb) const {
  return mKind != QueryKind::contact || normals_face(mA.normals[ta], mB.normals[tb], mRot, mCosTheta);
}

bool PairContext::leaf_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out) const {
  if (mKind != QueryKind::interference) {
    if (mKind == QueryKind::contact && !normals_face(mA.normals[ta], mB.normals[tb], mRot, mCosTheta)) return false;
    // Proximity, contact and distance keep the pairs within the tolerance (mReach is its reach).
    return leaf_within(ta, tb, mRequest.tolerance, mReach, [&](Candidate&& c) { out.push_back(std::move(c)); });
  }
  if (!groups_allow(ta, tb)) return false;
  Eigen::Vector3d a[3], b[3];
  corners(ta, tb, a, b);
  if (!geometry::triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2])) return false;
  out.push_back(Candidate{ta, tb, 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  return true;
}

void PairContext::wait_or_test(std::uint32_t ta, std::uint32_t tb, std::vector<Candidate>& out, LeafBuffer& buffer) const {
  if (mKind == QueryKind::interference) {
    if (!intersect_in_batches()) {
      leaf_test(ta, tb, out);
      return;
    }
    // leaf_test's steps up to the exact test, which waits for the batch; the corners are read
    // when it is full (gather_corners), eight pairs' at once.
    if (groups_allow(ta, tb)) wait_to_intersect(ta, tb, out, buffer.refusal);
    return;
  }
  // leaf_within's steps up to the refusal, which waits for the batch; the corners are read when it
  // is full, as above.
  if (mKind == QueryKind::contact && !normals_face(mA.normals[ta], mB.normals[tb], mRot, mCosTheta)) return;
  if (wait_leaf(ta, tb, buffer)) refuse_buffered(buffer, out, mRequest.tolerance, mReach);
}

bool PairContext::wait_leaf(std::uint32_t ta, std::uint32_t tb, LeafBuffer& buffer) const {
  if (mGroups != nullptr && !groups_allow(ta, tb)) return false;
  BufferedPairs& waiting = buffer.refusal;
  waiting.ta[waiting.batch.size] = ta;
  waiting.tb[waiting.batch.size] = tb;
  __builtin_prefetch(&mA.mesh.triangles[ta]);
  __builtin_prefetch(&mB.mesh.triangles[tb]);
  return ++waiting.batch.size == geometry::TriangleBatch::kLanes;
}

void PairContext::refuse_buffered(LeafBuffer& buffer, std::vector<Candidate>& out, double bound, double reach) const {
  if (mKind == QueryKind::interference) {
    intersect_buffered(buffer.refusal, out);
    return;
  }
  gather_corners(buffer.refusal);
  // Within an unbounded reach (a distance query that tests every pair) nothing is apart.
  const unsigned apart = reach < kUnbounded ? geometry::triangles_apart_batch(buffer.refusal.batch, reach) : 0u;
  // The lanes not refused, in order (the lanes past the batch's pairs are dropped).
  for (unsigned bits = ~apart & ((1u << buffer.refusal.batch.size) - 1u); bits != 0; bits &= bits - 1) {
    buffer.closest.add(buffer.refusal, __builtin_ctz(bits));
    if (buffer.closest.batch.full()) finish_buffered(buffer, out, bound);
  }
  buffer.refusal.batch.size = 0;
}

void PairContext::intersect_buffered(BufferedPairs& waiting, std::vector<Candidate>& out) const {
  gather_corners(waiting);
  const unsigned meet = geometry::triangles_intersect_batch(waiting.batch);
  // The lanes that meet, in order (the lanes past the batch's pairs are dropped).
  for (unsigned bits = meet & ((1u << waiting.batch.size) - 1u); bits != 0; bits &= bits - 1) {
    const int l = __builtin_ctz(bits);
    out.push_back(Candidate{waiting.ta[l], waiting.tb[l], 0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  }
  waiting.batch.size = 0;
}

void PairContext::finish_buffered(LeafBuffer& buffer, std::vector<Candidate>& out, double bound) const {
  BufferedPairs& waiting = buffer.closest;
  geometry::ClosestPointsBatch closest;
  geometry::closest_points_triangles_batch(waiting.batch, closest);
  const auto keep = [&](Candidate&& c) { out.push_back(std::move(c)); };
  if (intersect_in_batches()) {
    // finish_leaf's verdict on whether the triangles meet, in lanes (eight AVX-512 lanes, or four
    // AVX2 lanes twice; exact, as triangles_intersect; certainly_separated only ever spares it a
    // "no").
    const unsigned meet = geometry::triangles_intersect_batch(waiting.batch);
    for (int l = 0; l < waiting.batch.size; ++l) {
      keep_within(waiting.ta[l], waiting.tb[l], closest.get(l), ((meet >> l) & 1u) != 0, bound, keep);
    }
    waiting.batch.size = 0;
    return;
  }
  for (int l = 0; l < waiting.batch.size; ++l) {
    Eigen::Vector3d a[3], b[3];
    waiting.batch.get(l, a, b);
    finish_leaf(waiting.ta[l], waiting.tb[l], a, b, closest.get(l), bound, keep);
  }
  waiting.batch.size = 0;
}

void PairContext::flush_leaves(LeafBuffer& buffer, std::vector<Candidate>& out) const {
  // An empty batch appends nothing: skipped (a traversal that reached no leaf pays nothing).
  if (buffer.refusal.batch.size != 0) refuse_buffered(buffer, out, mRequest.tolerance, mReach);
  if (buffer.closest.batch.size != 0) finish_buffered(buffer, out, mRequest.tolerance);
}

void PairContext::flush_leaves(LeafBuffer& buffer, std::vector<Candidate>& out, double bound) const {
  if (buffer.refusal.batch.size != 0) refuse_buffered(buffer, out, bound, reach_for(bound));
  if (buffer.closest.batch.size != 0) finish_buffered(buffer, out, bound);
}

double PairContext::sphere_apart(std::uint32_t ia, std::uint32_t ib) const {
  const BvhNode& na = mA.nodes[ia];
  const BvhNode& nb = mB.nodes[ib];
  double dist2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    // B's center in A's frame.
    const double cb = mRot(i, 0) * nb.center[0] + mRot(i, 1) * nb.center[1] + mRot(i, 2) * nb.center[2] + mNodeFrame.trans[i];
    dist2 += square(na.center[i] - cb);
  }
  return dist2 / std::max(square(double(na.radius) + double(nb.radius)), std::numeric_limits<double>::min());
}

bool PairContext::leaf_distance(std::uint32_t ta, std::uint32_t tb, double bound, Candidate& out) const {
  return leaf_within(ta, tb, bound, reach_for(bound), [&](Candidate&& c) { out = std::move(c); });
}

}  // namespace caliber::narrow
