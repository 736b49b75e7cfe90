#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cfloat>

#include "geometry/edge_axes.h"
#include "geometry/lanes_avx2_masked.h"

namespace caliber::geometry {

// triangles_apart on a batch's pairs four at a time, one pair per AVX2 lane (x86-64, chosen at run
// time where the CPU has AVX2 but not AVX-512F): triangle_apart_kernel.inc's body, the AVX-512
// form's, on __m256d lanes with vector masks (that file says how each lane's verdict is the
// portable one). Where a half's four verdicts are settled by the planes, its edge axes are skipped.
namespace {

using namespace lanes4::masked;

#define CALIBER_AVX2 __attribute__((target("avx2")))
#define CALIBER_LANES CALIBER_AVX2

using ApartTri = lanes4::BatchHalf;

#include "geometry/triangle_apart_kernel.inc"

CALIBER_AVX2 unsigned apart_avx2(const TriangleBatch& batch, double reach) {
  const D r = all_lanes(reach);
  unsigned apart = 0;
  for (int half = 0; half < 2 && 4 * half < batch.size; ++half) {
    const ApartTri ta(batch.a, half), tb(batch.b, half);
    M m = beyond_plane(ta, tb, r) | beyond_plane(tb, ta, r);
    if (!all_set(m)) m = edges_apart(ta, tb, r, m);
    apart |= static_cast<unsigned>(bits(m)) << (4 * half);
  }
  return apart & ((1u << batch.size) - 1u);
}

#undef CALIBER_LANES
#undef CALIBER_AVX2

}  // namespace

namespace detail {

ApartBatchTest triangles_apart_batch_avx2_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? &apart_avx2 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
ApartBatchTest triangles_apart_batch_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
