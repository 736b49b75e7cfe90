#pragma once
// What the viewer and the exports draw of a step: each contact as a point and a normal (world
// frame), posed vertices, and the boxes of a BVH. Shared by `caliber view` and `caliber run --export`.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "caliber/engine.h"
#include "caliber/model.h"
#include "caliber/pose.h"
#include "caliber/world.h"

namespace caliber::cli {

/// One contact as drawn: contact and proximity queries give A's closest point and the normal from
/// A to B; interference gives no points, so it is drawn at the centroid of A's triangle with A's
/// face normal (both in the world frame).
struct ShownContact {
  std::uint32_t object_a = 0;
  std::uint32_t object_b = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

/// The step's contacts as drawn, in the step's contact order.
[[nodiscard]] std::vector<ShownContact> shown_contacts(const World& world, const StepResult& step,
                                                       const std::vector<Pose>& poses);

/// An oriented box: a BVH node's box in its object's frame, posed.
struct ShownBox {
  Eigen::Vector3d center;
  Eigen::Vector3d half;  ///< half-extents along the axes
  Eigen::Matrix3d axes;  ///< columns: the box's axes in the world frame
};

/// The box of node `node` of `model`, posed.
[[nodiscard]] ShownBox node_box(const Model& model, std::uint32_t node, const Pose& pose);

/// The nodes of `model` down to `depth` (the root is depth 0), level by level, each with its depth.
[[nodiscard]] std::vector<std::pair<std::uint32_t, int>> nodes_to_depth(const Model& model, int depth);

/// The 8 corners of a box: corner i has +half along axis k when bit k of i is set.
[[nodiscard]] std::vector<Eigen::Vector3d> box_corners(const ShownBox& box);

/// The 12 edges of a box as pairs of corner indices (box_corners' numbering).
inline constexpr int kBoxEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                         {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

}  // namespace caliber::cli
