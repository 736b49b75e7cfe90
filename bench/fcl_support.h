#pragma once
// What the FCL comparisons share: FCL models of caliber's meshes, poses in FCL's form, a mesh's
// box, and median timing.

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <fcl/geometry/bvh/BVH_model.h>

#include "caliber/mesh.h"
#include "caliber/pose.h"

namespace caliber::bench {

using FclModel = fcl::BVHModel<fcl::OBBRSSd>;

/// Where the benches look for the CGAL meshes without --meshes: data/meshes under the working
/// directory where there is one (a device pack, a checkout's root), else the source tree's
/// (CALIBER_BENCH_MESHES: the benches run from build/ too).
inline std::filesystem::path default_meshes_dir() {
  const std::filesystem::path here = "data/meshes";
#ifdef CALIBER_BENCH_MESHES
  if (!std::filesystem::is_directory(here)) return CALIBER_BENCH_MESHES;
#endif
  return here;
}

/// Median wall time of `repeat` runs of f, in milliseconds.
inline double median_ms(int repeat, const std::function<void()>& f) {
  std::vector<double> times;
  for (int i = 0; i < repeat; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

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

/// The axis-aligned box of a mesh's vertices: its low and high corners.
inline void box(const Mesh& m, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = m.vertices[0];
  hi = lo;
  for (const auto& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

/// The center and diagonal of a mesh's box.
inline void box_center(const Mesh& m, Eigen::Vector3d& center, double& diagonal) {
  Eigen::Vector3d lo, hi;
  box(m, lo, hi);
  center = 0.5 * (lo + hi);
  diagonal = (hi - lo).norm();
}

}  // namespace caliber::bench
