// PairContext::gather_corners in AVX2 (leaf_buffer.h): four lanes at a time, each corner's
// coordinates transposed in registers into the batch's lanes, B's moved into A's frame with
// geometry::rigid_move_row's operations lane by lane (only "avx2" is enabled here, not "fma", and
// the build has -ffp-contract=off: the same bits as the portable form).

#include "narrow/leaf_buffer.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2")))

using D = __m256d;

/// The corners at p[0..3] as lanes x, y, z (each read as two doubles and one: nothing past its
/// third coordinate).
CALIBER_AVX2 inline void corner_lanes(const double* const p[4], D& x, D& y, D& z) {
  // (x0 y0 x2 y2) and (x1 y1 x3 y3), then their low and high halves of each pair.
  const D even = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p[0])), _mm_loadu_pd(p[2]), 1);
  const D odd = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p[1])), _mm_loadu_pd(p[3]), 1);
  x = _mm256_unpacklo_pd(even, odd);
  y = _mm256_unpackhi_pd(even, odd);
  const __m128d z01 = _mm_unpacklo_pd(_mm_load_sd(p[0] + 2), _mm_load_sd(p[1] + 2));
  const __m128d z23 = _mm_unpacklo_pd(_mm_load_sd(p[2] + 2), _mm_load_sd(p[3] + 2));
  z = _mm256_insertf128_pd(_mm256_castpd128_pd256(z01), z23, 1);
}

CALIBER_AVX2 void gather_corners_avx2(const ModelData& a, const ModelData& b, const geometry::RigidMove& move,
                                      BufferedPairs& waiting) {
  if (waiting.batch.size == 0) return;  // no ids to read (the lanes past the pairs repeat lane 0's)
  CornerPointers at;
  corners_prefetched(a, b, waiting, at);
  geometry::TriangleBatch& batch = waiting.batch;
  for (int g = 0; g < geometry::TriangleBatch::kLanes; g += 4) {
    for (int k = 0; k < 3; ++k) {
      D x, y, z;
      corner_lanes(at.a[k] + g, x, y, z);
      _mm256_store_pd(&batch.a[k][0][g], x);
      _mm256_store_pd(&batch.a[k][1][g], y);
      _mm256_store_pd(&batch.a[k][2][g], z);
      corner_lanes(at.b[k] + g, x, y, z);
      for (int c = 0; c < 3; ++c) {
        // ((r0 x + r1 y) + r2 z) + t, each operation rounded (rigid_move_row).
        const D xy =
            _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(move.r[c][0]), x), _mm256_mul_pd(_mm256_set1_pd(move.r[c][1]), y));
        const D xyz = _mm256_add_pd(xy, _mm256_mul_pd(_mm256_set1_pd(move.r[c][2]), z));
        _mm256_store_pd(&batch.b[k][c][g], _mm256_add_pd(xyz, _mm256_set1_pd(move.t[c])));
      }
    }
  }
}

}  // namespace

GatherCorners gather_corners_avx2_if_supported() { return __builtin_cpu_supports("avx2") ? gather_corners_avx2 : nullptr; }

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
GatherCorners gather_corners_avx2_if_supported() { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
