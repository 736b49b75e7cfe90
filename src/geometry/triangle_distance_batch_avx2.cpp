#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cstdint>

#include "geometry/lanes_avx2_masked.h"

namespace caliber::geometry {

// The triangle kernel on a batch's pairs four at a time, one pair per AVX2 lane (x86-64, chosen at
// run time where the CPU has AVX2 and FMA but not AVX-512F): triangle_batch_kernel.inc's body, the AVX-512
// form's, on __m256d lanes with vector masks (that file says how each lane's bits are the portable
// kernel's).
namespace {

using namespace lanes4::masked;

#define CALIBER_AVX2 __attribute__((target("avx2,fma")))

#define CALIBER_LANES CALIBER_AVX2
#include "geometry/triangle_batch_kernel.inc"
#undef CALIBER_LANES

CALIBER_AVX2 void batch_half(const TriangleBatch& batch, int half, ClosestPointsBatch& out) {
  const Best best = nearest_pair(Tri(batch.a, half), Tri(batch.b, half));
  const int o = 4 * half;
  _mm256_store_pd(out.on_a[0] + o, best.p.x);
  _mm256_store_pd(out.on_a[1] + o, best.p.y);
  _mm256_store_pd(out.on_a[2] + o, best.p.z);
  _mm256_store_pd(out.on_b[0] + o, best.q.x);
  _mm256_store_pd(out.on_b[1] + o, best.q.y);
  _mm256_store_pd(out.on_b[2] + o, best.q.z);
  _mm256_store_pd(out.distance + o, _mm256_sqrt_pd(best.d2));
}

CALIBER_AVX2 void batch_avx2(const TriangleBatch& batch, ClosestPointsBatch& out) {
  batch_half(batch, 0, out);
  if (batch.size > 4) batch_half(batch, 1, out);
}

#undef CALIBER_AVX2

}  // namespace

namespace detail {

BatchKernel closest_points_triangles_batch_avx2_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? &batch_avx2 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
BatchKernel closest_points_triangles_batch_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
