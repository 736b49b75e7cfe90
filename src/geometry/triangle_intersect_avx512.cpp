#include "geometry/triangle_intersect.h"

#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include "geometry/lanes_avx512.h"

namespace caliber::geometry {

// triangles_intersect on eight pairs at once, one pair per AVX-512 lane (x86-64, chosen at run
// time where the CPU has AVX-512F). Each lane takes triangles_intersect's steps with its filters:
// the plane signs (plane_signs: s = n . (p0 - q), trusted where s^2 > 1e-26 |u|^2 |v|^2 |w|^2),
// then, where each plane cuts the other triangle, Guigue and Devillers' two orientations
// (planes_cross_meet), each trusted where orient3d's filter trusts it (|det| above its error
// bound on the permanent). A lane with a sign no filter trusts (a corner on or near the other's
// plane, a degenerate triangle, an orientation near zero, NaN) goes to triangles_intersect
// itself. Every sign a lane uses is the exact one, so every verdict is triangles_intersect's.
namespace {

using namespace lanes8;

#define CALIBER_AVX512 __attribute__((target("avx512f")))

/// The plane of triangle p against q's corners (plane_signs): `pos` and `neg` the lanes where
/// the sign of corner i is trusted positive or negative.
struct PlaneSigns {
  M pos[3], neg[3];
};

CALIBER_AVX512 inline PlaneSigns plane_signs(const P3 p[3], const P3 q[3]) {
  const P3 u = p[1] - p[0], v = p[2] - p[0];
  const P3 n = cross(u, v);
  const D uv2 = mul(dot(u, u), dot(v, v));
  const D zero = _mm512_setzero_pd();
  PlaneSigns s;
  for (int i = 0; i < 3; ++i) {
    const P3 w = p[0] - q[i];
    const D side = dot(n, w);
    const M trusted = gt(mul(side, side), mul(mul(all_lanes(1e-26), uv2), dot(w, w)));
    s.pos[i] = trusted & gt(side, zero);
    s.neg[i] = trusted & lt(side, zero);
  }
  return s;
}

CALIBER_AVX512 inline D abs(D x) { return _mm512_abs_pd(x); }

/// orient3d's filter (predicates.cpp, the same expression): `pos` and `neg` the lanes where the
/// sign is trusted positive or negative.
CALIBER_AVX512 inline void orient3d_filtered(const P3& a, const P3& b, const P3& c, const P3& d, M& pos, M& neg) {
  const P3 ad = a - d, bd = b - d, cd = c - d;
  const D bdxcdy = mul(bd.x, cd.y), cdxbdy = mul(cd.x, bd.y);
  const D cdxady = mul(cd.x, ad.y), adxcdy = mul(ad.x, cd.y);
  const D adxbdy = mul(ad.x, bd.y), bdxady = mul(bd.x, ad.y);
  const D det = add(add(mul(ad.z, sub(bdxcdy, cdxbdy)), mul(bd.z, sub(cdxady, adxcdy))), mul(cd.z, sub(adxbdy, bdxady)));
  const D permanent = add(add(mul(add(abs(bdxcdy), abs(cdxbdy)), abs(ad.z)), mul(add(abs(cdxady), abs(adxcdy)), abs(bd.z))),
                          mul(add(abs(adxbdy), abs(bdxady)), abs(cd.z)));
  const D bound = mul(all_lanes((7.0 + 56.0 * 0x1p-53) * 0x1p-53), permanent);
  pos = gt(det, bound);
  neg = gt(negate(det), bound);
}

/// The lone corner of three nonzero signs not all equal (lone() in triangle_intersect.cpp: 2
/// where the first two agree, else 1 where the first and last agree, else 0), as three lane masks.
struct Lone {
  M at[3];
};
CALIBER_AVX512 inline Lone lone(const M pos[3]) {
  const M first_two = static_cast<M>(~(pos[0] ^ pos[1]));
  const M first_last = static_cast<M>(~(pos[0] ^ pos[2]));
  return {{static_cast<M>(~first_two & ~first_last), static_cast<M>(~first_two & first_last), first_two}};
}

/// x[k] where `which` has lane k, of three (the masks partition the lanes).
CALIBER_AVX512 inline P3 take(const Lone& which, const P3& x0, const P3& x1, const P3& x2) {
  return pick(which.at[0], x0, pick(which.at[1], x1, x2));
}
CALIBER_AVX512 inline M take(const Lone& which, M x0, M x1, M x2) {
  return static_cast<M>((which.at[0] & x0) | (which.at[1] & x1) | (which.at[2] & x2));
}

/// planes_cross_meet per lane, where every sign is nonzero and each plane cuts the other
/// triangle (pa, pb: the lanes where A's, B's corners are on the positive side): `meet` the lanes
/// where the triangles meet, `sure` those where both orientations were trusted.
CALIBER_AVX512 inline void planes_cross_meet(const P3 a[3], const P3 b[3], const M pa[3], const M pb[3], M& meet, M& sure) {
  // A turned so that its lone corner comes first.
  const Lone i = lone(pa);
  const P3 t1[3] = {take(i, a[0], a[1], a[2]), take(i, a[1], a[2], a[0]), take(i, a[2], a[0], a[1])};
  // B's order reversed where A's lone corner is on B's negative side.
  const M keep_b = take(i, pa[0], pa[1], pa[2]);
  const P3 t2[3] = {b[0], pick(keep_b, b[1], b[2]), pick(keep_b, b[2], b[1])};
  const M d2[3] = {pb[0], static_cast<M>((keep_b & pb[1]) | (~keep_b & pb[2])),
                   static_cast<M>((keep_b & pb[2]) | (~keep_b & pb[1]))};
  // B turned so that its lone corner comes first; A's other two swapped where it is negative.
  const Lone k = lone(d2);
  const P3 p2 = take(k, t2[0], t2[1], t2[2]), q2 = take(k, t2[1], t2[2], t2[0]), r2 = take(k, t2[2], t2[0], t2[1]);
  const M positive = take(k, d2[0], d2[1], d2[2]);
  const P3& p1 = t1[0];
  const P3 q1 = pick(positive, t1[1], t1[2]), r1 = pick(positive, t1[2], t1[1]);
  M pos1, neg1, pos2, neg2;
  orient3d_filtered(p1, q1, p2, q2, pos1, neg1);
  orient3d_filtered(p1, r1, r2, p2, pos2, neg2);
  // Both <= 0 meet; either > 0 does not; a sign trusted positive decides alone.
  meet = static_cast<M>(neg1 & neg2);
  sure = static_cast<M>((pos1 | neg1) & (pos2 | neg2)) | pos1 | pos2;
}

CALIBER_AVX512 unsigned intersect_avx512(const TriangleBatch& batch) {
  const P3 a[3] = {load(batch.a[0]), load(batch.a[1]), load(batch.a[2])};
  const P3 b[3] = {load(batch.b[0]), load(batch.b[1]), load(batch.b[2])};
  const PlaneSigns sa = plane_signs(b, a);  // A's corners against B's plane
  const PlaneSigns sb = plane_signs(a, b);  // B's corners against A's plane
  // One plane with the other triangle strictly on one side: apart.
  const M apart = static_cast<M>((sa.pos[0] & sa.pos[1] & sa.pos[2]) | (sa.neg[0] & sa.neg[1] & sa.neg[2]) |
                                 (sb.pos[0] & sb.pos[1] & sb.pos[2]) | (sb.neg[0] & sb.neg[1] & sb.neg[2]));
  // Every sign trusted (so nonzero), each plane cutting the other triangle: two orientations.
  M trusted = 0xFF;
  for (int c = 0; c < 3; ++c) trusted &= static_cast<M>((sa.pos[c] | sa.neg[c]) & (sb.pos[c] | sb.neg[c]));
  M meet = 0, sure = 0;
  if (static_cast<M>(trusted & ~apart) != 0) planes_cross_meet(a, b, sa.pos, sb.pos, meet, sure);
  const M crossing = static_cast<M>(trusted & ~apart);
  unsigned out = static_cast<unsigned>(crossing & sure & meet);
  // The lanes no filter decided: triangles_intersect itself.
  const unsigned lanes = (1u << batch.size) - 1u;
  return (out | detail::triangles_intersect_lanes(batch, static_cast<unsigned>(~apart & ~(crossing & sure)) & lanes)) & lanes;
}

#undef CALIBER_AVX512

}  // namespace

namespace detail {

IntersectBatch triangles_intersect_batch_avx512_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") ? &intersect_avx512 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
IntersectBatch triangles_intersect_batch_avx512_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
