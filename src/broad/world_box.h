#pragma once
// The world-space box of an object, as the broad phase compares them.

#include <Eigen/Core>

#include "bvh/model_data.h"
#include "caliber/model.h"
#include "caliber/pose.h"

namespace caliber::broad {

/// A world-space box of an object: its root box moved by its pose (conservative: |R| h).
struct WorldBox {
  Eigen::Vector3d lo, hi;
};

/// The box of model m at `pose`, grown by `grow` and by a margin for the rounding of the move, so
/// that rounding never drops a pair (the same kind of safety margin as the narrow phase's).
inline WorldBox world_box(const Model& model, const Pose& pose, double grow) {
  const ModelData& m = data(model);
  const BvhNode& root = m.nodes[0];
  const Eigen::Vector3d c = m.origin + Eigen::Vector3d(root.box_center[0], root.box_center[1], root.box_center[2]);
  const Eigen::Vector3d h(root.box_half[0], root.box_half[1], root.box_half[2]);
  const Eigen::Matrix3d r = pose.rotation_matrix();
  const Eigen::Vector3d center = r * c + pose.translation;
  const Eigen::Vector3d half = r.cwiseAbs() * h;
  const double margin = grow + 1e-9 * (m.extent + pose.translation.norm() + grow);
  return {center - half - Eigen::Vector3d::Constant(margin), center + half + Eigen::Vector3d::Constant(margin)};
}

}  // namespace caliber::broad
