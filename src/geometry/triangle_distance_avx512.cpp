#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)

#include "geometry/lanes_avx512.h"

namespace caliber::geometry {

// The triangle kernel on eight pairs at once, one pair per AVX-512 lane (x86-64, chosen at run
// time where the CPU has AVX-512F). Each lane computes exactly what the portable kernel
// (triangle_distance.cpp) computes for its pair: the same feature pairs in the same order, each with
// the same IEEE operations (no FMA: this file is built with -ffp-contract=off and "avx512f" alone
// is enabled, not "fma"), every branch evaluated and the one the scalar code would take selected
// by masks; comparisons are the ordered, quiet ones (false on NaN, as in C++), and clamp01 is max
// then min in the operand order of the scalar's maxsd/minsd. Two things differ in how, not what:
//  - a lane that needs one of several divisions (the clamped parameter at either end of an edge,
//    or the point-on-triangle region's quotient) divides the operands its case divides, once;
//  - Nearest's square roots: a feature pair whose squared distance is below the best one's by a
//    relative 2^-50 has the smaller correctly rounded root too (the proof is at `consider`), so
//    the roots are taken only where that margin is missing, and for the winner at the end.
// tests/geometry/triangle_distance_test.cpp compares this form with the 2a20389 kernel bit for
// bit on 200,000 pairs of every kind (degenerate, coplanar, sharing corners, touching).
namespace {

using namespace lanes8;

#define CALIBER_AVX512 __attribute__((target("avx512f")))

/// kernel::Nearest, lane by lane: the best pair so far and its squared distance.
struct Best {
  P3 p, q;
  D d2;

  /// Offers (p, q) in the lanes of `offered`. The scalar takes a pair when d2 < best_d2 and
  /// sqrt(d2) < sqrt(best_d2) (its best.distance). Where d2 < fl((1 - 2^-50) best_d2) with best_d2
  /// >= 2^-1000 (normal, and so is the product), d2 < best_d2 (1 - 7 2^-53), so sqrt(d2) <
  /// sqrt(best_d2) (1 - 3.5 2^-53); rounded, sqrt(d2) gains at most a relative 2^-53 and
  /// sqrt(best_d2) loses at most that: the rounded roots stay strictly ordered, and the scalar
  /// would take the pair. Only the lanes without that margin compare the rounded roots.
  CALIBER_AVX512 void consider(const P3& np, const P3& nq, M offered = 0xFF) {
    const P3 pq = nq - np;
    const D nd2 = dot(pq, pq);
    const M lower = lt(nd2, d2) & offered;
    M take = lower & lt(nd2, mul(d2, all_lanes(0x1.ffffffffffffcp-1))) & ge(d2, all_lanes(0x1p-1000));
    if (const M unsure = lower & ~take) take |= unsure & lt(_mm512_sqrt_pd(nd2), _mm512_sqrt_pd(d2));
    p = pick(take, np, p);
    q = pick(take, nq, q);
    d2 = pick(take, nd2, d2);
  }
};

/// kernel::closest_points_edges per lane: every case computed, the branches' choice selected.
/// After s, the scalar divides t's numerator x = b s + f by e, then, where t falls outside [0, 1],
/// divides -c (below 0, or e not positive) or b - c (above 1) by a for s: two of its three
/// divisions in each lane. Where x alone settles which side t falls (below), a lane makes the one
/// it needs: with e >= 2^-1000, fl(e k) is within a relative 2^-53 of e k, so
///   0 <= x < fl(e (1 - 2^-50)): x / e in [0, 1), so fl(x / e) in [0, 1]: inside;
///   x > fl(e (1 + 2^-50)): x / e > 1 + 2^-53, so fl(x / e) > 1: above;
///   x < -e 2^-900 (e >= 2^-100, the product exact): fl(x / e) <= -2^-900 < 0: below.
/// Lanes none of these settle (x within a relative 2^-50 of 0 or e) make both divisions.
CALIBER_AVX512 void consider_edges(const P3& p1, const P3& d1, D a, const P3& p2, const P3& d2, D e, Best& best) {
  const D zero = _mm512_setzero_pd(), one = all_lanes(1.0);
  const P3 r = p1 - p2;
  const D f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
  const M a_pos = gt(a, zero), e_pos = gt(e, zero);
  // a > 0 and e > 0: the general case.
  const D denom = sub(mul(a, e), mul(b, b));
  const D s_general = _mm512_maskz_mov_pd(gt(denom, zero), clamp01(div(sub(mul(b, f), mul(c, e)), denom)));
  const D x = add(mul(b, s_general), f);
  const M normal_e = ge(e, all_lanes(0x1p-1000));
  M inside = normal_e & ge(x, zero) & lt(x, mul(e, all_lanes(0x1.ffffffffffffcp-1)));
  M above = normal_e & gt(x, mul(e, all_lanes(0x1.0000000000004p+0)));
  M below = ge(e, all_lanes(0x1p-100)) & lt(x, mul(e, all_lanes(-0x1p-900)));
  // Where t falls below 0, or e is not positive, s is clamp01(-c / a); above 1, clamp01((b - c) / a).
  const D neg_c = negate(c), b_c = sub(b, c);
  D t_general, at_end;
  if ((e_pos & ~(inside | above | below)) == 0) {
    const D q = div(pick(inside, x, pick(below | static_cast<M>(~e_pos), neg_c, b_c)), pick(inside, e, a));
    t_general = q;
    at_end = clamp01(q);
  } else {
    t_general = div(x, e);
    below = lt(t_general, zero);
    above = gt(t_general, one);
    inside = e_pos & ~(below | above);
    at_end = clamp01(div(pick(below | static_cast<M>(~e_pos), neg_c, b_c), a));
  }
  D s = pick(inside, s_general, at_end);
  D t = _mm512_maskz_mov_pd(e_pos, clamp01(pick(below, zero, pick(above, one, t_general))));
  // a not positive: s = 0, and t = clamp01(f / e) where e is positive (0 where neither is).
  s = _mm512_maskz_mov_pd(a_pos, s);
  if (a_pos != 0xFF) t = pick(a_pos, t, _mm512_maskz_mov_pd(e_pos, clamp01(div(f, e))));
  best.consider(p1 + s * d1, p2 + t * d2);
}

/// closest_point_on_segment per lane, and the squared distance to x.
CALIBER_AVX512 P3 closest_point_on_segment(const P3& x, const P3& p, const P3& q, D& dist2) {
  const P3 d = q - p;
  const D len2 = dot(d, d);
  const P3 y = pick(gt(len2, _mm512_setzero_pd()), p + clamp01(div(dot(x - p, d), len2)) * d, p);
  dist2 = dot(y - x, y - x);
  return y;
}

/// The nearest of the three edge points: closest_point_on_frame's fallback.
CALIBER_AVX512 P3 nearest_edge_point(const P3& x, const Triangle8& t) {
  D best_d, d;
  P3 y = closest_point_on_segment(x, t.v[0], t.v[1], best_d);
  P3 e = closest_point_on_segment(x, t.v[1], t.v[2], d);
  const M closer_bc = lt(d, best_d);
  y = pick(closer_bc, e, y);
  best_d = pick(closer_bc, d, best_d);
  e = closest_point_on_segment(x, t.v[2], t.v[0], d);
  return pick(lt(d, best_d), e, y);
}

/// kernel::closest_point_on_frame per lane: its regions in its order, the first that holds wins;
/// the nearest edge point where none does or the triangle is not solid. Of the quotients the
/// regions divide, each lane needs at most one: the first region's that holds, else the face's.
CALIBER_AVX512 __attribute__((always_inline)) inline P3 closest_point_on_triangle(const P3& x, const Triangle8& t) {
  const D zero = _mm512_setzero_pd(), one = all_lanes(1.0);
  const P3 &a = t.v[0], &b = t.v[1], &c = t.v[2];
  const P3 ax = x - a, bx = x - b, cx = x - c;
  const D d1 = dot(t.ab, ax), d2 = dot(t.ac, ax);
  const D d3 = dot(t.ab, bx), d4 = dot(t.ac, bx);
  const D d5 = dot(t.ab, cx), d6 = dot(t.ac, cx);
  const D vc = sub(mul(d1, d4), mul(d3, d2));
  const D vb = sub(mul(d5, d2), mul(d1, d6));
  const D va = sub(mul(d3, d6), mul(d5, d4));
  const D d1_d3 = sub(d1, d3), d2_d6 = sub(d2, d6), d4_d3 = sub(d4, d3), d5_d6 = sub(d5, d6);
  const D bc_sum = add(d4_d3, d5_d6);
  const D vsum = add(add(va, vb), vc);

  // Each region's lanes, less those of the regions before it.
  M taken = le(d1, zero) & le(d2, zero);  // corner a
  const M in_b = ge(d3, zero) & le(d4, d3) & ~taken;
  taken |= in_b;
  const M in_ab = le(vc, zero) & ge(d1, zero) & le(d3, zero) & gt(d1_d3, zero) & ~taken;
  taken |= in_ab;
  const M in_c = ge(d6, zero) & le(d5, d6) & ~taken;
  taken |= in_c;
  const M in_ac = le(vb, zero) & ge(d2, zero) & le(d6, zero) & gt(d2_d6, zero) & ~taken;
  taken |= in_ac;
  const M in_bc = le(va, zero) & ge(d4_d3, zero) & ge(d5_d6, zero) & gt(bc_sum, zero) & ~taken;
  taken |= in_bc;
  // The quotient: d1 / (d1 - d3) on ab, d2 / (d2 - d6) on ac, (d4 - d3) / (...) on bc, and the
  // face's 1 / (va + vb + vc) elsewhere.
  const D q = div(pick(in_ab, d1, pick(in_ac, d2, pick(in_bc, d4_d3, one))),
                  pick(in_ab, d1_d3, pick(in_ac, d2_d6, pick(in_bc, bc_sum, vsum))));
  const D v = mul(vb, q), w = mul(vc, q);
  const M in_face =
      ge(va, zero) & ge(vb, zero) & ge(vc, zero) & gt(vsum, zero) & ge(v, zero) & ge(w, zero) & le(add(v, w), one) & ~taken;
  const M settled = t.solid & (taken | in_face);

  // The region's point with the scalar's operations: a corner; a + q ab, a + q ac or b + q (c - b)
  // on an edge; (a + v ab) + w ac on the face (each sum only in its lanes, so that no other lane
  // gains a signed zero).
  const M on_edge = in_ab | in_ac | in_bc;
  const P3 base = pick(in_b | in_bc, b, pick(in_c, c, a));
  const P3 along = pick(in_ac, t.ac, pick(in_bc, c - b, t.ab));
  const P3 step = pick(in_face, v, q) * along;
  const P3 first{_mm512_mask_add_pd(base.x, on_edge | in_face, base.x, step.x),
                 _mm512_mask_add_pd(base.y, on_edge | in_face, base.y, step.y),
                 _mm512_mask_add_pd(base.z, on_edge | in_face, base.z, step.z)};
  const P3 rest = w * t.ac;
  const P3 y{_mm512_mask_add_pd(first.x, in_face, first.x, rest.x), _mm512_mask_add_pd(first.y, in_face, first.y, rest.y),
             _mm512_mask_add_pd(first.z, in_face, first.z, rest.z)};
  if (settled == 0xFF) return y;
  return pick(settled, y, nearest_edge_point(x, t));
}

/// crossing_point's verdict per lane for the edge whose ends lie sp and sq along the other's
/// normal: the lanes where it crosses the plane.
CALIBER_AVX512 inline M crossing(D sp, D sq) {
  const D zero = _mm512_setzero_pd();
  const M apart = (gt(sp, zero) & gt(sq, zero)) | (lt(sp, zero) & lt(sq, zero)) | _mm512_cmp_pd_mask(sp, sq, _CMP_EQ_OQ);
  return static_cast<M>(~apart);
}

CALIBER_AVX512 void batch_avx512(const TriangleBatch& batch, ClosestPointsBatch& out) {
  const Triangle8 ta(batch.a), tb(batch.b);
  Best best{ta.v[0], tb.v[0], _mm512_setzero_pd()};
  {
    const P3 pq = tb.v[0] - ta.v[0];
    best.d2 = dot(pq, pq);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) consider_edges(ta.v[i], ta.e[i], ta.len2[i], tb.v[j], tb.e[j], tb.len2[j], best);
  }
  for (int i = 0; i < 3; ++i) {
    best.consider(ta.v[i], closest_point_on_triangle(ta.v[i], tb));
    best.consider(closest_point_on_triangle(tb.v[i], ta), tb.v[i]);
  }
  // Edge-plane crossings: edge i of A against B's plane (through B's first corner), then edge i of
  // B against A's, where some lane crosses.
  D sa[3], sb[3];
  for (int i = 0; i < 3; ++i) {
    sa[i] = dot(tb.normal, ta.v[i] - tb.v[0]);
    sb[i] = dot(ta.normal, tb.v[i] - ta.v[0]);
  }
  for (int i = 0; i < 3; ++i) {
    const int k = (i + 1) % 3;
    if (const M m = crossing(sa[i], sa[k])) {
      const P3 x = ta.v[i] + clamp01(div(sa[i], sub(sa[i], sa[k]))) * ta.e[i];
      best.consider(x, closest_point_on_triangle(x, tb), m);
    }
    if (const M m = crossing(sb[i], sb[k])) {
      const P3 x = tb.v[i] + clamp01(div(sb[i], sub(sb[i], sb[k]))) * tb.e[i];
      best.consider(closest_point_on_triangle(x, ta), x, m);
    }
  }

  _mm512_store_pd(out.on_a[0], best.p.x);
  _mm512_store_pd(out.on_a[1], best.p.y);
  _mm512_store_pd(out.on_a[2], best.p.z);
  _mm512_store_pd(out.on_b[0], best.q.x);
  _mm512_store_pd(out.on_b[1], best.q.y);
  _mm512_store_pd(out.on_b[2], best.q.z);
  _mm512_store_pd(out.distance, _mm512_sqrt_pd(best.d2));
}

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
