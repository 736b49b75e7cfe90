#pragma once
/// \file
/// Rigid poses: rotation (unit quaternion) followed by translation.

#include "caliber/export.h"
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace caliber {

/// A rigid transform x_world = rotation * x_object + translation. The rotation is a unit quaternion
/// stored as Eigen's (w, x, y, z); scipy and ROS write quaternions (x, y, z, w): build from those
/// with from_values(tx, ty, tz, q[3], q[0], q[1], q[2]), or from a matrix.
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

  /// Builds a pose from a 4 x 4 rigid transform [R t; 0 0 0 1]: R must be a rotation within
  /// `tolerance` (|R R^T - I| and |det R - 1| at most that; 1e-9 suits doubles, 1e-6 a matrix
  /// that went through floats), and is then made exactly orthonormal (through its quaternion).
  /// Throws caliber::Error (bad_value) naming `source` otherwise, or on a non-finite value.
  CALIBER_EXPORT static Pose from_matrix(const Eigen::Matrix4d& matrix, double tolerance = 1e-9,
                                         std::string_view source = "matrix");
  /// Builds a pose from an Eigen isometry (its linear part must be a rotation within `tolerance`,
  /// as from_matrix).
  CALIBER_EXPORT static Pose from_isometry(const Eigen::Isometry3d& isometry, double tolerance = 1e-9,
                                           std::string_view source = "isometry");
  /// The pose as a 4 x 4 matrix [R t; 0 0 0 1].
  [[nodiscard]] Eigen::Matrix4d matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation_matrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
  }

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
[[nodiscard]] CALIBER_EXPORT Eigen::Quaterniond unit_quaternion(double w, double x, double y, double z,
                                                                std::string_view source = "quaternion");

/// Parses "tx ty tz qw qx qy qz" (spaces or commas). Throws caliber::Error naming `source`
/// when the text does not hold exactly seven finite numbers or the quaternion is zero.
[[nodiscard]] CALIBER_EXPORT Pose parse_pose(std::string_view text, std::string_view source = "pose");

/// Throws caliber::Error if the pose has a non-finite value or a quaternion that is not unit length
/// (within 1e-9); used on poses built by hand rather than through from_values/parse_pose.
CALIBER_EXPORT void validate_pose(const Pose& pose, std::string_view source = "pose");

}  // namespace caliber
