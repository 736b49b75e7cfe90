#pragma once
/// \file
/// Continuous collision detection for one pair of models: the first time of contact along rigid
/// motions, by conservative advancement on the exact distance query. Never late, never a missed
/// contact: see sweep().

#include <cstdint>

#include "caliber/export.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/query.h"

namespace caliber {

/// A rigid motion over t in [0, 1], from `start` to `end`: the translation interpolated linearly,
/// the rotation by slerp on the shorter arc (the scenes' keyframe motion between two keys). The
/// object turns about its own origin.
struct SweptPose {
  Pose start;
  Pose end;
  /// The pose at time t (t in [0, 1]): translation linear, rotation by slerp. A translation
  /// component that comes out below 2^-120 in magnitude (caliber's smallest coordinate) is 0.
  [[nodiscard]] CALIBER_EXPORT Pose at(double t) const;
};

/// Options of a swept query.
struct SweepRequest {
  /// Distance delta (world units) at which the models count as touching: the sweep reports the
  /// first time it finds them within delta. 0 (default): 1e-6 of the larger model's radius about
  /// its origin. Never below twice the rounding margin (2e-9 of the scene's size, its radii and
  /// translations): a smaller one is raised to that. Must be finite and >= 0.
  double tolerance = 0.0;
  /// The most distance queries a sweep makes; one that needs more ends `undecided`. Must be >= 1.
  std::uint64_t max_queries = 100000;
  /// Which primitive groups may touch (not owned; must outlive the call), as in QueryRequest: a
  /// triangle pair whose groups may not touch is never a contact of the sweep. Null: all may.
  const GroupCompatibility* groups = nullptr;
};

/// Throws caliber::Error (bad_value) on a negative or non-finite tolerance or max_queries 0.
CALIBER_EXPORT void validate_sweep_request(const SweepRequest& request);

/// How a sweep ended.
enum class SweepStatus : std::uint8_t {
  contact,   ///< the models come within the tolerance at `time`, and do not touch before it
  free,      ///< the models do not touch on [0, 1]
  undecided  ///< max_queries ran out: the models do not touch before `time`; after it, unknown
};

/// The answer of a swept query.
struct SweepResult {
  SweepStatus status = SweepStatus::free;
  /// contact: t*, the time of the report; free: 1; undecided: how far the sweep got.
  double time = 1.0;
  /// contact: the closest triangle pair at t* (its distance <= the tolerance; 0 when the triangles
  /// intersect there), with its points at the poses of t*.
  Contact closest;
  std::uint64_t queries = 0;  ///< distance queries made
  QueryStats stats;           ///< their node and leaf tests, summed
};

/// The first time in [0, 1] at which model A moving by `a` and model B moving by `b` come within
/// the tolerance. Conservative advancement: at time t the exact distance query gives the distance
/// d(t); no point of either model moves faster than mu = |dT_a| + theta_a r_a + |dT_b| + theta_b
/// r_b (translation, slerp angle and radius about the origin of each), so the models cannot touch
/// before t + d(t) / mu, and the sweep advances to there, until d <= tolerance (contact) or past 1
/// (free). Guaranteed, with a margin of 1e-9 of the scene's size (the models' radii and the
/// translations) taken off every distance for the rounding of poses and distances: a contact is
/// never reported later than the first true contact, "free" is never wrong, and at a reported
/// contact the models are within the tolerance (as raised to twice the margin, SweepRequest::
/// tolerance). A sweep that starts within the tolerance reports
/// contact at 0. Thread-safe on shared models. Throws caliber::Error on a bad pose or request.
[[nodiscard]] CALIBER_EXPORT SweepResult sweep(const Model& a, const SweptPose& motion_a, const Model& b,
                                               const SweptPose& motion_b, const SweepRequest& request = {});

}  // namespace caliber
