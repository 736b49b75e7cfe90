// PairContext::gather_corners: a leaf batch's corners read straight into its lanes, B's moved into
// A's frame there; the portable form, and the choice of form.

#include "narrow/pair_context.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "geometry/rigid_move.h"
#include "geometry/triangle_distance.h"

namespace caliber::narrow {

void PairContext::gather_corners(BufferedPairs& waiting) const {
  static const detail::GatherCorners form = [] {
    const detail::GatherCorners avx2 = detail::gather_corners_avx2_if_supported();
    return avx2 != nullptr ? avx2 : detail::gather_corners_portable;
  }();
  form(mA, mB, b_move(), waiting);
}

namespace detail {

void gather_corners_portable(const ModelData& a, const ModelData& b, const geometry::RigidMove& move, BufferedPairs& waiting) {
  if (waiting.batch.size == 0) return;  // no ids to read (the lanes past the pairs repeat lane 0's)
  CornerPointers at;
  corners_prefetched(a, b, waiting, at);
  // The corners straight into the batch's lanes, then B's moved into A's frame in all eight lanes,
  // two at a time with SSE2, with b_vertex's formula (geometry::RigidMove): the same operations,
  // so the same bits as corners().
  geometry::TriangleBatch& batch = waiting.batch;
  constexpr int kLanes = geometry::TriangleBatch::kLanes;
  for (int l = 0; l < kLanes; ++l) {
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) {
        batch.a[k][c][l] = at.a[k][l][c];
        batch.b[k][c][l] = at.b[k][l][c];
      }
    }
  }
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

}  // namespace detail
}  // namespace caliber::narrow
