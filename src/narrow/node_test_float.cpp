// The four-pair node test's float pre-decision (AVX2): node_within_2x2_lanes's comparisons (spheres,
// boxes, slabs, disks; node_test_avx2.cpp) made in float, each against two thresholds: the double
// form's less and plus a slack (FloatSlack) that bounds, with a wide margin, how far the float
// quantity lies from the double one. Past the upper threshold the double form surely refuses the
// pair; below the lower one, that comparison surely does not refuse it. A pair that no comparison
// surely refuses and some comparison may refuse is in doubt, and the whole visit goes to the
// double form: the decisions are the double form's, bit for bit (eight float lanes where it has
// four doubles: each test of A's side and of B's side in one instruction, no conversions).
//
// Why the slack holds: every value is a short sum of products of stored floats (exact in both),
// pose entries (|R| <= 1, each rounded once to float, -R^T T computed in double, then rounded)
// and coordinates at most the scale in magnitude (make_lanes). A moved center lies within about
// 40 unit roundoffs of the scale of the double one, a box gap within about 80, a slab's gap within
// about 160, a disk's gap (scaled by the squared length of its axis) within about 210, its
// squared sine (|m|^2 |n|^2 - (m . n)^2 here, the cross product there) within about 100 unit
// roundoffs. A's center along B's slab axis is taken in B's frame here (m . R^T (x - T)), in A's
// there ((R m) . (x - T)): the same number but for the pose's rounding, some 1e-16 of the scale.
// The slack is 512 unit roundoffs of the scale (1024 on the spheres' and the disks' gaps, 256 on
// the squared sine); squared comparisons move the threshold by the slack before squaring.

#include "narrow/node_test_avx2.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include "narrow/lanes8_avx2.h"

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2")))

using V = __m256;
using Q = __m128;

using namespace lanes8;
CALIBER_AVX2 inline V gt(V u, V v) { return _mm256_cmp_ps(u, v, _CMP_GT_OQ); }
CALIBER_AVX2 inline V dot3(const V u[3], const V v[3]) { return add(add(mul(u[0], v[0]), mul(u[1], v[1])), mul(u[2], v[2])); }
CALIBER_AVX2 inline Q dot3(const Q u[3], const Q v[3]) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(u[0], v[0]), _mm_mul_ps(u[1], v[1])), _mm_mul_ps(u[2], v[2]));
}
/// Eight lanes: lo's four, then hi's.
CALIBER_AVX2 inline V pair(Q lo, Q hi) { return _mm256_set_m128(hi, lo); }
/// Lane i of the result is lane idx[i] of x.
CALIBER_AVX2 inline V pick(V x, __m256i idx) { return _mm256_permutevar8x32_ps(x, idx); }
CALIBER_AVX2 inline __m256i lanes(int i0, int i1, int i2, int i3, int i4, int i5, int i6, int i7) {
  return _mm256_setr_epi32(i0, i1, i2, i3, i4, i5, i6, i7);
}
/// From node lanes (a0, a1, b0, b1): A's nodes in the pairs' lanes (a0 a0 a1 a1), B's (b0 b1 b0 b1).
CALIBER_AVX2 inline Q pairs_a(Q x) { return _mm_shuffle_ps(x, x, _MM_SHUFFLE(1, 1, 0, 0)); }
CALIBER_AVX2 inline Q pairs_b(Q x) { return _mm_shuffle_ps(x, x, _MM_SHUFFLE(3, 2, 3, 2)); }

/// Row k of one of NodeLanes' eight-lane matrices times x, (m[k][0] x0 + m[k][1] x1) + m[k][2] x2.
CALIBER_AVX2 inline V row(const float m[3][3][8], int k, const V x[3]) {
  return add(add(mul(_mm256_load_ps(m[k][0]), x[0]), mul(_mm256_load_ps(m[k][1]), x[1])), mul(_mm256_load_ps(m[k][2]), x[2]));
}

/// The floats 4 block .. 4 block + 3 of four records, a record per lane: out[i] holds float
/// 4 block + i of each.
template <class Record>
CALIBER_AVX2 inline void packed_block(const Record& r0, const Record& r1, const Record& r2, const Record& r3, int block,
                                      Q out[4]) {
  out[0] = _mm_loadu_ps(reinterpret_cast<const float*>(&r0) + 4 * block);
  out[1] = _mm_loadu_ps(reinterpret_cast<const float*>(&r1) + 4 * block);
  out[2] = _mm_loadu_ps(reinterpret_cast<const float*>(&r2) + 4 * block);
  out[3] = _mm_loadu_ps(reinterpret_cast<const float*>(&r3) + 4 * block);
  _MM_TRANSPOSE4_PS(out[0], out[1], out[2], out[3]);
}

/// What the comparisons found: per pair lane, surely apart by some comparison; maybe apart by
/// some comparison (as bit masks of eight lanes: A's side of pair k in lane k, B's in lane k + 4).
struct Verdict {
  V sure, maybe;
  CALIBER_AVX2 Verdict() : sure(_mm256_setzero_ps()), maybe(_mm256_setzero_ps()) {}
  CALIBER_AVX2 void compare(V value, V lo, V hi) {
    sure = either(sure, gt(value, hi));
    maybe = either(maybe, gt(value, lo));
  }
  /// The same where `can` is set: elsewhere the double form cannot refuse by this comparison.
  CALIBER_AVX2 void compare_where(V can, V value, V lo, V hi) {
    sure = either(sure, gt(value, hi));
    maybe = either(maybe, both(can, gt(value, lo)));
  }
};

/// The disks' comparison on one side of the slab (gap: the disk's distance beyond it, scaled by
/// the squared axis length): beyond when gap > 0 and gap^2 > rim2, the double form's test; only
/// where `can` (the slab's node has an axis: without one, every term of the double form's gap is
/// 0 but -slab_reach |m|^2, which never refuses).
CALIBER_AVX2 inline void compare_disk(Verdict& v, V can, V gap, V slack, V rim_lo, V rim_hi) {
  const V zero = _mm256_setzero_ps();
  const V low = sub(gap, slack), high = add(gap, slack);
  v.sure = either(v.sure, both(gt(low, zero), gt(mul(low, low), rim_hi)));
  v.maybe = either(v.maybe, both(can, both(gt(high, zero), gt(mul(high, high), rim_lo))));
}

/// The disks, from what float_bits gathered: at, each disk's center along the other's slab axis
/// (lanes 0-3: A's axis dotted with B's center moved in; 4-7: B's axis with A's center moved into
/// B's frame); along and nn per pair (A's axis dotted with B's moved into A's frame, and the
/// latter's squared length); [slab lo | slab hi], [disk lo | disk hi], [radius | len2] per node;
/// `can`: where the slab's node has an axis.
CALIBER_AVX2 __attribute__((always_inline)) inline void compare_disks(Verdict& v, const NodeLanes& l, V can, V at, Q along4, Q nn,
                                                                      V bounds, V disk, V shape) {
  const __m256i own_i = lanes(0, 0, 1, 1, 2, 3, 2, 3), axis_i = lanes(4, 4, 5, 5, 6, 7, 6, 7);
  const __m256i disk_i = lanes(2, 3, 2, 3, 0, 0, 1, 1), disk_hi_i = lanes(6, 7, 6, 7, 4, 4, 5, 5);
  // |m x n|^2 = |m|^2 |n|^2 - (m . n)^2 (m: A's axis, its len2 in the pair's lanes).
  const Q len2_a = pairs_a(_mm256_extractf128_ps(shape, 1));
  const Q cross4 = _mm_sub_ps(_mm_mul_ps(len2_a, nn), _mm_mul_ps(along4, along4));
  const V along = pair(along4, along4), cross = pair(cross4, cross4);
  const V len8 = pick(shape, disk_hi_i), r = pick(shape, disk_i);
  const V s0 = mul(pick(disk, disk_i), along), s1 = mul(pick(disk, disk_hi_i), along);
  const V at2 = mul(at, len8);
  const V low = add(at2, _mm256_min_ps(s0, s1)), high = add(at2, _mm256_max_ps(s0, s1));
  const V slab = _mm256_set1_ps(l.slab), cross_slack = _mm256_set1_ps(l.cross_slack);
  const V rim = mul(mul(r, r), len8);
  const V rim_lo = mul(rim, sub(cross, cross_slack)), rim_hi = mul(rim, add(cross, cross_slack));
  const V slack = mul(_mm256_set1_ps(l.disk_slack), len8);
  const V lo = pick(bounds, own_i), hi = pick(bounds, axis_i);  // the other's slab
  compare_disk(v, can, sub(low, mul(add(hi, slab), len8)), slack, rim_lo, rim_hi);
  compare_disk(v, can, sub(mul(sub(lo, slab), len8), high), slack, rim_lo, rim_hi);
}

/// The spheres (four pair lanes): the distance of the centers against the summed radii and reach,
/// moved by twice the slack before squaring (lo * |lo|: a negative lower threshold is below any
/// squared distance). Sets bits of sure and maybe.
CALIBER_AVX2 inline void compare_spheres(const NodeLanes& l, Q dist2, Q radius, int& sure, int& maybe) {
  const Q radii = _mm_add_ps(pairs_a(radius), pairs_b(radius));
  const Q s_hi = _mm_add_ps(radii, _mm_set1_ps(l.sphere_hi)), s_lo = _mm_add_ps(radii, _mm_set1_ps(l.sphere_lo));
  const Q s_lo2 = _mm_mul_ps(s_lo, _mm_andnot_ps(_mm_set1_ps(-0.0f), s_lo));
  sure = _mm_movemask_ps(_mm_cmpgt_ps(dist2, _mm_mul_ps(s_hi, s_hi)));
  maybe = _mm_movemask_ps(_mm_cmpgt_ps(dist2, s_lo2));
}

/// The pre-decision. The nodes come in node lanes (a0, a1, b0, b1); [sphere center | box center]
/// is moved into the other's frame (A's: R^T x - R^T T, B's: R x + T) and [half-extents | slab
/// axis] turned ([reach_on | axis_in]) one coordinate k at a time, and each test takes its part
/// of coordinate k at once (so that few values live across the loop): the boxes' axis k in eight
/// lanes (A's in 0-3, B's in 4-7), the sums of the spheres', slabs' and disks' dot products.
CALIBER_AVX2 __attribute__((always_inline)) inline void float_bits(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0,
                                                                   std::uint32_t a1, std::uint32_t b0, std::uint32_t b1,
                                                                   int& pass, int& unsure) {
  const BvhNode &na0 = f.nodes_a[a0], &na1 = f.nodes_a[a1], &nb0 = f.nodes_b[b0], &nb1 = f.nodes_b[b1];
  const BvhNodeFilter &fa0 = f.filters_a[a0], &fa1 = f.filters_a[a1], &fb0 = f.filters_b[b0], &fb1 = f.filters_b[b1];
  Q n0[4], n1[4], n2[4], f0[4], f1[4];
  packed_block(na0, na1, nb0, nb1, 0, n0);  // center, radius
  packed_block(na0, na1, nb0, nb1, 1, n1);  // box center, half[0]
  packed_block(na0, na1, nb0, nb1, 2, n2);  // half[1], half[2]
  packed_block(fa0, fa1, fb0, fb1, 0, f0);  // cone axis
  packed_block(fa0, fa1, fb0, fb1, 1, f1);  // ..., slab lo, slab hi
  const Q half[3] = {n1[3], n2[0], n2[1]};
  V places[3], sizes[3];  // [center | box], [half | axis]
  for (int k = 0; k < 3; ++k) {
    places[k] = pair(n0[k], n1[k]);
    sizes[k] = pair(half[k], f0[k]);
  }
  const Q mid = dot3(f0, n0), len2 = dot3(f0, f0);
  const V bounds = pair(f1[2], f1[3]);                                  // [slab lo | slab hi]
  const V disk = pair(_mm_sub_ps(f1[2], mid), _mm_sub_ps(f1[3], mid));  // [disk lo | disk hi]
  const V shape = pair(n0[3], len2);                                    // [radius | len2]
  const __m256i from_i = lanes(6, 7, 6, 7, 2, 3, 2, 3), own_i = lanes(0, 0, 1, 1, 2, 3, 2, 3);
  const __m256i other_i = lanes(6, 7, 6, 7, 4, 4, 5, 5), axis_i = lanes(4, 4, 5, 5, 6, 7, 6, 7);
  const __m256i other_half_i = lanes(2, 3, 2, 3, 0, 0, 1, 1), center_i = lanes(2, 3, 2, 3, 0, 0, 1, 1);
  const V reach_lo = _mm256_set1_ps(l.reach_lo), reach_hi = _mm256_set1_ps(l.reach_hi), hair = _mm256_set1_ps(l.hair);
  Verdict v;
  V slab_at = _mm256_setzero_ps(), slab_reach = slab_at, disk_at = slab_at;
  Q dist2 = _mm_setzero_ps(), along = dist2, nn = dist2;
  for (int k = 0; k < 3; ++k) {
    const V moved = add(row(l.move, k, places), _mm256_load_ps(l.post8[k]));  // [center_in | box_in]
    const V turned = row(l.turn, k, sizes);                                   // [reach_on | axis_in]
    // Spheres: A's center less B's moved in.
    const Q d = _mm_sub_ps(pairs_a(n0[k]), pairs_b(_mm256_castps256_ps128(moved)));
    dist2 = _mm_add_ps(dist2, _mm_mul_ps(d, d));
    // Boxes, axis k: lanes 0-3 A's (B's box moved in, less A's), 4-7 B's (B's box less A's moved in).
    const V boxes = _mm256_permute2f128_ps(places[k], moved, 0x31);    // [box | box_in]
    const V extents = _mm256_permute2f128_ps(sizes[k], turned, 0x20);  // [half | reach_on]
    const V gap = sub(magnitude(sub(pick(boxes, from_i), _mm256_unpacklo_ps(boxes, boxes))),
                      add(pick(extents, own_i), pick(extents, other_i)));
    v.compare(gap, reach_lo, reach_hi);
    // Slabs: lanes 0-3 A's slab against B's box moved in, 4-7 B's against A's.
    const V axis = pick(sizes[k], axis_i);
    slab_at = add(slab_at, mul(axis, pick(boxes, other_i)));
    slab_reach = add(slab_reach, mul(pick(add(magnitude(turned), hair), axis_i), pick(sizes[k], other_half_i)));
    // Disks: lanes 0-3 A's axis against B's center moved in, 4-7 B's axis against A's.
    disk_at = add(disk_at, mul(axis, pick(moved, center_i)));
    const Q n = pairs_b(_mm256_extractf128_ps(turned, 1));
    along = _mm_add_ps(along, _mm_mul_ps(_mm256_castps256_ps128(axis), n));
    nn = _mm_add_ps(nn, _mm_mul_ps(n, n));
  }
  int sphere_sure, sphere_maybe;
  compare_spheres(l, dist2, n0[3], sphere_sure, sphere_maybe);
  const V lo = pick(bounds, own_i), hi = pick(bounds, axis_i);
  const V slab_lo = _mm256_set1_ps(l.slab_lo), slab_hi = _mm256_set1_ps(l.slab_hi);
  // A slab's node without an axis (every triangle below degenerate) refuses nothing in the double
  // form: its gaps are -hair times the other's half-extents, never above slab_reach (> 0).
  const V can = gt(pick(shape, axis_i), _mm256_setzero_ps());
  v.compare_where(can, sub(sub(slab_at, slab_reach), hi), slab_lo, slab_hi);
  v.compare_where(can, sub(lo, add(slab_at, slab_reach)), slab_lo, slab_hi);
  compare_disks(v, l, can, disk_at, along, nn, bounds, disk, shape);
  const int sure8 = _mm256_movemask_ps(v.sure), maybe8 = _mm256_movemask_ps(v.maybe);
  const int sure = (sure8 | (sure8 >> 4) | sphere_sure) & 0xF, maybe = (maybe8 | (maybe8 >> 4) | sphere_maybe) & 0xF;
  pass = ~maybe & 0xF;
  unsure = maybe & ~sure;
}

CALIBER_AVX2 int node_within_2x2_float(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                       std::uint32_t b0, std::uint32_t b1) {
  if (l.floats) {
    int pass, unsure;
    float_bits(f, l, a0, a1, b0, b1, pass, unsure);
    if (unsure == 0) return pass;
  }
  return node_within_2x2_double(f, l, a0, a1, b0, b1);
}

#undef CALIBER_AVX2

}  // namespace

__attribute__((target("avx2"))) void node_within_2x2_float_bits(const NodeTestFrame& frame, const NodeLanes& lanes,
                                                                std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                                                std::uint32_t b1, int& pass, int& unsure) {
  float_bits(frame, lanes, a0, a1, b0, b1, pass, unsure);
}

NodeWithin2x2 node_within_2x2_float_form() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? &node_within_2x2_float : nullptr;
}

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
void node_within_2x2_float_bits(const NodeTestFrame&, const NodeLanes&, std::uint32_t, std::uint32_t, std::uint32_t,
                                std::uint32_t, int& pass, int& unsure) {
  pass = 0;
  unsure = 0xF;
}
NodeWithin2x2 node_within_2x2_float_form() { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
