#pragma once
// What the FCL comparisons share: FCL models of caliber's meshes and poses in FCL's form, with
// bench_support.h (the meshes' directory, a mesh's box, median timing).

#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <fcl/geometry/bvh/BVH_model.h>

#include "caliber/mesh.h"
#include "caliber/pose.h"
#include "bench_support.h"

namespace caliber::bench {

using FclModel = fcl::BVHModel<fcl::OBBRSSd>;

/// FCL's OBBRSS hierarchy of a mesh (FCL's default split).
inline std::shared_ptr<FclModel> build_fcl(const Mesh& mesh) {
  auto model = std::make_shared<FclModel>();
  std::vector<fcl::Vector3d> vertices(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(vertices.size()));
  model->addSubModel(vertices, triangles);
  model->endModel();
  return model;
}

inline fcl::Transform3d to_fcl(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation_matrix();
  tf.translation() = pose.translation;
  return tf;
}

}  // namespace caliber::bench
