#pragma once
// Where a model's node volumes are measured from (ModelData::origin), and the sizes about it.

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

#include "caliber/mesh.h"

namespace caliber::bvh {

/// The center of the box of the vertices the triangles use when it lies farther from the origin
/// than the box's largest side (a part in its assembly's frame), else zero: a mesh about its origin
/// keeps its volumes as they are.
inline Eigen::Vector3d volume_origin(const Mesh& mesh) {
  if (mesh.triangles.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = mesh.vertices[mesh.triangles[0][0]], hi = lo;
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) {
      lo = lo.cwiseMin(mesh.vertices[v]);
      hi = hi.cwiseMax(mesh.vertices[v]);
    }
  }
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  return center.cwiseAbs().maxCoeff() > (hi - lo).maxCoeff() ? center : Eigen::Vector3d::Zero();
}

/// The mesh's triangles and groups, its vertices moved by `by` (what the build reads).
inline Mesh moved_by(const Mesh& mesh, const Eigen::Vector3d& by) {
  Mesh out;
  out.vertices.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices) out.vertices.push_back(v + by);
  out.triangles = mesh.triangles;
  out.groups = mesh.groups;
  return out;
}

/// The largest distance from `from` of a vertex the triangles use (sqrt is monotone and correctly
/// rounded: the largest of the norms).
inline double largest_norm(const Mesh& mesh, const Eigen::Vector3d& from) {
  double r2 = 0.0;
  for (const auto& tri : mesh.triangles) {
    for (const std::uint32_t v : tri) r2 = std::max(r2, (mesh.vertices[v] - from).squaredNorm());
  }
  return std::sqrt(r2);
}

}  // namespace caliber::bvh
