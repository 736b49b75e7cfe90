#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cstdint>

#include "geometry/lanes_avx2.h"

namespace caliber::geometry {

// The triangle kernel on a batch's pairs four at a time, one pair per AVX2 lane (x86-64, chosen at
// run time where the CPU has AVX2 but not AVX-512F): the AVX-512 batch kernel
// (triangle_distance_avx512.cpp) with its masks as vector masks, each operation the same, so each
// lane's bits are the portable kernel's (its header says why its two shortcuts, one division per
// case and the square roots only where the squared distances are too close to order them, keep
// them). tests/geometry/triangle_distance_test.cpp compares this form with the 2a20389 kernel bit
// for bit on 200,000 pairs of every kind.
namespace {

using namespace lanes4;

#define CALIBER_AVX2 __attribute__((target("avx2")))

using D = __m256d;

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
CALIBER_AVX2 inline Pack3 cross(const Pack3& u, const Pack3& v) {
  return {sub(mul(u.y, v.z), mul(u.z, v.y)), sub(mul(u.z, v.x), mul(u.x, v.z)), sub(mul(u.x, v.y), mul(u.y, v.x))};
}

/// lanes8::Triangle8 for half `half` of a batch's triangles of one side: the same values.
struct Triangle4x {
  Pack3 v[3], e[3];
  D len2[3];
  Pack3 ab, ac, normal;
  M solid;

  CALIBER_AVX2 Triangle4x(const double (&c)[3][3][TriangleBatch::kLanes], int half) {
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

/// The AVX-512 form's Best: the nearest pair so far, lane by lane.
struct Best {
  Pack3 p, q;
  D d2;

  CALIBER_AVX2 void consider(const Pack3& np, const Pack3& nq, M offered) {
    const Pack3 pq = nq - np;
    const D nd2 = dot(pq, pq);
    const M lower = lt(nd2, d2) & offered;
    M take = lower & lt(nd2, mul(d2, all_lanes(0x1.ffffffffffffcp-1))) & ge(d2, all_lanes(0x1p-1000));
    const M unsure = lower & ~take;
    if (bits(unsure) != 0) take = take | (unsure & lt(_mm256_sqrt_pd(nd2), _mm256_sqrt_pd(d2)));
    p = pick(take, np, p);
    q = pick(take, nq, q);
    d2 = pick(take, nd2, d2);
  }
};

CALIBER_AVX2 inline M every_lane() { return _mm256_castsi256_pd(_mm256_set1_epi64x(-1)); }

/// consider_edges of the AVX-512 form (its header gives the divisions' cases).
CALIBER_AVX2 void consider_edges(const Pack3& p1, const Pack3& d1, D a, const Pack3& p2, const Pack3& d2, D e, Best& best) {
  const D zero = _mm256_setzero_pd(), one = all_lanes(1.0);
  const Pack3 r = p1 - p2;
  const D f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
  const M a_pos = gt(a, zero), e_pos = gt(e, zero);
  const D denom = sub(mul(a, e), mul(b, b));
  const D s_general = keep(gt(denom, zero), clamp01x4(div(sub(mul(b, f), mul(c, e)), denom)));
  const D x = add(mul(b, s_general), f);
  const M normal_e = ge(e, all_lanes(0x1p-1000));
  M inside = normal_e & ge(x, zero) & lt(x, mul(e, all_lanes(0x1.ffffffffffffcp-1)));
  M above = normal_e & gt(x, mul(e, all_lanes(0x1.0000000000004p+0)));
  M below = ge(e, all_lanes(0x1p-100)) & lt(x, mul(e, all_lanes(-0x1p-900)));
  const D neg_c = negate(c), b_c = sub(b, c);
  D t_general, at_end;
  if (bits(e_pos & ~(inside | above | below)) == 0) {
    const D q = div(pick(inside, x, pick(below | ~e_pos, neg_c, b_c)), pick(inside, e, a));
    t_general = q;
    at_end = clamp01x4(q);
  } else {
    t_general = div(x, e);
    below = lt(t_general, zero);
    above = gt(t_general, one);
    inside = e_pos & ~(below | above);
    at_end = clamp01x4(div(pick(below | ~e_pos, neg_c, b_c), a));
  }
  D s = pick(inside, s_general, at_end);
  D t = keep(e_pos, clamp01x4(pick(below, zero, pick(above, one, t_general))));
  s = keep(a_pos, s);
  if (bits(a_pos) != 0xF) t = pick(a_pos, t, keep(e_pos, clamp01x4(div(f, e))));
  best.consider(p1 + s * d1, p2 + t * d2, every_lane());
}

CALIBER_AVX2 Pack3 closest_point_on_segment(const Pack3& x, const Pack3& p, const Pack3& q, D& dist2) {
  const Pack3 d = q - p;
  const D len2 = dot(d, d);
  const Pack3 y = pick(gt(len2, _mm256_setzero_pd()), p + clamp01x4(div(dot(x - p, d), len2)) * d, p);
  dist2 = dot(y - x, y - x);
  return y;
}

CALIBER_AVX2 Pack3 nearest_edge_point(const Pack3& x, const Triangle4x& t) {
  D best_d, d;
  Pack3 y = closest_point_on_segment(x, t.v[0], t.v[1], best_d);
  Pack3 e = closest_point_on_segment(x, t.v[1], t.v[2], d);
  const M closer_bc = lt(d, best_d);
  y = pick(closer_bc, e, y);
  best_d = pick(closer_bc, d, best_d);
  e = closest_point_on_segment(x, t.v[2], t.v[0], d);
  return pick(lt(d, best_d), e, y);
}

/// closest_point_on_triangle of the AVX-512 form: the regions in the portable order, one division.
CALIBER_AVX2 __attribute__((always_inline)) inline Pack3 closest_point_on_triangle(const Pack3& x, const Triangle4x& t) {
  const D zero = _mm256_setzero_pd(), one = all_lanes(1.0);
  const Pack3 &a = t.v[0], &b = t.v[1], &c = t.v[2];
  const Pack3 ax = x - a, bx = x - b, cx = x - c;
  const D d1 = dot(t.ab, ax), d2 = dot(t.ac, ax);
  const D d3 = dot(t.ab, bx), d4 = dot(t.ac, bx);
  const D d5 = dot(t.ab, cx), d6 = dot(t.ac, cx);
  const D vc = sub(mul(d1, d4), mul(d3, d2));
  const D vb = sub(mul(d5, d2), mul(d1, d6));
  const D va = sub(mul(d3, d6), mul(d5, d4));
  const D d1_d3 = sub(d1, d3), d2_d6 = sub(d2, d6), d4_d3 = sub(d4, d3), d5_d6 = sub(d5, d6);
  const D bc_sum = add(d4_d3, d5_d6);
  const D vsum = add(add(va, vb), vc);

  M taken = le(d1, zero) & le(d2, zero);  // corner a
  const M in_b = ge(d3, zero) & le(d4, d3) & ~taken;
  taken = taken | in_b;
  const M in_ab = le(vc, zero) & ge(d1, zero) & le(d3, zero) & gt(d1_d3, zero) & ~taken;
  taken = taken | in_ab;
  const M in_c = ge(d6, zero) & le(d5, d6) & ~taken;
  taken = taken | in_c;
  const M in_ac = le(vb, zero) & ge(d2, zero) & le(d6, zero) & gt(d2_d6, zero) & ~taken;
  taken = taken | in_ac;
  const M in_bc = le(va, zero) & ge(d4_d3, zero) & ge(d5_d6, zero) & gt(bc_sum, zero) & ~taken;
  taken = taken | in_bc;
  const D q = div(pick(in_ab, d1, pick(in_ac, d2, pick(in_bc, d4_d3, one))),
                  pick(in_ab, d1_d3, pick(in_ac, d2_d6, pick(in_bc, bc_sum, vsum))));
  const D v = mul(vb, q), w = mul(vc, q);
  const M in_face =
      ge(va, zero) & ge(vb, zero) & ge(vc, zero) & gt(vsum, zero) & ge(v, zero) & ge(w, zero) & le(add(v, w), one) & ~taken;
  const M settled = t.solid & (taken | in_face);

  // The region's point with the scalar's operations, each sum only in its lanes.
  const M on_edge = in_ab | in_ac | in_bc;
  const Pack3 base = pick(in_b | in_bc, b, pick(in_c, c, a));
  const Pack3 along = pick(in_ac, t.ac, pick(in_bc, c - b, t.ab));
  const Pack3 first = pick(on_edge | in_face, base + pick(in_face, v, q) * along, base);
  const Pack3 y = pick(in_face, first + w * t.ac, first);
  if (bits(settled) == 0xF) return y;
  return pick(settled, y, nearest_edge_point(x, t));
}

CALIBER_AVX2 inline M crossing(D sp, D sq) {
  const D zero = _mm256_setzero_pd();
  return ~((gt(sp, zero) & gt(sq, zero)) | (lt(sp, zero) & lt(sq, zero)) | _mm256_cmp_pd(sp, sq, _CMP_EQ_OQ));
}

CALIBER_AVX2 void batch_half(const TriangleBatch& batch, int half, ClosestPointsBatch& out) {
  const Triangle4x ta(batch.a, half), tb(batch.b, half);
  Best best{ta.v[0], tb.v[0], _mm256_setzero_pd()};
  {
    const Pack3 pq = tb.v[0] - ta.v[0];
    best.d2 = dot(pq, pq);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) consider_edges(ta.v[i], ta.e[i], ta.len2[i], tb.v[j], tb.e[j], tb.len2[j], best);
  }
  for (int i = 0; i < 3; ++i) {
    best.consider(ta.v[i], closest_point_on_triangle(ta.v[i], tb), every_lane());
    best.consider(closest_point_on_triangle(tb.v[i], ta), tb.v[i], every_lane());
  }
  D sa[3], sb[3];
  for (int i = 0; i < 3; ++i) {
    sa[i] = dot(tb.normal, ta.v[i] - tb.v[0]);
    sb[i] = dot(ta.normal, tb.v[i] - ta.v[0]);
  }
  for (int i = 0; i < 3; ++i) {
    const int k = (i + 1) % 3;
    if (const M m = crossing(sa[i], sa[k]); bits(m) != 0) {
      const Pack3 x = ta.v[i] + clamp01x4(div(sa[i], sub(sa[i], sa[k]))) * ta.e[i];
      best.consider(x, closest_point_on_triangle(x, tb), m);
    }
    if (const M m = crossing(sb[i], sb[k]); bits(m) != 0) {
      const Pack3 x = tb.v[i] + clamp01x4(div(sb[i], sub(sb[i], sb[k]))) * tb.e[i];
      best.consider(closest_point_on_triangle(x, ta), x, m);
    }
  }
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
