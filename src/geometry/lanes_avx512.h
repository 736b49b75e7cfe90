#pragma once
/// \file
/// Three-vectors in eight AVX-512 lanes, one triangle pair per lane, for the batch kernels
/// (triangle_distance_avx512.cpp, triangle_apart_avx512.cpp): each operation the IEEE operation
/// the portable code does (no FMA), so that every lane computes its pair's bits. Included only by
/// code built for x86-64 with GNU C++; every function is compiled for AVX-512F alone, chosen at run
/// time.

#if defined(__x86_64__) && defined(__GNUC__)
// GCC 12's AVX-512 intrinsics (max, min, sqrt) pass _mm512_undefined_pd() as the unused source of
// their masked builtins, which -Wuninitialized reports at every use: a known false positive.
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>

#include <cstdint>

#include "geometry/triangle_distance.h"

namespace caliber::geometry::lanes8 {

#define CALIBER_AVX512 __attribute__((target("avx512f")))

using D = __m512d;
using M = __mmask8;

struct P3 {
  D x, y, z;
};

CALIBER_AVX512 inline D add(D u, D v) { return _mm512_add_pd(u, v); }
CALIBER_AVX512 inline D sub(D u, D v) { return _mm512_sub_pd(u, v); }
CALIBER_AVX512 inline D mul(D u, D v) { return _mm512_mul_pd(u, v); }
CALIBER_AVX512 inline D div(D u, D v) { return _mm512_div_pd(u, v); }
CALIBER_AVX512 inline D all_lanes(double v) { return _mm512_set1_pd(v); }
CALIBER_AVX512 inline D negate(D u) {
  return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(u), _mm512_set1_epi64(INT64_MIN)));
}
CALIBER_AVX512 inline P3 operator+(const P3& u, const P3& v) { return {add(u.x, v.x), add(u.y, v.y), add(u.z, v.z)}; }
CALIBER_AVX512 inline P3 operator-(const P3& u, const P3& v) { return {sub(u.x, v.x), sub(u.y, v.y), sub(u.z, v.z)}; }
/// s * v, as Eigen's scalar times vector: s * v[k] for each coordinate.
CALIBER_AVX512 inline P3 operator*(D s, const P3& v) { return {mul(s, v.x), mul(s, v.y), mul(s, v.z)}; }
/// Eigen's order for a 3-vector: (x0*y0 + x1*y1) + x2*y2.
CALIBER_AVX512 inline D dot(const P3& u, const P3& v) { return add(add(mul(u.x, v.x), mul(u.y, v.y)), mul(u.z, v.z)); }
/// Eigen's cross product, coordinate by coordinate.
CALIBER_AVX512 inline P3 cross(const P3& u, const P3& v) {
  return {sub(mul(u.y, v.z), mul(u.z, v.y)), sub(mul(u.z, v.x), mul(u.x, v.z)), sub(mul(u.x, v.y), mul(u.y, v.x))};
}
CALIBER_AVX512 inline M gt(D u, D v) { return _mm512_cmp_pd_mask(u, v, _CMP_GT_OQ); }
CALIBER_AVX512 inline M ge(D u, D v) { return _mm512_cmp_pd_mask(u, v, _CMP_GE_OQ); }
CALIBER_AVX512 inline M lt(D u, D v) { return _mm512_cmp_pd_mask(u, v, _CMP_LT_OQ); }
CALIBER_AVX512 inline M le(D u, D v) { return _mm512_cmp_pd_mask(u, v, _CMP_LE_OQ); }
/// mask ? u : v, lane by lane.
CALIBER_AVX512 inline D pick(M mask, D u, D v) { return _mm512_mask_blend_pd(mask, v, u); }
CALIBER_AVX512 inline P3 pick(M mask, const P3& u, const P3& v) {
  return {pick(mask, u.x, v.x), pick(mask, u.y, v.y), pick(mask, u.z, v.z)};
}
/// clamp01 (triangle_distance.cpp): vmaxpd returns its second operand where either is NaN, as
/// maxsd does there, so NaN falls to 0.
CALIBER_AVX512 inline D clamp01(D t) { return _mm512_min_pd(_mm512_max_pd(t, _mm512_setzero_pd()), all_lanes(1.0)); }

CALIBER_AVX512 inline D root(D u) { return _mm512_sqrt_pd(u); }
/// u v + w, rounded once.
CALIBER_AVX512 inline D fmadd(D u, D v, D w) { return _mm512_fmadd_pd(u, v, w); }
CALIBER_AVX512 inline D magnitude(D u) {
  return _mm512_castsi512_pd(_mm512_andnot_si512(_mm512_set1_epi64(INT64_MIN), _mm512_castpd_si512(u)));
}
CALIBER_AVX512 inline P3 magnitude(const P3& u) { return {magnitude(u.x), magnitude(u.y), magnitude(u.z)}; }
CALIBER_AVX512 inline D min_lanes(D u, D v) { return _mm512_min_pd(u, v); }
CALIBER_AVX512 inline D max_lanes(D u, D v) { return _mm512_max_pd(u, v); }
CALIBER_AVX512 inline M eq(D u, D v) { return _mm512_cmp_pd_mask(u, v, _CMP_EQ_OQ); }
CALIBER_AVX512 inline M every_lane() { return 0xFF; }
CALIBER_AVX512 inline M no_lane() { return 0; }
CALIBER_AVX512 inline bool none(M m) { return m == 0; }
CALIBER_AVX512 inline bool all_set(M m) { return m == 0xFF; }
CALIBER_AVX512 inline M not_lanes(M m) { return static_cast<M>(~m); }
/// u where the mask is set, else 0.
CALIBER_AVX512 inline D keep(M m, D u) { return _mm512_maskz_mov_pd(m, u); }

CALIBER_AVX512 inline P3 load(const double (&c)[3][TriangleBatch::kLanes]) {
  return {_mm512_load_pd(c[0]), _mm512_load_pd(c[1]), _mm512_load_pd(c[2])};
}

/// A triangle per lane with what the kernel reads of it: kernel::TriangleFrame's values and the
/// edge vectors (corner i to corner i + 1) with their squared lengths.
struct Triangle8 {
  P3 v[3], e[3];
  D len2[3];
  P3 ab, ac, normal;    ///< v1 - v0, v2 - v0, ab x ac
  D ab2, ac2, normal2;  ///< their squared lengths

  CALIBER_AVX512 explicit Triangle8(const double (&c)[3][3][TriangleBatch::kLanes]) : v{load(c[0]), load(c[1]), load(c[2])} {
    for (int i = 0; i < 3; ++i) {
      e[i] = v[(i + 1) % 3] - v[i];
      len2[i] = dot(e[i], e[i]);
    }
    ab = e[0];  // v1 - v0, the same subtraction
    ac = v[2] - v[0];
    normal = cross(ab, ac);
    ab2 = len2[0];
    ac2 = dot(ac, ac);
    normal2 = dot(normal, normal);
  }
};

#undef CALIBER_AVX512

}  // namespace caliber::geometry::lanes8

#endif
