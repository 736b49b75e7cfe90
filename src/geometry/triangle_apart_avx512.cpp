#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <cfloat>

#include "geometry/edge_axes.h"
#include "geometry/lanes_avx512.h"

namespace caliber::geometry {

// triangles_apart on eight pairs at once, one pair per AVX-512 lane (x86-64, chosen at run time
// where the CPU has AVX-512F): triangle_apart_kernel.inc's body on __m512d lanes and __mmask8
// masks (that file says how each lane's verdict is the portable one).
namespace {

using namespace lanes8;

#define CALIBER_AVX512 __attribute__((target("avx512f")))
#define CALIBER_LANES CALIBER_AVX512

using ApartTri = Triangle8;

#include "geometry/triangle_apart_kernel.inc"

CALIBER_AVX512 unsigned apart_avx512(const TriangleBatch& batch, double reach) {
  const Triangle8 ta(batch.a), tb(batch.b);
  const D r = all_lanes(reach);
  M apart = beyond_plane(ta, tb, r) | beyond_plane(tb, ta, r);
  if (!all_set(apart)) apart = edges_apart(ta, tb, r, apart);
  return static_cast<unsigned>(apart) & ((1u << batch.size) - 1u);
}

#undef CALIBER_LANES
#undef CALIBER_AVX512

}  // namespace

namespace detail {

ApartBatchTest triangles_apart_batch_avx512_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") ? &apart_avx512 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
ApartBatchTest triangles_apart_batch_avx512_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
