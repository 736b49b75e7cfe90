#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "caliber/batch.h"
#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/pose.h"

namespace caliber {
namespace {

/// A translation's components must be 0 or of magnitude in [kMinCoordinate, kMaxCoordinate].
void check_translation(const Eigen::Vector3d& t, std::string_view source) {
  for (int c = 0; c < 3; ++c) {
    const double x = std::abs(t[c]);
    if (x > kMaxCoordinate) {
      throw Error(ErrorCode::bad_value, std::string(source), "translation beyond +-1e15 (caliber's limit on coordinates)");
    }
    if (x != 0.0 && x < kMinCoordinate) {
      throw Error(
          ErrorCode::bad_value, std::string(source),
          "translation component below 2^-120 (about 7.5e-37), the smallest non-zero value caliber's exact predicates take");
    }
  }
}

}  // namespace

Eigen::Quaterniond unit_quaternion(double w, double x, double y, double z, std::string_view source) {
  for (const double v : {w, x, y, z}) {
    if (!std::isfinite(v)) throw Error(ErrorCode::bad_value, std::string(source), "quaternion has a non-finite value");
  }
  const double largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  // (Nearly) zero: no rotation is meant, or the numbers are noise. Refused, like exactly zero.
  if (!(largest > 1e-9)) {
    throw Error(ErrorCode::bad_value, std::string(source), "quaternion is (nearly) zero; a rotation needs a non-zero quaternion");
  }
  w /= largest, x /= largest, y /= largest, z /= largest;
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);  // in [1, 2]
  return Eigen::Quaterniond(w / norm, x / norm, y / norm, z / norm);
}

Pose Pose::from_values(double tx, double ty, double tz, double qw, double qx, double qy, double qz, std::string_view source) {
  const double values[7] = {tx, ty, tz, qw, qx, qy, qz};
  for (const double v : values) {
    if (!std::isfinite(v)) throw Error(ErrorCode::bad_value, std::string(source), "pose has a non-finite value");
  }
  check_translation(Eigen::Vector3d(tx, ty, tz), source);
  Pose pose;
  pose.rotation = unit_quaternion(qw, qx, qy, qz, source);
  pose.translation = Eigen::Vector3d(tx, ty, tz);
  return pose;
}

Pose Pose::from_matrix(const Eigen::Matrix4d& matrix, double tolerance, std::string_view source) {
  if (!(tolerance >= 0.0) || !(tolerance < 0.5)) {
    throw Error(ErrorCode::bad_value, std::string(source), "the rotation's tolerance must be in [0, 0.5)");
  }
  if (!matrix.allFinite()) throw Error(ErrorCode::bad_value, std::string(source), "has a value that is not finite");
  const Eigen::Matrix3d r = matrix.topLeftCorner<3, 3>();
  const double off = (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = r.determinant();
  if (off > tolerance || std::abs(det - 1.0) > tolerance || matrix(3, 0) != 0.0 || matrix(3, 1) != 0.0 || matrix(3, 2) != 0.0 ||
      matrix(3, 3) != 1.0) {
    char problem[200];
    std::snprintf(problem, sizeof problem,
                  "is not a rigid transform within %g (|R R^T - I| = %.3g, det R = %.17g; last row must be 0 0 0 1)", tolerance,
                  off, det);
    throw Error(ErrorCode::bad_value, std::string(source), problem);
  }
  const Eigen::Quaterniond q(r);
  return from_values(matrix(0, 3), matrix(1, 3), matrix(2, 3), q.w(), q.x(), q.y(), q.z(), source);
}

Pose Pose::from_isometry(const Eigen::Isometry3d& isometry, double tolerance, std::string_view source) {
  return from_matrix(isometry.matrix(), tolerance, source);
}

Pose parse_pose(std::string_view text, std::string_view source) {
  std::vector<double> values;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == ' ' || c == ',' || c == '\t' || c == '\n') {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < text.size() && text[end] != ' ' && text[end] != ',' && text[end] != '\t' && text[end] != '\n') ++end;
    const std::string_view token = text.substr(i, end - i);
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size()) {
      throw Error(ErrorCode::bad_value, std::string(source),
                  "'" + std::string(token) + "' is not a number (expected \"tx ty tz qw qx qy qz\")");
    }
    values.push_back(value);
    i = end;
  }
  if (values.size() != 7) {
    throw Error(ErrorCode::bad_value, std::string(source),
                "expected 7 numbers \"tx ty tz qw qx qy qz\", got " + std::to_string(values.size()));
  }
  return Pose::from_values(values[0], values[1], values[2], values[3], values[4], values[5], values[6], source);
}

void validate_pose(const Pose& pose, std::string_view source) {
  if (!pose.translation.allFinite() || !pose.rotation.coeffs().allFinite()) {
    throw Error(ErrorCode::bad_value, std::string(source), "pose has a non-finite value");
  }
  check_translation(pose.translation, source);
  if (std::abs(pose.rotation.norm() - 1.0) > 1e-9) {
    throw Error(ErrorCode::bad_value, std::string(source), "quaternion is not unit length");
  }
}

namespace {

/// Converts each of `count` rows with `make(row, source)`; the first row that throws is converted
/// again with its own name, `source`[i], so that the message names it (no name is made otherwise).
template <class Make>
std::vector<Pose> poses_from_rows(std::size_t values, std::size_t width, std::string_view source, Make&& make) {
  if (values % width != 0) {
    throw Error(ErrorCode::bad_argument, std::string(source),
                std::to_string(values) + " values are not a whole number of poses of " + std::to_string(width));
  }
  std::vector<Pose> poses(values / width);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    try {
      poses[i] = make(i, std::string_view());
    } catch (const Error&) {
      poses[i] = make(i, std::string(source) + "[" + std::to_string(i) + "]");  // throws again, naming the row
    }
  }
  return poses;
}

}  // namespace

std::vector<Pose> poses_from_matrices(std::span<const double> values, double tolerance, std::string_view source) {
  if (!(tolerance >= 0.0) || !(tolerance < 0.5)) {
    throw Error(ErrorCode::bad_value, "tolerance", "the rotation's tolerance must be in [0, 0.5)");
  }
  return poses_from_rows(values.size(), 16, source, [&](std::size_t i, std::string_view name) {
    return Pose::from_matrix(Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data() + 16 * i), tolerance,
                             name);
  });
}

std::vector<Pose> poses_from_vectors(std::span<const double> values, QuaternionOrder order, std::string_view source) {
  return poses_from_rows(values.size(), 7, source, [&](std::size_t i, std::string_view name) {
    const double* v = values.data() + 7 * i;
    return order == QuaternionOrder::wxyz ? Pose::from_values(v[0], v[1], v[2], v[3], v[4], v[5], v[6], name)
                                          : Pose::from_values(v[0], v[1], v[2], v[6], v[3], v[4], v[5], name);
  });
}

}  // namespace caliber
