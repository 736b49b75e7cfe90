#pragma once
/// \file
/// What bounds a model's motion along a SweptPose: its radius about its origin, and the margin
/// the swept query takes off its distances for rounding (caliber/sweep.h); the swept query once
/// its input is checked and its radii known.

#include <algorithm>
#include <cmath>

#include "caliber/model.h"
#include "caliber/sweep.h"

namespace caliber::narrow {

/// The largest distance of a vertex from the model's origin: how far a point of it can be from
/// the axis it turns about.
inline double radius_about_origin(const Model& model) {
  double r2 = 0.0;
  for (const Eigen::Vector3d& v : model.mesh().vertices) r2 = std::max(r2, v.squaredNorm());
  return std::sqrt(r2);
}

/// The margin for rounding, as a share of the scene's size (radii and translations): poses
/// interpolated and distances computed in double precision are off by a few units in the last
/// place of that size; 1e-9 of it covers them many times over.
inline constexpr double kSweepMargin = 1e-9;

/// A sweep's tolerance when the request gives none, as a share of the larger radius.
inline constexpr double kSweepDefaultTolerance = 1e-6;

/// caliber::sweep on input already checked (poses, request), with the models' radii about their
/// origins given (radius_about_origin): what a sweep of many pairs calls, each radius found once.
[[nodiscard]] SweepResult sweep_checked(const Model& a, double ra, const SweptPose& motion_a, const Model& b, double rb,
                                        const SweptPose& motion_b, const SweepRequest& request);

}  // namespace caliber::narrow
