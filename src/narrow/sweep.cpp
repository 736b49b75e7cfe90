// The swept query: conservative advancement on the exact distance query (caliber/sweep.h).

#include "caliber/sweep.h"

#include <algorithm>
#include <cmath>

#include "caliber/error.h"
#include "narrow/finalize.h"
#include "narrow/pair_context.h"
#include "narrow/sweep_bounds.h"

namespace caliber {
namespace {

/// An upper bound on the speed (distance per unit t) of any point of the model along the motion.
double speed_bound(const SweptPose& m, double radius) {
  return (m.end.translation - m.start.translation).norm() + narrow::turn_angle(m.start.rotation, m.end.rotation) * radius;
}

}  // namespace

void validate_sweep_request(const SweepRequest& request) {
  if (!std::isfinite(request.tolerance) || request.tolerance < 0.0) {
    throw Error(ErrorCode::bad_value, "sweep", "tolerance must be finite and >= 0");
  }
  if (request.max_queries < 1) throw Error(ErrorCode::bad_value, "sweep", "max_queries must be >= 1");
}

Pose SweptPose::at(double t) const {
  Pose p;
  p.translation = (1.0 - t) * start.translation + t * end.translation;
  // An interpolated component below the smallest non-zero coordinate caliber takes (validate_pose)
  // is 0: a move of at most sqrt(3) 2^-120, which the sweep's margin covers (kSweepFlush).
  for (int k = 0; k < 3; ++k) {
    if (p.translation[k] != 0.0 && std::abs(p.translation[k]) < kMinCoordinate) p.translation[k] = 0.0;
  }
  p.rotation = start.rotation.slerp(t, end.rotation).normalized();
  return p;
}

SweepResult sweep(const Model& a, const SweptPose& motion_a, const Model& b, const SweptPose& motion_b,
                  const SweepRequest& request) {
  validate_pose(motion_a.start, "sweep: start pose of A");
  validate_pose(motion_a.end, "sweep: end pose of A");
  validate_pose(motion_b.start, "sweep: start pose of B");
  validate_pose(motion_b.end, "sweep: end pose of B");
  validate_sweep_request(request);
  return narrow::sweep_checked(a, narrow::radius_about_origin(a), motion_a, b, narrow::radius_about_origin(b), motion_b, request);
}

namespace narrow {

QueryRequest sweep_distance_request(const GroupCompatibility* groups) {
  QueryRequest distance;
  distance.groups = groups;
  distance.kind = QueryKind::distance;
  distance.tolerance = kUnbounded;
  distance.first_hit = false;  // its poses are apart (the first one aside): the first hit would find nothing
  return distance;
}

SweepAdvance::SweepAdvance(double ra, const SweptPose& motion_a, double rb, const SweptPose& motion_b,
                           const SweepRequest& request)
    : mMotionA(motion_a), mMotionB(motion_b), mMaxQueries(request.max_queries) {
  const double size = ra + rb +
                      std::max({motion_a.start.translation.norm(), motion_a.end.translation.norm(),
                                motion_b.start.translation.norm(), motion_b.end.translation.norm()});
  mMargin = kSweepMargin * size + kSweepFlush;
  mTolerance = sweep_tolerance(request, std::max(ra, rb), mMargin);
  // Bounds may only be rounded up: a speed a hair too high costs a step, a hair too low a miss.
  mSpeed = (speed_bound(motion_a, ra) + speed_bound(motion_b, rb)) * (1.0 + 1e-12);
  mTurnA = turn_angle(motion_a.start.rotation, motion_a.end.rotation) * (1.0 + 1e-12);
  mTurnB = turn_angle(motion_b.start.rotation, motion_b.end.rotation) * (1.0 + 1e-12);
  mResult.time = 0.0;
}

bool SweepAdvance::take(const QueryResult& r, const PairContext& ctx) {
  const double t = mResult.time;
  ++mResult.queries;
  mLastTests = r.stats.node_tests;
  mResult.stats.node_tests += r.stats.node_tests;
  mResult.stats.leaf_tests += r.stats.leaf_tests;
  mHasLast = !r.contacts.empty();
  if (!mHasLast) {  // (an empty model: nothing to touch)
    mResult.status = SweepStatus::free;
    mResult.time = 1.0;
    return true;
  }
  mLastA = r.contacts.front().tri_a;
  mLastB = r.contacts.front().tri_b;
  const double d = r.contacts.front().distance;
  if (d <= mTolerance) {
    mResult.status = SweepStatus::contact;
    mResult.closest = r.contacts.front();
    return true;
  }
  // No contact before t + (d - margin) / mu: every point moves at most mu per unit t. Nor before
  // the local advance, pair of triangles by pair (what lets parts slide past each other).
  double step = mSpeed == 0.0 ? 1.0 : (d - mMargin) / mSpeed;
  if (t + step < 1.0) {
    LocalMotion m;
    m.translation = ctx.pose_a().rotation.conjugate() * ((mMotionB.end.translation - mMotionB.start.translation) -
                                                         (mMotionA.end.translation - mMotionA.start.translation));
    m.turn_a = mTurnA;
    m.turn_b = mTurnB;
    m.margin = mMargin;
    // The closest pair's own advance bounds the local one from above: only where it goes further
    // than the global step (a grazing pass) is there something to gain from the traversal.
    const double closest = pair_advance(ctx, m, mLastA, mLastB);
    if (closest > kGrazing * step) {
      // At most mReach global steps, and no more node pairs than half the query's node tests:
      // a pass that only grazes gains much for little, one that closes in is left to the query.
      const double cap = std::min({1.0 - t, closest, mReach * step});
      const double local = local_advance(ctx, m, cap, r.stats.node_tests / 2 + 64);
      mReach = local >= cap ? std::min(mReach * kLocalGrowth, 1e15) : kLocalReach;
      step = std::max(step, local);
    }
  }
  if (t + step >= 1.0) {
    mResult.status = SweepStatus::free;
    mResult.time = 1.0;
    return true;
  }
  mResult.time = t + step;
  if (mResult.queries >= mMaxQueries) {
    mResult.status = SweepStatus::undecided;
    return true;
  }
  return false;
}

SweepResult sweep_checked(const Model& a, double ra, const SweptPose& motion_a, const Model& b, double rb,
                          const SweptPose& motion_b, const SweepRequest& request) {
  const QueryRequest distance = sweep_distance_request(request.groups);
  SweepAdvance advance(ra, motion_a, rb, motion_b, request);
  for (bool done = false; !done;) {
    const PairContext ctx(a, advance.pose_a(), b, advance.pose_b(), distance);
    done = advance.take(query_whole(ctx), ctx);
  }
  return advance.result();
}

}  // namespace narrow

}  // namespace caliber
