#pragma once
/// \file
/// Rigid poses: rotation (unit quaternion) followed by translation.

#include "caliber/export.h"
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace caliber {

/// A rigid transform x_world = rotation * x_object + translation. The rotation is a unit quaternion.
struct Pose {
  /// Unit quaternion (w, x, y, z).
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  /// Translation (world units).
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  /// Builds a pose from a translation and a quaternion (w, x, y, z).
  /// Throws caliber::Error (bad_value) if a value is not finite or the quaternion is (nearly) zero;
  /// otherwise the quaternion is normalized. `source` names the input in the message.
  CALIBER_EXPORT static Pose from_values(double tx, double ty, double tz, double qw, double qx, double qy, double qz,
                          std::string_view source = "pose");

  /// The rotation as a matrix.
  [[nodiscard]] Eigen::Matrix3d rotation_matrix() const { return rotation.toRotationMatrix(); }
  /// Applies the pose to a point.
  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return rotation * p + translation; }
};

/// The unit quaternion of (w, x, y, z), scaled by its largest component before it is squared, so
/// that neither a huge nor a tiny quaternion overflows or underflows into the wrong rotation
/// ([1e200, 0, 0, 1e200] is [1, 0, 0, 1]). Throws caliber::Error (bad_value) naming `source` when a
/// value is not finite or the quaternion is (nearly) zero: no component above 1e-9. The one
/// normalization of the CLI and scene files.
[[nodiscard]] CALIBER_EXPORT Eigen::Quaterniond unit_quaternion(double w, double x, double y, double z, std::string_view source = "quaternion");

/// Parses "tx ty tz qw qx qy qz" (spaces or commas). Throws caliber::Error naming `source`
/// when the text does not hold exactly seven finite numbers or the quaternion is zero.
[[nodiscard]] CALIBER_EXPORT Pose parse_pose(std::string_view text, std::string_view source = "pose");

/// Throws caliber::Error if the pose has a non-finite value or a quaternion that is not unit length
/// (within 1e-9); used on poses built by hand rather than through from_values/parse_pose.
CALIBER_EXPORT void validate_pose(const Pose& pose, std::string_view source = "pose");

}  // namespace caliber
