#pragma once
/// \file
/// Three-vectors in four AVX2 lanes for the triangle kernel (triangle_distance_avx2.cpp: a lane
/// per feature pair) and the batched tests (triangle_intersect_avx2.cpp, triangle_apart_avx2.cpp,
/// triangle_distance_batch_avx2.cpp: a lane per triangle pair, the last two through
/// lanes_avx2_masked.h), each operation the IEEE operation the portable code does (no fused
/// multiply-add here: the kernel's FMA is explicit, kernel::cross_term and fmadd), so that every
/// lane computes its bits. Included only by code built for x86-64 with GNU C++; these functions are
/// compiled for AVX2 (the kernel and the batch that call them also enable FMA), chosen at run time.

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <Eigen/Core>

#include "geometry/triangle_distance.h"

namespace caliber::geometry::lanes4 {

#define CALIBER_AVX2 __attribute__((target("avx2")))

using Vec3 = Eigen::Vector3d;

struct Pack3 {
  __m256d x, y, z;
};

CALIBER_AVX2 inline __m256d lanes(double l0, double l1, double l2, double l3) { return _mm256_setr_pd(l0, l1, l2, l3); }
CALIBER_AVX2 inline Pack3 lanes(const Vec3& l0, const Vec3& l1, const Vec3& l2, const Vec3& l3) {
  return {lanes(l0.x(), l1.x(), l2.x(), l3.x()), lanes(l0.y(), l1.y(), l2.y(), l3.y()), lanes(l0.z(), l1.z(), l2.z(), l3.z())};
}
CALIBER_AVX2 inline Pack3 operator+(const Pack3& u, const Pack3& v) {
  return {_mm256_add_pd(u.x, v.x), _mm256_add_pd(u.y, v.y), _mm256_add_pd(u.z, v.z)};
}
CALIBER_AVX2 inline Pack3 operator-(const Pack3& u, const Pack3& v) {
  return {_mm256_sub_pd(u.x, v.x), _mm256_sub_pd(u.y, v.y), _mm256_sub_pd(u.z, v.z)};
}
CALIBER_AVX2 inline Pack3 broadcast(const Vec3& v) {
  return {_mm256_set1_pd(v.x()), _mm256_set1_pd(v.y()), _mm256_set1_pd(v.z())};
}
/// Absolute values.
CALIBER_AVX2 inline __m256d magnitude(__m256d u) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), u); }
CALIBER_AVX2 inline Pack3 magnitude(const Pack3& u) { return {magnitude(u.x), magnitude(u.y), magnitude(u.z)}; }
/// s * v, as Eigen's scalar times vector: s * v[k] for each coordinate.
CALIBER_AVX2 inline Pack3 operator*(__m256d s, const Pack3& v) {
  return {_mm256_mul_pd(s, v.x), _mm256_mul_pd(s, v.y), _mm256_mul_pd(s, v.z)};
}
CALIBER_AVX2 inline __m256d dot(const Pack3& u, const Pack3& v) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(u.x, v.x), _mm256_mul_pd(u.y, v.y)), _mm256_mul_pd(u.z, v.z));
}
/// mask ? u : v, lane by lane.
CALIBER_AVX2 inline __m256d pick(__m256d mask, __m256d u, __m256d v) { return _mm256_blendv_pd(v, u, mask); }
CALIBER_AVX2 inline Pack3 pick(__m256d mask, const Pack3& u, const Pack3& v) {
  return {pick(mask, u.x, v.x), pick(mask, u.y, v.y), pick(mask, u.z, v.z)};
}
CALIBER_AVX2 inline __m256d clamp01x4(__m256d t) {
  // _mm256_max_pd(t, 0) returns its second operand where either is NaN, as maxsd does in clamp01
  // (triangle_distance.cpp).
  return _mm256_min_pd(_mm256_max_pd(t, _mm256_setzero_pd()), _mm256_set1_pd(1.0));
}
CALIBER_AVX2 inline __m256d gt(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_GT_OQ); }
CALIBER_AVX2 inline __m256d ge(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_GE_OQ); }
CALIBER_AVX2 inline __m256d lt(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_LT_OQ); }
CALIBER_AVX2 inline __m256d le(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_LE_OQ); }
/// Every mask's lanes anded, or ored.
template <class... Masks>
CALIBER_AVX2 inline __m256d all(__m256d m, Masks... rest) {
  ((m = _mm256_and_pd(m, rest)), ...);
  return m;
}
template <class... Masks>
CALIBER_AVX2 inline __m256d any(__m256d m, Masks... rest) {
  ((m = _mm256_or_pd(m, rest)), ...);
  return m;
}
CALIBER_AVX2 inline __m256d negate(__m256d u) { return _mm256_xor_pd(u, _mm256_set1_pd(-0.0)); }

/// A triangle's corners in lanes 0-2 (lane 3 repeats corner 0), each edge vector (corner i to
/// corner i + 1, the same subtraction as the portable form's) and its squared length.
struct Triangle4 {
  Pack3 v, e;
  __m256d len2;
};

template <int kImm>
CALIBER_AVX2 inline Pack3 permute(const Pack3& u) {
  return {_mm256_permute4x64_pd(u.x, kImm), _mm256_permute4x64_pd(u.y, kImm), _mm256_permute4x64_pd(u.z, kImm)};
}

/// Lanes i0, i1, i2, i3 of u (each 0-3).
template <int i0, int i1, int i2, int i3>
CALIBER_AVX2 inline Pack3 gather(const Pack3& u) {
  return permute<i0 | (i1 << 2) | (i2 << 4) | (i3 << 6)>(u);
}
template <int i0, int i1, int i2, int i3>
CALIBER_AVX2 inline __m256d gather(__m256d u) {
  return _mm256_permute4x64_pd(u, i0 | (i1 << 2) | (i2 << 4) | (i3 << 6));
}

/// (u_i, w_i, u_j, w_j): a lane of A and of B, twice.
template <int i, int j>
CALIBER_AVX2 inline Pack3 interleave(const Pack3& u, const Pack3& w) {
  const Pack3 pu = gather<i, i, j, j>(u), pw = gather<i, i, j, j>(w);
  return {_mm256_blend_pd(pu.x, pw.x, 0b1010), _mm256_blend_pd(pu.y, pw.y, 0b1010), _mm256_blend_pd(pu.z, pw.z, 0b1010)};
}
template <int i, int j>
CALIBER_AVX2 inline __m256d interleave(__m256d u, __m256d w) {
  const __m256d pu = gather<i, i, j, j>(u), pw = gather<i, i, j, j>(w);
  return _mm256_blend_pd(pu, pw, 0b1010);
}

CALIBER_AVX2 inline Triangle4 load(const Vec3 t[3]) {
  Triangle4 r;
  r.v = lanes(t[0], t[1], t[2], t[0]);
  r.e = gather<1, 2, 0, 1>(r.v) - r.v;
  r.len2 = dot(r.e, r.e);
  return r;
}

/// Eigen's cross product, coordinate by coordinate.
CALIBER_AVX2 inline Pack3 cross(const Pack3& u, const Pack3& v) {
  return {_mm256_sub_pd(_mm256_mul_pd(u.y, v.z), _mm256_mul_pd(u.z, v.y)),
          _mm256_sub_pd(_mm256_mul_pd(u.z, v.x), _mm256_mul_pd(u.x, v.z)),
          _mm256_sub_pd(_mm256_mul_pd(u.x, v.y), _mm256_mul_pd(u.y, v.x))};
}

/// Lanes 4 half to 4 half + 3 of a corner of a batch's triangles ([coordinate][pair]).
CALIBER_AVX2 inline Pack3 load_half(const double (&c)[3][TriangleBatch::kLanes], int half) {
  return {_mm256_load_pd(c[0] + 4 * half), _mm256_load_pd(c[1] + 4 * half), _mm256_load_pd(c[2] + 4 * half)};
}

/// Half `half` of a batch's triangles of one side (TriangleBatch::a or b; lanes 4 half to 4 half +
/// 3) with what the refusal batch reads, lanes8::Triangle8's values by the same operations: the
/// edges (corner i to corner i + 1), ac (corner 0 to 2), the normal ab x ac (ab is edge 0) and
/// the squared lengths of ab, ac and the normal.
struct BatchHalf {
  Pack3 v[3], e[3], ac, normal;
  __m256d ab2, ac2, normal2;

  CALIBER_AVX2 BatchHalf(const double (&c)[3][3][TriangleBatch::kLanes], int half) {
    for (int k = 0; k < 3; ++k) v[k] = load_half(c[k], half);
    for (int i = 0; i < 3; ++i) e[i] = v[(i + 1) % 3] - v[i];
    ac = v[2] - v[0];
    normal = cross(e[0], ac);
    ab2 = dot(e[0], e[0]);
    ac2 = dot(ac, ac);
    normal2 = dot(normal, normal);
  }
};

/// kernel::slab_clear's test of the corners w (relative to p or q) against v, |v| being m.
CALIBER_AVX2 inline __m256d slab_side(const Pack3& w, const Pack3& v, const Pack3& m) {
  const __m256d bound = dot(magnitude(w), m);
  return _mm256_and_pd(ge(dot(w, v), _mm256_mul_pd(bound, _mm256_set1_pd(-0x1p-49))),
                       le(bound, _mm256_set1_pd(0x1.fffffffffffffp+1023)));
}

/// kernel::slab_clear (triangle_kernel.h) with A's corners in the lanes of ca and B's in cb (each
/// lane a corner: Triangle4's fourth repeats its first): the same expressions in the same order.
CALIBER_AVX2 inline bool slab_clear_x4(const Pack3& ca, const Pack3& cb, const Vec3& p, const Vec3& q) {
  const Pack3 bp = broadcast(p), bq = broadcast(q);
  const Pack3 v = bq - bp, m = magnitude(v);
  return _mm256_movemask_pd(_mm256_and_pd(slab_side(bp - ca, v, m), slab_side(cb - bq, v, m))) == 0xF;
}

#undef CALIBER_AVX2

}  // namespace caliber::geometry::lanes4

#endif
