// PairContext::gather_corners: a leaf batch's corners read straight into its lanes, B's moved into
// A's frame there.

#include "narrow/pair_context.h"

#include <Eigen/Core>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "geometry/rigid_move.h"
#include "geometry/triangle_distance.h"

namespace caliber::narrow {

void PairContext::gather_corners(BufferedPairs& waiting) const {
  const int n = waiting.batch.size;
  if (n == 0) return;  // no ids to read (the lanes past n repeat lane 0's)
  // The triangles' corner ids, then their corners, asked of memory for every pair before any is
  // read: the misses overlap rather than follow one another.
  for (int l = 0; l < n; ++l) {
    __builtin_prefetch(&mA.mesh.triangles[waiting.ta[l]]);
    __builtin_prefetch(&mB.mesh.triangles[waiting.tb[l]]);
  }
  for (int l = 0; l < n; ++l) {
    for (int k = 0; k < 3; ++k) {
      __builtin_prefetch(&mA.mesh.vertices[mA.mesh.triangles[waiting.ta[l]][k]]);
      __builtin_prefetch(&mB.mesh.vertices[mB.mesh.triangles[waiting.tb[l]][k]]);
    }
  }
  // The corners straight into the batch's lanes (the lanes past n as lane 0, as TriangleBatch::pad
  // fills them), then B's moved into A's frame in all eight lanes, two at a time with SSE2, with
  // b_vertex's formula (geometry::RigidMove): the same operations, so the same bits as corners().
  geometry::TriangleBatch& batch = waiting.batch;
  constexpr int kLanes = geometry::TriangleBatch::kLanes;
  for (int l = 0; l < kLanes; ++l) {
    const auto& tri_a = mA.mesh.triangles[waiting.ta[l < n ? l : 0]];
    const auto& tri_b = mB.mesh.triangles[waiting.tb[l < n ? l : 0]];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& va = mA.mesh.vertices[tri_a[k]];
      const Eigen::Vector3d& vb = mB.mesh.vertices[tri_b[k]];
      for (int c = 0; c < 3; ++c) {
        batch.a[k][c][l] = va[c];
        batch.b[k][c][l] = vb[c];
      }
    }
  }
  const geometry::RigidMove move(mRot, mTrans);
  for (int k = 0; k < 3; ++k) {
#if defined(__SSE2__)
    for (int l = 0; l < kLanes; l += 2) {
      const __m128d x = _mm_load_pd(&batch.b[k][0][l]), y = _mm_load_pd(&batch.b[k][1][l]), z = _mm_load_pd(&batch.b[k][2][l]);
      for (int c = 0; c < 3; ++c) {
        const __m128d xy = _mm_add_pd(_mm_mul_pd(_mm_set1_pd(move.r[c][0]), x), _mm_mul_pd(_mm_set1_pd(move.r[c][1]), y));
        const __m128d xyz = _mm_add_pd(xy, _mm_mul_pd(_mm_set1_pd(move.r[c][2]), z));
        _mm_store_pd(&batch.b[k][c][l], _mm_add_pd(xyz, _mm_set1_pd(move.t[c])));
      }
    }
#else
    for (int l = 0; l < kLanes; ++l) {
      const double x = batch.b[k][0][l], y = batch.b[k][1][l], z = batch.b[k][2][l];
      for (int c = 0; c < 3; ++c) batch.b[k][c][l] = geometry::rigid_move_row(move.r[c], move.t[c], x, y, z);
    }
#endif
  }
}

}  // namespace caliber::narrow
