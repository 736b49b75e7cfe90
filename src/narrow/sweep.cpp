// The swept query: conservative advancement on the exact distance query (caliber/sweep.h).

#include "caliber/sweep.h"

#include <algorithm>
#include <cmath>

#include "caliber/error.h"
#include "narrow/sweep_bounds.h"

namespace caliber {
namespace {

/// The angle (radians, in [0, pi]) of the shorter rotation from q0 to q1: what slerp turns by.
double turn_angle(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1) {
  const Eigen::Quaterniond d = q0.conjugate() * q1;
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

/// An upper bound on the speed (distance per unit t) of any point of the model along the motion.
double speed_bound(const SweptPose& m, double radius) {
  return (m.end.translation - m.start.translation).norm() + turn_angle(m.start.rotation, m.end.rotation) * radius;
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

SweepResult sweep_checked(const Model& a, double ra, const SweptPose& motion_a, const Model& b, double rb,
                          const SweptPose& motion_b, const SweepRequest& request) {
  const double size = ra + rb +
                      std::max({motion_a.start.translation.norm(), motion_a.end.translation.norm(),
                                motion_b.start.translation.norm(), motion_b.end.translation.norm()});
  const double margin = kSweepMargin * size;
  const double tolerance =
      std::max(request.tolerance > 0.0 ? request.tolerance : kSweepDefaultTolerance * std::max(ra, rb), 2.0 * margin);
  // Bounds may only be rounded up: a speed a hair too high costs a step, a hair too low a miss.
  const double mu = (speed_bound(motion_a, ra) + speed_bound(motion_b, rb)) * (1.0 + 1e-12);

  QueryRequest distance;
  distance.kind = QueryKind::distance;
  distance.tolerance = kUnbounded;
  SweepResult out;
  double t = 0.0;
  while (true) {
    const QueryResult r = query(a, motion_a.at(t), b, motion_b.at(t), distance);
    ++out.queries;
    out.stats.node_tests += r.stats.node_tests;
    out.stats.leaf_tests += r.stats.leaf_tests;
    if (r.contacts.empty()) {  // (an empty model: nothing to touch)
      out.status = SweepStatus::free;
      out.time = 1.0;
      return out;
    }
    const double d = r.contacts.front().distance;
    if (d <= tolerance) {
      out.status = SweepStatus::contact;
      out.time = t;
      out.closest = r.contacts.front();
      return out;
    }
    // No contact before t + (d - margin) / mu: every point moves at most mu per unit t.
    if (mu == 0.0 || t + (d - margin) / mu >= 1.0) {
      out.status = SweepStatus::free;
      out.time = 1.0;
      return out;
    }
    if (out.queries >= request.max_queries) {
      out.status = SweepStatus::undecided;
      out.time = t + (d - margin) / mu;
      return out;
    }
    t += (d - margin) / mu;
  }
}

}  // namespace narrow

}  // namespace caliber
