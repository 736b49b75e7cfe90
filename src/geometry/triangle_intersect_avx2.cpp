#include "geometry/triangle_intersect.h"

#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include "geometry/lanes_avx2.h"

namespace caliber::geometry {

// triangles_intersect on eight pairs, four AVX2 lanes at a time (x86-64, chosen at run time where
// the CPU has AVX2 and not AVX-512F): the filters of triangle_intersect_avx512.cpp, a lane mask
// being a vector of all-ones or all-zero doubles. The plane signs (s = n . (p0 - q), trusted where
// s^2 > 1e-26 |u|^2 |v|^2 |w|^2), then, where each plane cuts the other triangle, Guigue and
// Devillers' two orientations, each trusted where orient3d's filter trusts it. A lane no filter
// decides goes to triangles_intersect itself, so every verdict is triangles_intersect's.
namespace {

using namespace lanes4;

#define CALIBER_AVX2 __attribute__((target("avx2")))

using D = __m256d;

CALIBER_AVX2 inline D add(D u, D v) { return _mm256_add_pd(u, v); }
CALIBER_AVX2 inline D sub(D u, D v) { return _mm256_sub_pd(u, v); }
CALIBER_AVX2 inline D mul(D u, D v) { return _mm256_mul_pd(u, v); }
CALIBER_AVX2 inline D both(D u, D v) { return _mm256_and_pd(u, v); }
CALIBER_AVX2 inline D either(D u, D v) { return _mm256_or_pd(u, v); }
/// u and not v.
CALIBER_AVX2 inline D but_not(D u, D v) { return _mm256_andnot_pd(v, u); }
CALIBER_AVX2 inline D none() { return _mm256_setzero_pd(); }
/// The lanes where u and v agree (both set or both clear).
CALIBER_AVX2 inline D agree(D u, D v) { return _mm256_xor_pd(_mm256_xor_pd(u, v), _mm256_castsi256_pd(_mm256_set1_epi64x(-1))); }
/// The plane of triangle p against q's corners: `pos` and `neg` the lanes where the sign of
/// corner i is trusted positive or negative.
struct PlaneSigns {
  D pos[3], neg[3];
};

CALIBER_AVX2 inline PlaneSigns plane_signs(const Pack3 p[3], const Pack3 q[3]) {
  const Pack3 u = p[1] - p[0], v = p[2] - p[0];
  const Pack3 n = cross(u, v);
  const D uv2 = mul(dot(u, u), dot(v, v));
  PlaneSigns s;
  for (int i = 0; i < 3; ++i) {
    const Pack3 w = p[0] - q[i];
    const D side = dot(n, w);
    const D trusted = gt(mul(side, side), mul(mul(_mm256_set1_pd(1e-26), uv2), dot(w, w)));
    s.pos[i] = both(trusted, gt(side, none()));
    s.neg[i] = both(trusted, lt(side, none()));
  }
  return s;
}

/// orient3d's filter (predicates.cpp, the same expression): `pos` and `neg` the lanes where the
/// sign is trusted positive or negative.
CALIBER_AVX2 inline void orient3d_filtered(const Pack3& a, const Pack3& b, const Pack3& c, const Pack3& d, D& pos, D& neg) {
  const Pack3 ad = a - d, bd = b - d, cd = c - d;
  const D bdxcdy = mul(bd.x, cd.y), cdxbdy = mul(cd.x, bd.y);
  const D cdxady = mul(cd.x, ad.y), adxcdy = mul(ad.x, cd.y);
  const D adxbdy = mul(ad.x, bd.y), bdxady = mul(bd.x, ad.y);
  const D det = add(add(mul(ad.z, sub(bdxcdy, cdxbdy)), mul(bd.z, sub(cdxady, adxcdy))), mul(cd.z, sub(adxbdy, bdxady)));
  const D permanent = add(add(mul(add(magnitude(bdxcdy), magnitude(cdxbdy)), magnitude(ad.z)),
                              mul(add(magnitude(cdxady), magnitude(adxcdy)), magnitude(bd.z))),
                          mul(add(magnitude(adxbdy), magnitude(bdxady)), magnitude(cd.z)));
  const D bound = mul(_mm256_set1_pd((7.0 + 56.0 * 0x1p-53) * 0x1p-53), permanent);
  pos = gt(det, bound);
  neg = gt(negate(det), bound);
}

/// The lone corner of three nonzero signs not all equal (lone() in triangle_intersect.cpp: 2
/// where the first two agree, else 1 where the first and last agree, else 0), as three lane masks.
struct Lone {
  D at[3];
};
CALIBER_AVX2 inline Lone lone(const D pos[3]) {
  const D first_two = agree(pos[0], pos[1]);
  const D first_last = agree(pos[0], pos[2]);
  return {{but_not(but_not(_mm256_castsi256_pd(_mm256_set1_epi64x(-1)), first_two), first_last), but_not(first_last, first_two),
           first_two}};
}

/// x[k] where `which` has lane k, of three (the masks partition the lanes).
CALIBER_AVX2 inline Pack3 take(const Lone& which, const Pack3& x0, const Pack3& x1, const Pack3& x2) {
  return pick(which.at[0], x0, pick(which.at[1], x1, x2));
}
CALIBER_AVX2 inline D take(const Lone& which, D x0, D x1, D x2) {
  return either(either(both(which.at[0], x0), both(which.at[1], x1)), both(which.at[2], x2));
}

/// planes_cross_meet per lane, where every sign is nonzero and each plane cuts the other
/// triangle (pa, pb: the lanes where A's, B's corners are on the positive side): `meet` the lanes
/// where the triangles meet, `sure` those where both orientations were trusted.
CALIBER_AVX2 inline void planes_cross_meet(const Pack3 a[3], const Pack3 b[3], const D pa[3], const D pb[3], D& meet, D& sure) {
  // A turned so that its lone corner comes first.
  const Lone i = lone(pa);
  const Pack3 t1[3] = {take(i, a[0], a[1], a[2]), take(i, a[1], a[2], a[0]), take(i, a[2], a[0], a[1])};
  // B's order reversed where A's lone corner is on B's negative side.
  const D keep_b = take(i, pa[0], pa[1], pa[2]);
  const Pack3 t2[3] = {b[0], pick(keep_b, b[1], b[2]), pick(keep_b, b[2], b[1])};
  const D d2[3] = {pb[0], pick(keep_b, pb[1], pb[2]), pick(keep_b, pb[2], pb[1])};
  // B turned so that its lone corner comes first; A's other two swapped where it is negative.
  const Lone k = lone(d2);
  const Pack3 p2 = take(k, t2[0], t2[1], t2[2]), q2 = take(k, t2[1], t2[2], t2[0]), r2 = take(k, t2[2], t2[0], t2[1]);
  const D positive = take(k, d2[0], d2[1], d2[2]);
  const Pack3& p1 = t1[0];
  const Pack3 q1 = pick(positive, t1[1], t1[2]), r1 = pick(positive, t1[2], t1[1]);
  D pos1, neg1, pos2, neg2;
  orient3d_filtered(p1, q1, p2, q2, pos1, neg1);
  orient3d_filtered(p1, r1, r2, p2, pos2, neg2);
  // Both <= 0 meet; either > 0 does not; a sign trusted positive decides alone.
  meet = both(neg1, neg2);
  sure = either(either(both(either(pos1, neg1), either(pos2, neg2)), pos1), pos2);
}

/// Four lanes of the batch (4 half .. 4 half + 3): the lanes whose verdict the filters decided
/// (`decided`) and, of those, the ones that meet, as four bits each.
CALIBER_AVX2 inline void intersect_half(const TriangleBatch& batch, int half, unsigned& decided, unsigned& meets) {
  const Pack3 a[3] = {load_half(batch.a[0], half), load_half(batch.a[1], half), load_half(batch.a[2], half)};
  const Pack3 b[3] = {load_half(batch.b[0], half), load_half(batch.b[1], half), load_half(batch.b[2], half)};
  const PlaneSigns sa = plane_signs(b, a);  // A's corners against B's plane
  const PlaneSigns sb = plane_signs(a, b);  // B's corners against A's plane
  // One plane with the other triangle strictly on one side: apart.
  const D apart = either(either(both(both(sa.pos[0], sa.pos[1]), sa.pos[2]), both(both(sa.neg[0], sa.neg[1]), sa.neg[2])),
                         either(both(both(sb.pos[0], sb.pos[1]), sb.pos[2]), both(both(sb.neg[0], sb.neg[1]), sb.neg[2])));
  // Every sign trusted (so nonzero), each plane cutting the other triangle: two orientations.
  D trusted = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  for (int c = 0; c < 3; ++c) trusted = both(trusted, both(either(sa.pos[c], sa.neg[c]), either(sb.pos[c], sb.neg[c])));
  const D crossing = but_not(trusted, apart);
  D meet = none(), sure = none();
  if (_mm256_movemask_pd(crossing) != 0) planes_cross_meet(a, b, sa.pos, sb.pos, meet, sure);
  const D crossing_sure = both(crossing, sure);
  decided = static_cast<unsigned>(_mm256_movemask_pd(either(apart, crossing_sure)));
  meets = static_cast<unsigned>(_mm256_movemask_pd(both(crossing_sure, meet)));
}

CALIBER_AVX2 unsigned intersect_avx2(const TriangleBatch& batch) {
  unsigned decided = 0, out = 0;
  for (int half = 0; half < 2; ++half) {
    if (4 * half >= batch.size) break;
    unsigned d, m;
    intersect_half(batch, half, d, m);
    decided |= d << (4 * half);
    out |= m << (4 * half);
  }
  // The lanes no filter decided: triangles_intersect itself.
  const unsigned lanes = (1u << batch.size) - 1u;
  return (out | detail::triangles_intersect_lanes(batch, ~decided & lanes)) & lanes;
}

#undef CALIBER_AVX2

}  // namespace

namespace detail {

IntersectBatch triangles_intersect_batch_avx2_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? &intersect_avx2 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
IntersectBatch triangles_intersect_batch_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
