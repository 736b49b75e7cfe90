#pragma once
/// \file
/// BvhNode::shape of every leaf: where its triangle's corners lie in its box (leaf_corners decodes
/// them), set once the nodes are made.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "bvh/model_data.h"
#include "caliber/mesh.h"
#include "parallel/executor.h"
#include "util/assert.h"

namespace caliber::bvh {

/// The float bounds of node n's box along axis i, in double (exact: the sums of two floats).
inline void box_range(const BvhNode& n, int i, double& lo, double& hi) {
  lo = static_cast<double>(n.box_center[i]) - static_cast<double>(n.box_half[i]);
  hi = static_cast<double>(n.box_center[i]) + static_cast<double>(n.box_half[i]);
}

/// The shape of leaf n, whose triangle's corners (relative to the model's origin, as the box was
/// built around them) are p[0..2]: per axis, the first lowest and the last highest corner (two
/// distinct ones, 0 and 2 where all three are equal), and the third's place on the box's range.
inline std::uint64_t leaf_shape(const BvhNode& n, const Eigen::Vector3d p[3]) {
  std::uint64_t shape = 0;
  for (int i = 0; i < 3; ++i) {
    int low = 0, high = 0;
    for (int j = 1; j < 3; ++j) {
      if (p[j][i] < p[low][i]) low = j;
      if (p[j][i] >= p[high][i]) high = j;
    }
    double lo, hi;
    box_range(n, i, lo, hi);
    const double place = hi > lo ? (p[3 - low - high][i] - lo) / (hi - lo) * 65535.0 : 0.0;
    // The nearest step (the middle corner lies in the box: place is within [0, 65535]).
    const auto q = static_cast<std::uint64_t>(std::clamp(place, 0.0, 65535.0) + 0.5);
    shape |= q << (16 * i) | static_cast<std::uint64_t>(low) << (48 + 4 * i) | static_cast<std::uint64_t>(high) << (50 + 4 * i);
  }
  return shape;
}

/// The corners of leaf n's triangle (relative to its model's origin, as its box is) decoded from
/// n.shape and its box: corner[j][i], coordinate i of corner j, in the triangle's order. Along
/// each axis the extreme corners are the box's float bounds, off the true ones by the box's own
/// rounding (a few float roundoffs of the box's distance from the origin), and the middle one is
/// rounded to 1/65535 of the box's range: `error`, 2^-16 of the box's largest range, is about
/// twice that rounding's bound.
inline void leaf_corners(const BvhNode& n, double corner[3][3], double& error) {
  error = 0.0;
  for (int i = 0; i < 3; ++i) {
    double lo, hi;
    box_range(n, i, lo, hi);
    const auto low = static_cast<int>(n.shape >> (48 + 4 * i) & 3u), high = static_cast<int>(n.shape >> (50 + 4 * i) & 3u);
    CALIBER_ASSERT(low != high && low < 3 && high < 3, "a leaf's shape names two of its corners on each axis");
    const double q = static_cast<double>(n.shape >> (16 * i) & 0xFFFFu);
    corner[low][i] = lo;
    corner[high][i] = hi;
    corner[3 - low - high][i] = lo + (hi - lo) * (q * (1.0 / 65535.0));
    error = std::max(error, (hi - lo) * 0x1p-16);
  }
}

/// Sets the shape of every leaf of `model` (its nodes made) from `local`, the mesh its volumes
/// were built around (moved by -origin); `grain` nodes at a time, in parallel on the caller's
/// executor.
inline void fill_leaf_shapes(const Mesh& local, ModelData& model, std::size_t grain) {
  parallel::parallel_for(0, model.nodes.size(), grain, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i != hi; ++i) {
      BvhNode& n = model.nodes[i];
      if (!n.is_leaf()) continue;
      const auto& t = local.triangles[n.triangle()];
      const Eigen::Vector3d p[3] = {local.vertices[t[0]], local.vertices[t[1]], local.vertices[t[2]]};
      n.shape = leaf_shape(n, p);
    }
  });
}

}  // namespace caliber::bvh
