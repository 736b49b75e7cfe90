#pragma once
/// \file
/// Leaf tests waiting for the batch kernels: the pairs of one traversal that passed the leaf
/// test's first checks wait for the refusal test (geometry::triangles_apart_batch), those it does
/// not refuse for their closest points (geometry::closest_points_triangles_batch), eight at a time
/// (PairContext::leaf_test with a buffer, PairContext::flush_leaves). Pairs wait in `refusal` as
/// ids alone, their corners read when the batch is full (PairContext::gather_corners), for
/// geometry::triangles_intersect_batch (interference) or the refusal test.

#include <cstdint>

#include "geometry/triangle_distance.h"

namespace caliber::narrow {

/// Triangle pairs with their ids, in the order they came.
struct BufferedPairs {
  geometry::TriangleBatch batch;                      ///< the corners (B's in A's frame)
  std::uint32_t ta[geometry::TriangleBatch::kLanes];  ///< the triangles of A
  std::uint32_t tb[geometry::TriangleBatch::kLanes];  ///< the triangles of B

  /// Appends pair `lane` of `from`.
  void add(const BufferedPairs& from, int lane) {
    ta[batch.size] = from.ta[lane];
    tb[batch.size] = from.tb[lane];
    batch.add(from.batch, lane);
  }
};

/// One traversal's leaf pairs on their way through the batch kernels.
struct LeafBuffer {
  BufferedPairs refusal;  ///< waiting for the refusal test
  BufferedPairs closest;  ///< not refused, waiting for their closest points
};

}  // namespace caliber::narrow
