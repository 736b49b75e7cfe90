#pragma once
/// \file
/// The names the batch kernels' bodies (triangle_batch_kernel.inc, triangle_apart_kernel.inc) are
/// written in, on four AVX2 lanes with vector masks: what lanes8 (lanes_avx512.h) gives them on
/// eight AVX-512 lanes with bit masks, each operation the IEEE operation of its namesake there.
/// Used by the batches' AVX2 forms (triangle_distance_batch_avx2.cpp, triangle_apart_avx2.cpp).

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "geometry/lanes_avx2.h"

namespace caliber::geometry::lanes4::masked {

#define CALIBER_AVX2 __attribute__((target("avx2")))

using lanes4::cross;
using lanes4::dot;
using lanes4::magnitude;
using lanes4::negate;
using lanes4::Pack3;
using lanes4::pick;

using D = __m256d;
using P3 = Pack3;

/// A mask, all ones or all zeros per lane, with the AVX-512 form's operators on its masks (GCC
/// has no bitwise operators on double vectors). A function that returns an M or takes one by value
/// is inlined (always_inline beyond the one-instruction helpers here); the others take a
/// reference: GCC 12.2 compiled an out-of-line function returning an M with a vzeroupper before
/// its ret, which cleared lanes 2 and 3 of the result it had just put in ymm0.
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
/// u where the mask is set, else 0 (_mm512_maskz_mov_pd).
CALIBER_AVX2 inline D keep(M m, D u) { return _mm256_and_pd(m.m, u); }
CALIBER_AVX2 inline D root(D u) { return _mm256_sqrt_pd(u); }
/// u v + w, rounded once (the caller enables "fma").
__attribute__((target("avx2,fma"))) inline D fmadd(D u, D v, D w) { return _mm256_fmadd_pd(u, v, w); }
CALIBER_AVX2 inline D min_lanes(D u, D v) { return _mm256_min_pd(u, v); }
CALIBER_AVX2 inline D max_lanes(D u, D v) { return _mm256_max_pd(u, v); }
CALIBER_AVX2 inline M no_lane() { return _mm256_setzero_pd(); }
CALIBER_AVX2 inline M eq(D u, D v) { return _mm256_cmp_pd(u, v, _CMP_EQ_OQ); }
CALIBER_AVX2 inline M every_lane() { return _mm256_castsi256_pd(_mm256_set1_epi64x(-1)); }
CALIBER_AVX2 inline bool none(M m) { return bits(m) == 0; }
CALIBER_AVX2 inline bool all_set(M m) { return bits(m) == 0xF; }
CALIBER_AVX2 inline M not_lanes(M m) { return ~m; }
CALIBER_AVX2 inline D clamp01(D t) { return lanes4::clamp01x4(t); }

/// What the closest-points batch reads of lanes8::Triangle8 (the corners, the edges and their
/// squared lengths), for half `half` of a batch's triangles of one side: the same values.
struct Tri {
  P3 v[3], e[3];
  D len2[3];

  CALIBER_AVX2 Tri(const double (&c)[3][3][TriangleBatch::kLanes], int half) {
    for (int k = 0; k < 3; ++k) v[k] = lanes4::load_half(c[k], half);
    for (int i = 0; i < 3; ++i) {
      e[i] = v[(i + 1) % 3] - v[i];
      len2[i] = dot(e[i], e[i]);
    }
  }
};

#undef CALIBER_AVX2

}  // namespace caliber::geometry::lanes4::masked

#endif
