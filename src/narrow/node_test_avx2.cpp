// The node test of a visit's child pairs, four at a time (AVX2, chosen at run time where the CPU has it):
// the same decisions as PairContext::node_within's geometry and disks_beyond_slabs on each pair
// (without the disks for a visit where one side descends), bit for bit.

#include "narrow/node_test_avx2.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cstddef>

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2")))

/// Lanes of the four node pairs (a0 b0, a0 b1, a1 b0, a1 b1): A's nodes a0 a0 a1 a1, B's b0 b1 b0 b1.
/// The records' floats come in blocks of four (a vector load of each record, then shuffles), each
/// float converted to double (exactly). The blocks' positions in BvhNode and BvhNodeFilter:
static_assert(offsetof(BvhNode, center) == 0 && offsetof(BvhNode, radius) == 12 && offsetof(BvhNode, box_center) == 16 &&
              offsetof(BvhNode, box_half) == 28 && sizeof(BvhNode) == 48);
static_assert(offsetof(BvhNodeFilter, cone_axis) == 0 && offsetof(BvhNodeFilter, slab_lo) == 24 &&
              offsetof(BvhNodeFilter, slab_hi) == 28);

/// Floats 4 block .. 4 block + 3 of two records, in A's lane order (r0 r0 r1 r1).
template <class Record>
CALIBER_AVX2 inline void block_a(const Record& r0, const Record& r1, int block, __m256d out[4]) {
  const __m128 x0 = _mm_loadu_ps(reinterpret_cast<const float*>(&r0) + 4 * block);
  const __m128 x1 = _mm_loadu_ps(reinterpret_cast<const float*>(&r1) + 4 * block);
  out[0] = _mm256_cvtps_pd(_mm_shuffle_ps(x0, x1, _MM_SHUFFLE(0, 0, 0, 0)));
  out[1] = _mm256_cvtps_pd(_mm_shuffle_ps(x0, x1, _MM_SHUFFLE(1, 1, 1, 1)));
  out[2] = _mm256_cvtps_pd(_mm_shuffle_ps(x0, x1, _MM_SHUFFLE(2, 2, 2, 2)));
  out[3] = _mm256_cvtps_pd(_mm_shuffle_ps(x0, x1, _MM_SHUFFLE(3, 3, 3, 3)));
}
/// The same in B's lane order (r0 r1 r0 r1).
template <class Record>
CALIBER_AVX2 inline void block_b(const Record& r0, const Record& r1, int block, __m256d out[4]) {
  const __m128 x0 = _mm_loadu_ps(reinterpret_cast<const float*>(&r0) + 4 * block);
  const __m128 x1 = _mm_loadu_ps(reinterpret_cast<const float*>(&r1) + 4 * block);
  const __m128 lo = _mm_unpacklo_ps(x0, x1), hi = _mm_unpackhi_ps(x0, x1);
  out[0] = _mm256_cvtps_pd(_mm_movelh_ps(lo, lo));
  out[1] = _mm256_cvtps_pd(_mm_movehl_ps(lo, lo));
  out[2] = _mm256_cvtps_pd(_mm_movelh_ps(hi, hi));
  out[3] = _mm256_cvtps_pd(_mm_movehl_ps(hi, hi));
}
/// A node's floats 0..11 (center, radius, box center, box half-extents; the last two are the
/// index and count, unused) and a filter's 0..7 (cone axis, angle, cos, sin, slab lo and hi).
template <bool kA, class Record>
CALIBER_AVX2 inline void blocks(const Record& r0, const Record& r1, int count, __m256d* out) {
  for (int b = 0; b < count; ++b) kA ? block_a(r0, r1, b, out + 4 * b) : block_b(r0, r1, b, out + 4 * b);
}

CALIBER_AVX2 inline __m256d add(__m256d u, __m256d v) { return _mm256_add_pd(u, v); }
CALIBER_AVX2 inline __m256d sub(__m256d u, __m256d v) { return _mm256_sub_pd(u, v); }
CALIBER_AVX2 inline __m256d mul(__m256d u, __m256d v) { return _mm256_mul_pd(u, v); }
CALIBER_AVX2 inline __m256d gt(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_GT_OQ); }
CALIBER_AVX2 inline __m256d lt(__m256d u, __m256d v) { return _mm256_cmp_pd(u, v, _CMP_LT_OQ); }
CALIBER_AVX2 inline __m256d either(__m256d u, __m256d v) { return _mm256_or_pd(u, v); }
CALIBER_AVX2 inline __m256d magnitude(__m256d u) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), u); }
/// (u0 v0 + u1 v1) + u2 v2, as the scalar dot products of the node test sum them.
CALIBER_AVX2 inline __m256d dot3(const __m256d u[3], const __m256d v[3]) {
  return add(add(mul(u[0], v[0]), mul(u[1], v[1])), mul(u[2], v[2]));
}
/// Row i of m (m[i][0], m[i][1], m[i][2]) dotted with v, m's entries the same in every lane.
CALIBER_AVX2 inline __m256d row_dot(const double m[3][3], int i, const __m256d v[3]) {
  return add(add(mul(_mm256_set1_pd(m[i][0]), v[0]), mul(_mm256_set1_pd(m[i][1]), v[1])), mul(_mm256_set1_pd(m[i][2]), v[2]));
}
/// Column j of m dotted with v.
CALIBER_AVX2 inline __m256d column_dot(const double m[3][3], int j, const __m256d v[3]) {
  return add(add(mul(_mm256_set1_pd(m[0][j]), v[0]), mul(_mm256_set1_pd(m[1][j]), v[1])), mul(_mm256_set1_pd(m[2][j]), v[2]));
}

/// PairContext::box_beyond_slab in four lanes.
CALIBER_AVX2 inline __m256d beyond_slab(const __m256d axis[3], const __m256d on[3], __m256d lo, __m256d hi,
                                        const __m256d center[3], const __m256d half[3], __m256d slab_reach) {
  const __m256d at = dot3(axis, center);
  const __m256d reach = dot3(on, half);
  return either(gt(sub(at, reach), add(hi, slab_reach)), lt(add(at, reach), sub(lo, slab_reach)));
}

/// narrow::disk_beyond_slab (disks.h) in four lanes.
CALIBER_AVX2 inline __m256d disk_beyond_slab(__m256d at, __m256d disk_lo, __m256d disk_hi, __m256d along, __m256d r, __m256d len2,
                                             __m256d cross2, __m256d lo, __m256d hi, __m256d slab_reach) {
  const __m256d s0 = mul(disk_lo, along), s1 = mul(disk_hi, along);
  const __m256d at2 = mul(at, len2);
  const __m256d low = add(at2, _mm256_min_pd(s0, s1)), high = add(at2, _mm256_max_pd(s0, s1));
  const __m256d rim2 = mul(mul(mul(r, r), cross2), len2);
  const __m256d above = sub(low, mul(add(hi, slab_reach), len2)), below = sub(mul(sub(lo, slab_reach), len2), high);
  const __m256d zero = _mm256_setzero_pd();
  return either(_mm256_and_pd(gt(above, zero), gt(mul(above, above), rim2)),
                _mm256_and_pd(gt(below, zero), gt(mul(below, below), rim2)));
}

/// PairContext::prepare_a / prepare_b (with their disks) and node_within with disks_beyond_slabs
/// on the four node pairs, lane by lane the scalar code's operations in its order (fill_a, fill_b,
/// box_beyond_slab, disk_beyond_slab); without the disks (kDisks false), node_within alone.
/// Inlined into the forms below.
template <bool kDisks>
CALIBER_AVX2 __attribute__((always_inline)) inline int node_within_2x2_lanes(const NodeTestFrame& f, std::uint32_t a0,
                                                                             std::uint32_t a1, std::uint32_t b0,
                                                                             std::uint32_t b1) {
  const BvhNode &na0 = f.nodes_a[a0], &na1 = f.nodes_a[a1], &nb0 = f.nodes_b[b0], &nb1 = f.nodes_b[b1];
  const BvhNodeFilter &fa0 = f.filters_a[a0], &fa1 = f.filters_a[a1], &fb0 = f.filters_b[b0], &fb1 = f.filters_b[b1];
  const __m256d reach = _mm256_set1_pd(f.reach), slab_reach = _mm256_set1_pd(f.slab_reach);
  const __m256d hair = _mm256_set1_pd(f.hair);
  __m256d a_center[3], a_box[3], a_half[3], a_rel[3], a_axis[3], a_box_in_b[3], a_reach_on_b[3], a_slab_on_b[3];
  __m256d b_c[3], b_box[3], b_half[3], b_axis[3], b_center[3], b_box_in_a[3], b_reach_on_a[3], b_slab_on_a[3], b_axis_in_a[3];
  __m256d an[12], bn[12], af[8], bf[8];  // the records' floats, in lanes
  blocks<true>(na0, na1, 3, an);
  blocks<false>(nb0, nb1, 3, bn);
  blocks<true>(fa0, fa1, 2, af);
  blocks<false>(fb0, fb1, 2, bf);
  for (int k = 0; k < 3; ++k) {
    a_center[k] = an[k];
    a_box[k] = an[4 + k];
    a_half[k] = an[7 + k];
    a_rel[k] = sub(a_box[k], _mm256_set1_pd(f.trans[k]));
    a_axis[k] = af[k];
    b_c[k] = bn[k];
    b_box[k] = bn[4 + k];
    b_half[k] = bn[7 + k];
    b_axis[k] = bf[k];
  }
  for (int k = 0; k < 3; ++k) {
    // A's box seen from B: x_b = R^T (x_a - T); B's node brought into A's frame: R x_b + T.
    a_box_in_b[k] = column_dot(f.rot, k, a_rel);
    a_reach_on_b[k] = column_dot(f.abs_rot, k, a_half);
    a_slab_on_b[k] = add(magnitude(column_dot(f.rot, k, a_axis)), hair);
    const __m256d t = _mm256_set1_pd(f.trans[k]);
    b_center[k] = add(row_dot(f.rot, k, b_c), t);
    b_box_in_a[k] = add(row_dot(f.rot, k, b_box), t);
    b_reach_on_a[k] = row_dot(f.abs_rot, k, b_half);
    b_axis_in_a[k] = row_dot(f.rot, k, b_axis);
    b_slab_on_a[k] = add(magnitude(b_axis_in_a[k]), hair);
  }
  // Spheres: dist2 accumulates from 0 (0 + x is x), the radii summed before the reach is added.
  __m256d d[3];
  for (int k = 0; k < 3; ++k) d[k] = sub(a_center[k], b_center[k]);
  const __m256d dist2 = add(add(mul(d[0], d[0]), mul(d[1], d[1])), mul(d[2], d[2]));
  const __m256d spheres = add(add(an[3], bn[3]), reach);
  __m256d apart = gt(dist2, mul(spheres, spheres));
  for (int k = 0; k < 3; ++k) {  // A's axes, then B's
    apart = either(apart, gt(magnitude(sub(b_box_in_a[k], a_box[k])), add(add(a_half[k], b_reach_on_a[k]), reach)));
  }
  for (int k = 0; k < 3; ++k) {
    apart = either(apart, gt(magnitude(sub(b_box[k], a_box_in_b[k])), add(add(b_half[k], a_reach_on_b[k]), reach)));
  }
  const __m256d a_lo = af[6], a_hi = af[7];
  const __m256d b_lo = bf[6], b_hi = bf[7];
  apart = either(apart, beyond_slab(a_axis, a_slab_on_b, a_lo, a_hi, b_box_in_a, b_half, slab_reach));
  apart = either(apart, beyond_slab(b_axis, b_slab_on_a, b_lo, b_hi, a_box_in_b, a_half, slab_reach));
  if constexpr (!kDisks) return ~_mm256_movemask_pd(apart) & 0xF;
  // The disks (PairContext::prepare_disk_a, prepare_disk_b, narrow::disks_beyond_slabs).
  __m256d center_from_b[3];
  for (int k = 0; k < 3; ++k) center_from_b[k] = sub(a_center[k], _mm256_set1_pd(f.trans[k]));
  const __m256d a_mid = dot3(a_axis, a_center), b_mid = dot3(b_axis, b_c);
  const __m256d along = dot3(a_axis, b_axis_in_a);
  const __m256d x = sub(mul(a_axis[1], b_axis_in_a[2]), mul(a_axis[2], b_axis_in_a[1]));
  const __m256d y = sub(mul(a_axis[2], b_axis_in_a[0]), mul(a_axis[0], b_axis_in_a[2]));
  const __m256d z = sub(mul(a_axis[0], b_axis_in_a[1]), mul(a_axis[1], b_axis_in_a[0]));
  const __m256d cross2 = add(add(mul(x, x), mul(y, y)), mul(z, z));
  apart = either(apart, disk_beyond_slab(dot3(a_axis, b_center), sub(b_lo, b_mid), sub(b_hi, b_mid), along, bn[3],
                                         dot3(b_axis, b_axis), cross2, a_lo, a_hi, slab_reach));
  apart = either(apart, disk_beyond_slab(dot3(b_axis_in_a, center_from_b), sub(a_lo, a_mid), sub(a_hi, a_mid), along, an[3],
                                         dot3(a_axis, a_axis), cross2, b_lo, b_hi, slab_reach));
  return ~_mm256_movemask_pd(apart) & 0xF;
}

CALIBER_AVX2 int node_within_2x2_avx2(const NodeTestFrame& f, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                      std::uint32_t b1) {
  return node_within_2x2_lanes<true>(f, a0, a1, b0, b1);
}
CALIBER_AVX2 int node_within_one_side_avx2(const NodeTestFrame& f, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                           std::uint32_t b1) {
  return node_within_2x2_lanes<false>(f, a0, a1, b0, b1);
}

/// The same code with AVX-512VL's 32 vector registers (the test holds about 50 four-lane values;
/// with 16 registers, many of its instructions were spills). The same operations (no FMA: this
/// file is built with -ffp-contract=off), so the same decisions.
#define CALIBER_AVX512VL __attribute__((target("avx2,avx512f,avx512vl")))
CALIBER_AVX512VL int node_within_2x2_avx512vl(const NodeTestFrame& f, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                              std::uint32_t b1) {
  return node_within_2x2_lanes<true>(f, a0, a1, b0, b1);
}
CALIBER_AVX512VL int node_within_one_side_avx512vl(const NodeTestFrame& f, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                                   std::uint32_t b1) {
  return node_within_2x2_lanes<false>(f, a0, a1, b0, b1);
}
#undef CALIBER_AVX512VL

#undef CALIBER_AVX2

}  // namespace

NodeWithin2x2 node_within_2x2_form(bool wide_registers, bool disks) {
  __builtin_cpu_init();
  if (wide_registers) {
    if (!__builtin_cpu_supports("avx512vl")) return nullptr;
    return disks ? &node_within_2x2_avx512vl : &node_within_one_side_avx512vl;
  }
  if (!__builtin_cpu_supports("avx2")) return nullptr;
  return disks ? &node_within_2x2_avx2 : &node_within_one_side_avx2;
}

NodeWithin2x2 node_within_2x2_avx2_if_supported(bool disks) {
  const NodeWithin2x2 wide = node_within_2x2_form(true, disks);
  return wide != nullptr ? wide : node_within_2x2_form(false, disks);
}

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
NodeWithin2x2 node_within_2x2_form(bool, bool) { return nullptr; }
NodeWithin2x2 node_within_2x2_avx2_if_supported(bool) { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
