#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/pose.h"

namespace caliber {

Pose Pose::from_values(double tx, double ty, double tz, double qw, double qx, double qy, double qz,
                       std::string_view source) {
  const double values[7] = {tx, ty, tz, qw, qx, qy, qz};
  for (const double v : values) {
    if (!std::isfinite(v)) throw Error(ErrorCode::bad_value, std::string(source), "pose has a non-finite value");
  }
  for (const double v : {tx, ty, tz}) {
    if (std::abs(v) > kMaxCoordinate) {
      throw Error(ErrorCode::bad_value, std::string(source), "translation beyond +-1e15 (caliber's limit on coordinates)");
    }
  }
  // Scaled before squaring, so that a huge quaternion does not overflow into a zero rotation.
  const double largest = std::max({std::abs(qw), std::abs(qx), std::abs(qy), std::abs(qz)});
  if (largest > 0.0) {
    qw /= largest, qx /= largest, qy /= largest, qz /= largest;
  }
  const double unit_norm = std::sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
  const double norm = largest * unit_norm;
  if (!(norm > 1e-9)) {
    throw Error(ErrorCode::bad_value, std::string(source), "quaternion is zero; a rotation needs a non-zero quaternion");
  }
  Pose pose;
  pose.rotation = Eigen::Quaterniond(qw / unit_norm, qx / unit_norm, qy / unit_norm, qz / unit_norm);
  pose.translation = Eigen::Vector3d(tx, ty, tz);
  return pose;
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
  if (pose.translation.cwiseAbs().maxCoeff() > kMaxCoordinate) {
    throw Error(ErrorCode::bad_value, std::string(source), "translation beyond +-1e15 (caliber's limit on coordinates)");
  }
  if (std::abs(pose.rotation.norm() - 1.0) > 1e-9) {
    throw Error(ErrorCode::bad_value, std::string(source), "quaternion is not unit length");
  }
}

}  // namespace caliber
