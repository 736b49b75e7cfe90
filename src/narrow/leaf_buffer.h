#pragma once
/// \file
/// Leaf tests waiting for the batch kernels: the pairs of one traversal that passed the leaf
/// test's first checks wait for the refusal test (geometry::triangles_apart_batch), those it does
/// not refuse for their closest points (geometry::closest_points_triangles_batch), eight at a time
/// (PairContext::leaf_test with a buffer, PairContext::flush_leaves). Pairs wait in `refusal` as
/// ids alone, their corners read when the batch is full (PairContext::gather_corners), for
/// geometry::triangles_intersect_batch (interference) or the refusal test.

#include <cstdint>

#include "bvh/model_data.h"
#include "geometry/rigid_move.h"
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

namespace detail {
/// A form of PairContext::gather_corners: reads the corners of the `waiting.batch.size` pairs
/// waiting (their ids) into the batch's lanes, the lanes past them as lane 0, B's moved into A's
/// frame by `move` with geometry::rigid_move_row's operations (the same bits in every form).
using GatherCorners = void (*)(const ModelData& a, const ModelData& b, const geometry::RigidMove& move, BufferedPairs& waiting);
/// The portable form (SSE2 where the build has it).
void gather_corners_portable(const ModelData& a, const ModelData& b, const geometry::RigidMove& move, BufferedPairs& waiting);
/// The AVX2 form (four lanes at a time, the corners transposed in registers), or nullptr where the
/// CPU (or this build) has no AVX2.
GatherCorners gather_corners_avx2_if_supported();

/// Where the corners of a batch's lanes lie: vertex k of lane l's triangles at a[k][l], b[k][l]
/// (three doubles each).
struct CornerPointers {
  const double* a[3][geometry::TriangleBatch::kLanes];
  const double* b[3][geometry::TriangleBatch::kLanes];
};

/// The corners of every lane of `waiting` (the lanes past its batch.size pairs as lane 0, as
/// TriangleBatch::pad fills them; it holds at least one pair), asked of memory for every pair
/// before any is read (the triangles' corner ids first, then their corners): the misses overlap
/// rather than follow one another. (It writes `out`: a function that only prefetched would be
/// found free of effects, and its calls dropped.)
inline void corners_prefetched(const ModelData& a, const ModelData& b, const BufferedPairs& waiting, CornerPointers& out) {
  const int n = waiting.batch.size;
  for (int l = 0; l < n; ++l) {
    __builtin_prefetch(&a.mesh.triangles[waiting.ta[l]]);
    __builtin_prefetch(&b.mesh.triangles[waiting.tb[l]]);
  }
  for (int l = 0; l < geometry::TriangleBatch::kLanes; ++l) {
    for (int k = 0; k < 3; ++k) {
      if (l < n) {
        out.a[k][l] = a.mesh.vertices[a.mesh.triangles[waiting.ta[l]][k]].data();
        out.b[k][l] = b.mesh.vertices[b.mesh.triangles[waiting.tb[l]][k]].data();
        __builtin_prefetch(out.a[k][l]);
        __builtin_prefetch(out.b[k][l]);
      } else {
        out.a[k][l] = out.a[k][0];
        out.b[k][l] = out.b[k][0];
      }
    }
  }
}
}  // namespace detail

}  // namespace caliber::narrow
