#pragma once
/// \file
/// What bounds a model's motion along a SweptPose: its radius about its origin, and the margin
/// the swept query takes off its distances for rounding (caliber/sweep.h); the swept query once
/// its input is checked and its radii known, whole or a distance query at a time (SweepAdvance).

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "caliber/model.h"
#include "caliber/sweep.h"
#include "narrow/pair_context.h"

namespace caliber::narrow {

/// The largest distance from the model's origin of a vertex its triangles use (Model::extent):
/// how far a point of it can be from the axis it turns about. (A vertex no triangle uses is no
/// part of the model: it moves nothing, and a stray one far away must not inflate the speed bound,
/// the default tolerance or the swept boxes.)
inline double radius_about_origin(const Model& model) { return model.extent(); }

/// The angle (radians, in [0, pi]) of the shorter rotation from q0 to q1: what slerp turns by.
inline double turn_angle(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1) {
  const Eigen::Quaterniond d = q0.conjugate() * q1;
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

/// The margin for rounding, as a share of the scene's size (radii and translations): poses
/// interpolated and distances computed in double precision are off by a few units in the last
/// place of that size; 1e-9 of it covers them many times over.
inline constexpr double kSweepMargin = 1e-9;

/// What SweptPose::at's flush of tiny components can move the two poses of a pair, in all: each
/// by at most sqrt(3) 2^-120. Added to the margin (for any scene of a realistic size it does not
/// change the margin's bits).
inline constexpr double kSweepFlush = 2.0 * 1.7320508075688773 * kMinCoordinate;

/// A sweep's tolerance when the request gives none, as a share of the larger radius.
inline constexpr double kSweepDefaultTolerance = 1e-6;

/// The distance at which a sweep counts models as touching: the request's tolerance, or
/// kSweepDefaultTolerance of `radius` (the larger model's), and never below twice the rounding
/// margin.
inline double sweep_tolerance(const SweepRequest& request, double radius, double margin) {
  return std::max(request.tolerance > 0.0 ? request.tolerance : kSweepDefaultTolerance * radius, 2.0 * margin);
}

/// The distance request every query of a sweep makes: the closest pair, at any distance, among
/// the triangle pairs whose groups may touch (`groups`: SweepRequest::groups), without the first
/// hit (QueryRequest::first_hit: the sweep's poses are apart, but for the first).
[[nodiscard]] QueryRequest sweep_distance_request(const GroupCompatibility* groups);

/// A local advance first tries to prove this many global steps (the models' closest distance over
/// their fastest point); each time it proves all it tried, the next tries kLocalGrowth times more.
inline constexpr double kLocalReach = 64.0;
inline constexpr double kLocalGrowth = 8.0;
/// A local advance is tried only where the closest pair alone could go this many global steps
/// (a grazing pass): where it goes little further, so would the local advance, at a price.
inline constexpr double kGrazing = 8.0;

/// How a pair moves from the poses of a query on, in A's frame at that query: what local_advance
/// bounds the speed of each pair of triangles by.
struct LocalMotion {
  Eigen::Vector3d translation;  ///< B's translation less A's, per unit t, in A's frame at the query
  double turn_a = 0.0;          ///< A's turn (radians per unit t) about its origin
  double turn_b = 0.0;          ///< B's likewise
  double margin = 0.0;          ///< the sweep's margin for rounding (taken off every separation)
};

/// How far (a share of the sweep) triangles ta of A and tb of B can move by `m` from the poses of
/// `ctx` before they could come within the margin (infinity when their groups may not touch).
[[nodiscard]] double pair_advance(const PairContext& ctx, const LocalMotion& m, std::uint32_t ta, std::uint32_t tb);

/// How far (a share of the sweep, at most `cap`) the pair of `ctx` can move by `m` from the poses
/// of `ctx` before any of its triangle pairs could come within the margin: the smallest, over the
/// pairs of triangles, of their separation along the direction between their closest points over
/// the speed at which it can shrink (the translation along that direction, and each triangle's
/// turn about its model's origin); node pairs farther apart than `cap` times their fastest point
/// are left out. Never more than the time to the first contact; for two parts sliding past each
/// other, far more than their closest distance over their fastest point. After `budget` node
/// pairs, gives up: 0.
[[nodiscard]] double local_advance(const PairContext& ctx, const LocalMotion& m, double cap, std::uint64_t budget);

/// One pair's conservative advancement, a distance query at a time, on input already checked:
/// the next query is at poses pose_a() and pose_b() (time time()); take() its answer, until
/// take() says the sweep is over (result()). Whoever makes the queries (one thread, or the
/// engine's method splitting a heavy one), the same answers give the same sweep.
class SweepAdvance {
 public:
  /// ra, rb: the models' radii about their origins (radius_about_origin).
  SweepAdvance(double ra, const SweptPose& motion_a, double rb, const SweptPose& motion_b, const SweepRequest& request);
  [[nodiscard]] Pose pose_a() const { return mMotionA.at(mResult.time); }
  [[nodiscard]] Pose pose_b() const { return mMotionB.at(mResult.time); }
  /// Takes the answer of the distance query (sweep_distance_request) at pose_a() and pose_b(),
  /// made on `ctx` (a context of those poses and that request, whose local_advance it takes too);
  /// returns true when that ends the sweep.
  bool take(const QueryResult& r, const PairContext& ctx);
  /// The answer, once take() has returned true (before: free up to time(), not yet over).
  [[nodiscard]] const SweepResult& result() const { return mResult; }
  /// The node tests of the last query taken (how heavy the next one may be).
  [[nodiscard]] std::uint64_t last_node_tests() const { return mLastTests; }
  /// The closest triangle pair of the last query taken: at the next poses, its distance bounds
  /// the next query's answer from above. False before any query.
  [[nodiscard]] bool last_pair(std::uint32_t& ta, std::uint32_t& tb) const {
    ta = mLastA;
    tb = mLastB;
    return mHasLast;
  }

 private:
  SweptPose mMotionA, mMotionB;
  double mMargin, mTolerance, mSpeed;
  double mTurnA = 0.0, mTurnB = 0.0;  ///< the slerp angles of the two motions
  double mReach = kLocalReach;        ///< how many global steps the next local advance may prove
  std::uint64_t mMaxQueries;
  std::uint64_t mLastTests = 0;
  std::uint32_t mLastA = 0, mLastB = 0;  ///< the last query's closest pair, when mHasLast
  bool mHasLast = false;
  SweepResult mResult;  ///< time: the time of the next query until the sweep is over
};

/// caliber::sweep on input already checked (poses, request), with the models' radii about their
/// origins given (radius_about_origin): what a sweep of many pairs calls, each radius found once.
[[nodiscard]] SweepResult sweep_checked(const Model& a, double ra, const SweptPose& motion_a, const Model& b, double rb,
                                        const SweptPose& motion_b, const SweepRequest& request);

}  // namespace caliber::narrow
