#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cstdint>

#include "geometry/lanes_avx2.h"

namespace caliber::geometry {

// The triangle kernel on a batch's pairs four at a time, one pair per AVX2 lane (x86-64, chosen at
// run time where the CPU has AVX2 but not AVX-512F): triangle_batch_kernel.inc's body, the AVX-512
// form's, on __m256d lanes with vector masks (that file says how each lane's bits are the portable
// kernel's).
namespace {

using namespace lanes4;

#define CALIBER_AVX2 __attribute__((target("avx2")))

using D = __m256d;
using P3 = Pack3;

/// A mask, all ones or all zeros per lane, with the AVX-512 form's operators on its masks (GCC
/// has no bitwise operators on double vectors).
struct M {
  __m256d m;
  M() = default;
  CALIBER_AVX2 M(__m256d v) : m(v) {}                  // NOLINT(google-explicit-constructor): a comparison's result
  CALIBER_AVX2 operator __m256d() const { return m; }  // NOLINT(google-explicit-constructor)
};
CALIBER_AVX2 inline M operator&(M u, M v) { return _mm256_and_pd(u.m, v.m); }
CALIBER_AVX2 inline M operator|(M u, M v) { return _mm256_or_pd(u.m, v.m); }
CALIBER_AVX2 inline M operator~(M u) { return _mm256_xor_pd(u.m, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))); }
CALIBER_AVX2 inline int bits(M u) { return _mm256_movemask_pd(u.m); }
// The ordered, quiet comparisons (false on NaN), as masks.
CALIBER_AVX2 inline M gt(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_GT_OQ); }
CALIBER_AVX2 inline M ge(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_GE_OQ); }
CALIBER_AVX2 inline M lt(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_LT_OQ); }
CALIBER_AVX2 inline M le(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_LE_OQ); }

CALIBER_AVX2 inline D add(D u, D v) { return _mm256_add_pd(u, v); }
CALIBER_AVX2 inline D sub(D u, D v) { return _mm256_sub_pd(u, v); }
CALIBER_AVX2 inline D mul(D u, D v) { return _mm256_mul_pd(u, v); }
CALIBER_AVX2 inline D div(D u, D v) { return _mm256_div_pd(u, v); }
CALIBER_AVX2 inline D all_lanes(double v) { return _mm256_set1_pd(v); }
/// _mm512_maskz_mov_pd: u where the mask is set, else 0.
CALIBER_AVX2 inline D keep(M m, D u) { return _mm256_and_pd(m.m, u); }
CALIBER_AVX2 inline P3 cross(const P3& u, const P3& v) {
  return {sub(mul(u.y, v.z), mul(u.z, v.y)), sub(mul(u.z, v.x), mul(u.x, v.z)), sub(mul(u.x, v.y), mul(u.y, v.x))};
}

/// lanes8::Triangle8 for half `half` of a batch's triangles of one side: the same values.
struct Tri {
  P3 v[3], e[3];
  D len2[3];
  P3 ab, ac, normal;
  M solid;

  CALIBER_AVX2 Tri(const double (&c)[3][3][TriangleBatch::kLanes], int half) {
    for (int k = 0; k < 3; ++k) {
      v[k] = {_mm256_load_pd(c[k][0] + 4 * half), _mm256_load_pd(c[k][1] + 4 * half), _mm256_load_pd(c[k][2] + 4 * half)};
    }
    for (int i = 0; i < 3; ++i) {
      e[i] = v[(i + 1) % 3] - v[i];
      len2[i] = dot(e[i], e[i]);
    }
    ab = e[0];
    ac = v[2] - v[0];
    normal = cross(ab, ac);
    const D ab2 = len2[0], ac2 = dot(ac, ac), normal2 = dot(normal, normal);
    const D scale2 = _mm256_max_pd(ac2, ab2);
    solid = gt(normal2, mul(mul(all_lanes(1e-24), scale2), scale2));
  }
};

CALIBER_AVX2 inline D root(D u) { return _mm256_sqrt_pd(u); }
CALIBER_AVX2 inline M eq(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_EQ_OQ); }
CALIBER_AVX2 inline M every_lane() { return _mm256_castsi256_pd(_mm256_set1_epi64x(-1)); }
CALIBER_AVX2 inline bool none(M m) { return bits(m) == 0; }
CALIBER_AVX2 inline bool all_set(M m) { return bits(m) == 0xF; }
CALIBER_AVX2 inline M not_lanes(M m) { return ~m; }
CALIBER_AVX2 inline D clamp01(D t) { return clamp01x4(t); }
CALIBER_AVX2 inline P3 add_where(M m, const P3& base, const P3& step) { return pick(m, base + step, base); }

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
  return __builtin_cpu_supports("avx2") ? &batch_avx2 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
BatchKernel closest_points_triangles_batch_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
