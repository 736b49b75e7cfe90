#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)

#include "geometry/lanes_avx512.h"

namespace caliber::geometry {

// The triangle kernel on eight pairs at once, one pair per AVX-512 lane (x86-64, chosen at run
// time where the CPU has AVX-512F): triangle_batch_kernel.inc's body on __m512d lanes and __mmask8
// masks (that file says how each lane's bits are the portable kernel's).
namespace {

using namespace lanes8;

#define CALIBER_AVX512 __attribute__((target("avx512f")))
#define CALIBER_LANES CALIBER_AVX512

using Tri = Triangle8;

#include "geometry/triangle_batch_kernel.inc"

CALIBER_AVX512 void batch_avx512(const TriangleBatch& batch, ClosestPointsBatch& out) {
  const Best best = nearest_pair(Triangle8(batch.a), Triangle8(batch.b));
  _mm512_store_pd(out.on_a[0], best.p.x);
  _mm512_store_pd(out.on_a[1], best.p.y);
  _mm512_store_pd(out.on_a[2], best.p.z);
  _mm512_store_pd(out.on_b[0], best.q.x);
  _mm512_store_pd(out.on_b[1], best.q.y);
  _mm512_store_pd(out.on_b[2], best.q.z);
  _mm512_store_pd(out.distance, _mm512_sqrt_pd(best.d2));
}

#undef CALIBER_LANES
#undef CALIBER_AVX512

}  // namespace

namespace detail {

BatchKernel closest_points_triangles_batch_avx512_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") ? &batch_avx512 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
BatchKernel closest_points_triangles_batch_avx512_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
