#pragma once
/// \file
/// Eight float lanes in AVX2: the IEEE operations the node tests' float forms are written in
/// (node_test_float.cpp, wide_test_avx2.cpp), each lane's result the scalar operation's. Included
/// only by code built for x86-64 with GNU C++; compiled for AVX2 alone, chosen at run time.

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace caliber::narrow::lanes8 {

#define CALIBER_LANES8 __attribute__((target("avx2")))

using V = __m256;

CALIBER_LANES8 inline V add(V u, V v) { return _mm256_add_ps(u, v); }
CALIBER_LANES8 inline V sub(V u, V v) { return _mm256_sub_ps(u, v); }
CALIBER_LANES8 inline V mul(V u, V v) { return _mm256_mul_ps(u, v); }
CALIBER_LANES8 inline V either(V u, V v) { return _mm256_or_ps(u, v); }
CALIBER_LANES8 inline V both(V u, V v) { return _mm256_and_ps(u, v); }
CALIBER_LANES8 inline V magnitude(V u) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), u); }

#undef CALIBER_LANES8

}  // namespace caliber::narrow::lanes8

#endif
