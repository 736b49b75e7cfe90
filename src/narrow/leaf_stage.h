#pragma once
/// \file
/// Leaf tests waiting for their closest points: the pairs of one traversal that passed the leaf
/// test's cheap refusals, computed eight at a time by geometry::closest_points_triangles_batch
/// (PairContext::leaf_test with a stage, PairContext::flush_leaves).

#include <cstdint>

#include "geometry/triangle_distance.h"

namespace caliber::narrow {

struct LeafStage {
  geometry::TriangleBatch batch;  ///< the waiting pairs' corners (B's in A's frame)
  std::uint32_t ta[geometry::TriangleBatch::kLanes];  ///< their triangles of A
  std::uint32_t tb[geometry::TriangleBatch::kLanes];  ///< their triangles of B
};

}  // namespace caliber::narrow
