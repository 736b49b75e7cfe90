// The distance bound of a visit's four child pairs in AVX2 lanes (a0 b0, a0 b1, a1 b0, a1 b1):
// PairContext::gap's bounds (object-frame boxes, then frames_apart) in every lane, their larger,
// frames_apart skipped once every lane is beyond the reach with the boxes' bound, each with
// the scalar's operations in its order: this file is built with -ffp-contract=off, like the rest,
// so no multiply and add are fused, in the AVX2 build (which enables "avx2" alone, not "fma") or
// in its AVX-512VL build (whose target would allow FMA instructions; none is emitted).

#include "narrow/distance_bound_avx2.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2")))

/// A's node in lanes 0-1 and 2-3 is a0 and a1; B's alternates b0, b1.
CALIBER_AVX2 inline __m256d lanes_a(double a0, double a1) { return _mm256_setr_pd(a0, a0, a1, a1); }
CALIBER_AVX2 inline __m256d lanes_b(double b0, double b1) { return _mm256_setr_pd(b0, b1, b0, b1); }

CALIBER_AVX2 inline __m256d add(__m256d u, __m256d v) { return _mm256_add_pd(u, v); }
CALIBER_AVX2 inline __m256d sub(__m256d u, __m256d v) { return _mm256_sub_pd(u, v); }
CALIBER_AVX2 inline __m256d mul(__m256d u, __m256d v) { return _mm256_mul_pd(u, v); }
CALIBER_AVX2 inline __m256d magnitude(__m256d u) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), u); }
/// max(0, u) squared.
CALIBER_AVX2 inline __m256d square_of_positive(__m256d u) {
  const __m256d p = _mm256_max_pd(u, _mm256_setzero_pd());
  return mul(p, p);
}
CALIBER_AVX2 inline __m256d dot3(__m256d x0, __m256d x1, __m256d x2, __m256d y0, __m256d y1, __m256d y2) {
  return add(add(mul(x0, y0), mul(x1, y1)), mul(x2, y2));
}

/// std::clamp(s, -h, h) for h >= 0, as the scalar's comparisons take it (s < -h gives -h, else
/// h < s gives h, else s): maxpd(x, y) is x > y ? x : y and minpd(x, y) is x < y ? x : y, so
/// max(-h, s) is s < -h ? -h : s and min(h, that) is h < that ? h : that, the same choice on
/// ties, signed zeros and NaN (three operations where two compares and two blends took five).
CALIBER_AVX2 inline __m256d clamp_half(__m256d s, __m256d h) {
  const __m256d lo = _mm256_xor_pd(h, _mm256_set1_pd(-0.0));
  return _mm256_min_pd(h, _mm256_max_pd(lo, s));
}

/// narrow::frames_apart in four lanes (a's coordinates: r[i][k] = a's axis i . b's axis k, t[i] =
/// a's axis i . d; ah, bh the half-extents).
CALIBER_AVX2 inline __m256d frames_apart(const BoundConstants& k, const __m256d r[3][3], const __m256d t[3], const __m256d ah[3],
                                         const __m256d bh[3]) {
  __m256d p[3], v[3], u[3], q[3], n[3];
  for (int i = 0; i < 3; ++i) {
    p[i] = clamp_half(t[i], ah[i]);
    v[i] = sub(p[i], t[i]);
  }
  for (int j = 0; j < 3; ++j) u[j] = clamp_half(dot3(r[0][j], r[1][j], r[2][j], v[0], v[1], v[2]), bh[j]);
  for (int i = 0; i < 3; ++i) {
    q[i] = add(add(add(t[i], mul(r[i][0], u[0])), mul(r[i][1], u[1])), mul(r[i][2], u[2]));
    n[i] = sub(q[i], clamp_half(q[i], ah[i]));
  }
  const __m256d len = _mm256_sqrt_pd(dot3(n[0], n[1], n[2], n[0], n[1], n[2]));
  const __m256d some = _mm256_cmp_pd(len, _mm256_setzero_pd(), _CMP_GT_OQ);
  const __m256d at = dot3(n[0], n[1], n[2], t[0], t[1], t[2]);
  __m256d spread_a = _mm256_setzero_pd(), spread_b = _mm256_setzero_pd();
  for (int j = 0; j < 3; ++j) {
    spread_a = add(spread_a, mul(ah[j], magnitude(n[j])));
    spread_b = add(spread_b, mul(bh[j], magnitude(dot3(r[0][j], r[1][j], r[2][j], n[0], n[1], n[2]))));
  }
  const __m256d halves = add(add(add(ah[0], ah[1]), ah[2]), add(add(bh[0], bh[1]), bh[2]));
  const __m256d within = sub(_mm256_div_pd(sub(at, add(spread_a, spread_b)), len), mul(_mm256_set1_pd(k.hair), halves));
  const __m256d apart = _mm256_max_pd(mul(within, _mm256_set1_pd(k.apart_shrink)), _mm256_setzero_pd());
  return _mm256_and_pd(apart, some);
}

/// Whether every lane of u is above `reach`.
CALIBER_AVX2 inline bool all_beyond(__m256d u, __m256d reach) {
  return _mm256_movemask_pd(_mm256_cmp_pd(u, reach, _CMP_GT_OQ)) == 0xF;
}

CALIBER_AVX2 void gaps_2x2(const BoundConstants& k, const NearA& a0, const NearA& a1, const NearB& b0, const NearB& b1,
                           double reach_, double out[4]) {
  const __m256d reach = _mm256_set1_pd(reach_);
  // Object-frame boxes: each box against the other's box seen along its axes.
  __m256d boxes_a = _mm256_setzero_pd(), boxes_b = _mm256_setzero_pd();
  for (int i = 0; i < 3; ++i) {
    const __m256d along_a = magnitude(sub(lanes_b(b0.box_in_a[i], b1.box_in_a[i]), lanes_a(a0.box[i], a1.box[i])));
    boxes_a =
        add(boxes_a,
            square_of_positive(sub(sub(along_a, lanes_a(a0.half[i], a1.half[i])), lanes_b(b0.reach_on_a[i], b1.reach_on_a[i]))));
    const __m256d along_b = magnitude(sub(lanes_b(b0.box[i], b1.box[i]), lanes_a(a0.box_in_b[i], a1.box_in_b[i])));
    boxes_b =
        add(boxes_b,
            square_of_positive(sub(sub(along_b, lanes_b(b0.half[i], b1.half[i])), lanes_a(a0.reach_on_b[i], a1.reach_on_b[i]))));
  }
  const __m256d boxes = _mm256_sqrt_pd(_mm256_max_pd(boxes_a, boxes_b));
  // Every lane beyond the reach already (where the scalar stops too): the rest is not needed.
  if (all_beyond(boxes, reach)) {
    _mm256_storeu_pd(out, boxes);
    return;
  }
  // frames_apart in a's coordinates: r, a's axis i . b's axis j; t, b's center along a's axes
  // (frames_relative).
  __m256d ax[3][3], bx[3][3], d[3], ah[3], bh[3];
  for (int i = 0; i < 3; ++i) {
    for (int c = 0; c < 3; ++c) {
      ax[i][c] = lanes_a(a0.frame.axis[i][c], a1.frame.axis[i][c]);
      bx[i][c] = lanes_b(b0.frame.axis[i][c], b1.frame.axis[i][c]);
    }
    d[i] = sub(lanes_b(b0.frame.center[i], b1.frame.center[i]), lanes_a(a0.frame.center[i], a1.frame.center[i]));
    ah[i] = lanes_a(a0.frame.half[i], a1.frame.half[i]);
    bh[i] = lanes_b(b0.frame.half[i], b1.frame.half[i]);
  }
  __m256d r[3][3], t[3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r[i][j] = dot3(ax[i][0], ax[i][1], ax[i][2], bx[j][0], bx[j][1], bx[j][2]);
    t[i] = dot3(ax[i][0], ax[i][1], ax[i][2], d[0], d[1], d[2]);
  }
  // As the scalar's std::max(boxes, apart): the boxes' bound where they are equal or apart is NaN.
  _mm256_storeu_pd(out, _mm256_max_pd(frames_apart(k, r, t, ah, bh), boxes));
}

#undef CALIBER_AVX2

/// The same bound built for AVX-512VL as well: the same operations on the same lanes
/// (-ffp-contract=off fuses none), with 32 vector registers, where frames_apart's values fit.
__attribute__((target("avx2,avx512f,avx512vl"), flatten)) void gaps_2x2_avx512vl(const BoundConstants& k, const NearA& a0,
                                                                                 const NearA& a1, const NearB& b0,
                                                                                 const NearB& b1, double reach, double out[4]) {
  gaps_2x2(k, a0, a1, b0, b1, reach, out);
}

}  // namespace

Gaps2x2 gaps_2x2_form(bool wide_registers) {
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) return nullptr;
  if (!wide_registers) return &gaps_2x2;
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? &gaps_2x2_avx512vl : nullptr;
}

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
Gaps2x2 gaps_2x2_form(bool) { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
