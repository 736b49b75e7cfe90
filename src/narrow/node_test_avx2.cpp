// The node test of a visit's child pairs, four at a time (AVX2, chosen at run time where the CPU has it):
// the same decisions as PairContext::node_within's geometry and disks_beyond_slabs on each pair
// (without the disks for a visit where one side descends), bit for bit.

#include "narrow/node_test_avx2.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cstddef>
#include <numbers>

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2")))

/// Lanes of the four node pairs (a0 b0, a0 b1, a1 b0, a1 b1): A's nodes a0 a0 a1 a1, B's b0 b1 b0 b1.
/// The four records' floats come in blocks of four (a vector load of each record, a transpose: a
/// node per lane, a0 a1 b0 b1), each float converted to double (exactly). The blocks' positions in
/// BvhNode and BvhNodeFilter:
static_assert(offsetof(BvhNode, center) == 0 && offsetof(BvhNode, radius) == 12 && offsetof(BvhNode, box_center) == 16 &&
              offsetof(BvhNode, box_half) == 28 && sizeof(BvhNode) == 64);
static_assert(offsetof(BvhNodeFilter, cone_axis) == 0 && offsetof(BvhNodeFilter, slab_lo) == 24 &&
              offsetof(BvhNodeFilter, slab_hi) == 28);

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

/// The floats 4 block .. 4 block + 3 of four records (a0, a1, b0, b1), a record per lane: out[i]
/// holds float 4 block + i of each.
template <class Record>
CALIBER_AVX2 inline void packed_block(const Record& r0, const Record& r1, const Record& r2, const Record& r3, int block,
                                      __m256d out[4]) {
  __m128 x0 = _mm_loadu_ps(reinterpret_cast<const float*>(&r0) + 4 * block);
  __m128 x1 = _mm_loadu_ps(reinterpret_cast<const float*>(&r1) + 4 * block);
  __m128 x2 = _mm_loadu_ps(reinterpret_cast<const float*>(&r2) + 4 * block);
  __m128 x3 = _mm_loadu_ps(reinterpret_cast<const float*>(&r3) + 4 * block);
  _MM_TRANSPOSE4_PS(x0, x1, x2, x3);
  out[0] = _mm256_cvtps_pd(x0);
  out[1] = _mm256_cvtps_pd(x1);
  out[2] = _mm256_cvtps_pd(x2);
  out[3] = _mm256_cvtps_pd(x3);
}

/// From lanes (a0, a1, b0, b1): A's nodes in the four pairs' lanes (a0 a0 a1 a1), and B's (b0 b1 b0 b1).
CALIBER_AVX2 inline __m256d lanes_a(__m256d p) { return _mm256_permute4x64_pd(p, 0b01010000); }
CALIBER_AVX2 inline __m256d lanes_b(__m256d p) { return _mm256_permute4x64_pd(p, 0b11101110); }

/// Coordinate k of m x (m one of NodeLanes' matrices), (m[k][0] x[0] + m[k][1] x[1]) + m[k][2] x[2]:
/// in A's lanes column k of the pose's matrix dotted with x (fill_a's order), in B's row k (fill_b's).
CALIBER_AVX2 inline __m256d lane_dot(const double m[3][3][4], int k, const __m256d x[3]) {
  return add(add(mul(_mm256_loadu_pd(m[k][0]), x[0]), mul(_mm256_loadu_pd(m[k][1]), x[1])), mul(_mm256_loadu_pd(m[k][2]), x[2]));
}

/// The four nodes' floats (a0, a1, b0, b1: a node per lane): sphere center and radius; box center
/// and half-extents; cone axis; slab.
struct FourNodes {
  __m256d center[3], radius, box[3], half[3], axis[3], lo, hi;

  CALIBER_AVX2 __attribute__((always_inline))
  FourNodes(const NodeTestFrame& f, std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1) {
    const BvhNode &na0 = f.nodes_a[a0], &na1 = f.nodes_a[a1], &nb0 = f.nodes_b[b0], &nb1 = f.nodes_b[b1];
    const BvhNodeFilter &fa0 = f.filters_a[a0], &fa1 = f.filters_a[a1], &fb0 = f.filters_b[b0], &fb1 = f.filters_b[b1];
    __m256d n0[4], n1[4], n2[4], f0[4], f1[4];
    packed_block(na0, na1, nb0, nb1, 0, n0);
    packed_block(na0, na1, nb0, nb1, 1, n1);
    packed_block(na0, na1, nb0, nb1, 2, n2);
    packed_block(fa0, fa1, fb0, fb1, 0, f0);
    packed_block(fa0, fa1, fb0, fb1, 1, f1);
    for (int k = 0; k < 3; ++k) {
      center[k] = n0[k];
      box[k] = n1[k];
      axis[k] = f0[k];
    }
    radius = n0[3];
    half[0] = n1[3];
    half[1] = n2[0];
    half[2] = n2[1];
    lo = f1[2];
    hi = f1[3];
  }
};

/// PairContext::prepare_a / prepare_b (with their disks) and node_within with disks_beyond_slabs
/// on the four node pairs, lane by lane the scalar code's operations in its order (fill_a, fill_b,
/// box_beyond_slab, disk_beyond_slab). What each node brings into the other's frame is computed
/// once, for a0, a1, b0 and b1 in four lanes (NodeLanes), then spread to the pairs' lanes where it
/// is read. Inlined into the forms below.
CALIBER_AVX2 __attribute__((always_inline)) inline int node_within_2x2_lanes(const NodeTestFrame& f, const NodeLanes& l,
                                                                             std::uint32_t a0, std::uint32_t a1, std::uint32_t b0,
                                                                             std::uint32_t b1) {
  const __m256d reach = _mm256_set1_pd(f.reach), slab_reach = _mm256_set1_pd(f.slab_reach), hair = _mm256_set1_pd(f.hair);
  const FourNodes nodes(f, a0, a1, b0, b1);
  const __m256d(&center)[3] = nodes.center, radius = nodes.radius, (&box)[3] = nodes.box, (&half)[3] = nodes.half;
  const __m256d(&axis)[3] = nodes.axis, lo = nodes.lo, hi = nodes.hi;
  // Each node in the other's frame (A's: x_b = R^T (x_a - T); B's: R x_b + T), each part just
  // before the tests that read it (shorter lives, fewer spills): B's sphere center (and A's center
  // less T, the disk's), then box center and reach of the half-extents, then slab axis.
  __m256d center_rel[3], center_in[3], box_rel[3], box_in[3], reach_on[3], axis_in[3], slab_on[3];
  for (int k = 0; k < 3; ++k) center_rel[k] = sub(center[k], _mm256_loadu_pd(l.pre[k]));
  for (int k = 0; k < 3; ++k) center_in[k] = add(lane_dot(l.rot, k, center_rel), _mm256_loadu_pd(l.post[k]));
  // Spheres: dist2 accumulates from 0 (0 + x is x), the radii summed before the reach is added.
  __m256d d[3];
  for (int k = 0; k < 3; ++k) d[k] = sub(lanes_a(center[k]), lanes_b(center_in[k]));
  const __m256d dist2 = add(add(mul(d[0], d[0]), mul(d[1], d[1])), mul(d[2], d[2]));
  const __m256d spheres = add(add(lanes_a(radius), lanes_b(radius)), reach);
  __m256d apart = gt(dist2, mul(spheres, spheres));
  for (int k = 0; k < 3; ++k) box_rel[k] = sub(box[k], _mm256_loadu_pd(l.pre[k]));
  for (int k = 0; k < 3; ++k) {
    box_in[k] = add(lane_dot(l.rot, k, box_rel), _mm256_loadu_pd(l.post[k]));
    reach_on[k] = lane_dot(l.abs_rot, k, half);
  }
  for (int k = 0; k < 3; ++k) {  // A's axes, then B's
    apart = either(
        apart, gt(magnitude(sub(lanes_b(box_in[k]), lanes_a(box[k]))), add(add(lanes_a(half[k]), lanes_b(reach_on[k])), reach)));
  }
  for (int k = 0; k < 3; ++k) {
    apart = either(
        apart, gt(magnitude(sub(lanes_b(box[k]), lanes_a(box_in[k]))), add(add(lanes_b(half[k]), lanes_a(reach_on[k])), reach)));
  }
  for (int k = 0; k < 3; ++k) {
    axis_in[k] = lane_dot(l.rot, k, axis);
    slab_on[k] = add(magnitude(axis_in[k]), hair);
  }
  __m256d a_axis[3], b_axis[3], a_box_in_b[3], b_box_in_a[3], a_half[3], b_half[3], a_slab_on_b[3], b_slab_on_a[3];
  for (int k = 0; k < 3; ++k) {
    a_axis[k] = lanes_a(axis[k]);
    b_axis[k] = lanes_b(axis[k]);
    a_box_in_b[k] = lanes_a(box_in[k]);
    b_box_in_a[k] = lanes_b(box_in[k]);
    a_half[k] = lanes_a(half[k]);
    b_half[k] = lanes_b(half[k]);
    a_slab_on_b[k] = lanes_a(slab_on[k]);
    b_slab_on_a[k] = lanes_b(slab_on[k]);
  }
  const __m256d a_lo = lanes_a(lo), a_hi = lanes_a(hi), b_lo = lanes_b(lo), b_hi = lanes_b(hi);
  apart = either(apart, beyond_slab(a_axis, a_slab_on_b, a_lo, a_hi, b_box_in_a, b_half, slab_reach));
  apart = either(apart, beyond_slab(b_axis, b_slab_on_a, b_lo, b_hi, a_box_in_b, a_half, slab_reach));
  // The disks (PairContext::prepare_disk_a, prepare_disk_b, narrow::disks_beyond_slabs): each
  // node's slab about its own sphere's center, and its axis's squared length.
  const __m256d mid = dot3(axis, center), len2 = dot3(axis, axis);
  const __m256d disk_lo = sub(lo, mid), disk_hi = sub(hi, mid);
  __m256d b_axis_in_a[3], b_center[3], center_from_b[3];
  for (int k = 0; k < 3; ++k) {
    b_axis_in_a[k] = lanes_b(axis_in[k]);
    b_center[k] = lanes_b(center_in[k]);
    center_from_b[k] = lanes_a(center_rel[k]);
  }
  const __m256d along = dot3(a_axis, b_axis_in_a);
  const __m256d x = sub(mul(a_axis[1], b_axis_in_a[2]), mul(a_axis[2], b_axis_in_a[1]));
  const __m256d y = sub(mul(a_axis[2], b_axis_in_a[0]), mul(a_axis[0], b_axis_in_a[2]));
  const __m256d z = sub(mul(a_axis[0], b_axis_in_a[1]), mul(a_axis[1], b_axis_in_a[0]));
  const __m256d cross2 = add(add(mul(x, x), mul(y, y)), mul(z, z));
  apart = either(apart, disk_beyond_slab(dot3(a_axis, b_center), lanes_b(disk_lo), lanes_b(disk_hi), along, lanes_b(radius),
                                         lanes_b(len2), cross2, a_lo, a_hi, slab_reach));
  apart = either(apart, disk_beyond_slab(dot3(b_axis_in_a, center_from_b), lanes_a(disk_lo), lanes_a(disk_hi), along,
                                         lanes_a(radius), lanes_a(len2), cross2, b_lo, b_hi, slab_reach));
  return ~_mm256_movemask_pd(apart) & 0xF;
}

/// From lanes (x0, x1, x2, x3): (x2, x3, x0, x1), the halves swapped.
CALIBER_AVX2 inline __m256d swap_halves(__m256d p) { return _mm256_permute2f128_pd(p, p, 0x01); }

/// node_within_2x2_lanes's tests but the disks, on a visit where one side descends (a0 = a1 or
/// b0 = b1): its two pairs P0 = (a0, b0) and P1 = (a1, b1), bits 0 and 3. The nodes are moved as there; each test
/// that has a side of A's and one of B's (the boxes' axes, the slabs) then runs in one set of
/// lanes for both sides, where the four-pair form runs two: lanes 0 and 1 hold P0's and P1's test
/// on A's side, lanes 2 and 3 the same pairs' test on B's side, each lane the four-pair form's
/// operations on the same values (so the same decisions). The spheres fill P0, P1, P0, P1.
CALIBER_AVX2 __attribute__((always_inline)) inline int node_within_one_side_lanes(const NodeTestFrame& f, const NodeLanes& l,
                                                                                  std::uint32_t a0, std::uint32_t a1,
                                                                                  std::uint32_t b0, std::uint32_t b1) {
  const __m256d reach = _mm256_set1_pd(f.reach), slab_reach = _mm256_set1_pd(f.slab_reach), hair = _mm256_set1_pd(f.hair);
  const FourNodes nodes(f, a0, a1, b0, b1);
  const __m256d(&center)[3] = nodes.center, radius = nodes.radius, (&box)[3] = nodes.box, (&half)[3] = nodes.half;
  const __m256d(&axis)[3] = nodes.axis, lo = nodes.lo, hi = nodes.hi;
  // Spheres: A's nodes (lanes 0, 1) against B's moved into A's frame (lanes 2, 3), each half
  // spread over both halves.
  __m256d center_rel[3], center_in[3];
  for (int k = 0; k < 3; ++k) center_rel[k] = sub(center[k], _mm256_loadu_pd(l.pre[k]));
  for (int k = 0; k < 3; ++k) center_in[k] = add(lane_dot(l.rot, k, center_rel), _mm256_loadu_pd(l.post[k]));
  __m256d d[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = sub(_mm256_permute2f128_pd(center[k], center[k], 0x00), _mm256_permute2f128_pd(center_in[k], center_in[k], 0x11));
  }
  const __m256d dist2 = add(add(mul(d[0], d[0]), mul(d[1], d[1])), mul(d[2], d[2]));
  const __m256d spheres =
      add(add(_mm256_permute2f128_pd(radius, radius, 0x00), _mm256_permute2f128_pd(radius, radius, 0x11)), reach);
  __m256d apart = gt(dist2, mul(spheres, spheres));
  // Boxes: axis k of A (lanes 0, 1: B's box moved into A's frame less A's) and of B (lanes 2, 3:
  // B's box less A's moved into B's frame), the half-extents as the four-pair form adds them.
  __m256d box_rel[3], box_in[3], reach_on[3];
  for (int k = 0; k < 3; ++k) box_rel[k] = sub(box[k], _mm256_loadu_pd(l.pre[k]));
  for (int k = 0; k < 3; ++k) {
    box_in[k] = add(lane_dot(l.rot, k, box_rel), _mm256_loadu_pd(l.post[k]));
    reach_on[k] = lane_dot(l.abs_rot, k, half);
  }
  for (int k = 0; k < 3; ++k) {
    const __m256d from = _mm256_permute2f128_pd(box_in[k], box[k], 0x31), to = _mm256_permute2f128_pd(box[k], box_in[k], 0x20);
    apart = either(apart, gt(magnitude(sub(from, to)), add(add(half[k], swap_halves(reach_on[k])), reach)));
  }
  // Slabs: each node's own slab (lanes 0, 1: A's; 2, 3: B's) against the other pair node's box
  // moved into its frame.
  __m256d slab_on[3], other_box[3], other_half[3];
  for (int k = 0; k < 3; ++k) {
    slab_on[k] = add(magnitude(lane_dot(l.rot, k, axis)), hair);
    other_box[k] = swap_halves(box_in[k]);
    other_half[k] = swap_halves(half[k]);
  }
  apart = either(apart, beyond_slab(axis, slab_on, lo, hi, other_box, other_half, slab_reach));
  const int refused = _mm256_movemask_pd(apart);
  const int pass = ~(refused | (refused >> 2)) & 0b11;  // bit 0: P0, bit 1: P1
  return (pass & 1) | ((pass & 2) << 2);
}

CALIBER_AVX2 int node_within_one_side_avx2(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                           std::uint32_t b0, std::uint32_t b1) {
  return node_within_one_side_lanes(f, l, a0, a1, b0, b1);
}

/// The same code with AVX-512VL's 32 vector registers (the test holds dozens of four-lane values;
/// with 16 registers, some of its instructions are spills). The same operations (no FMA: this
/// file is built with -ffp-contract=off), so the same decisions.
#define CALIBER_AVX512VL __attribute__((target("avx2,avx512f,avx512vl")))
CALIBER_AVX512VL int node_within_2x2_avx512vl(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                              std::uint32_t b0, std::uint32_t b1) {
  return node_within_2x2_lanes(f, l, a0, a1, b0, b1);
}
CALIBER_AVX512VL int node_within_one_side_avx512vl(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                                   std::uint32_t b0, std::uint32_t b1) {
  return node_within_one_side_lanes(f, l, a0, a1, b0, b1);
}
#undef CALIBER_AVX512VL

/// PairContext::cones_can_face on the four pairs (a0 b0, a0 b1, a1 b0, a1 b1), its operations in
/// its order in each lane: B's axis moved into A's frame (row k of the pose, left to right), its
/// dot product with A's, the angles' sum and the cosine of the widest angle that can face.
CALIBER_AVX2 int cones_face_2x2_avx2(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                     std::uint32_t b0, std::uint32_t b1, const ConeAngle& angle) {
  __m256d f0[4], f1[4];
  packed_block(f.filters_a[a0], f.filters_a[a1], f.filters_b[b0], f.filters_b[b1], 0, f0);  // axis, angle
  packed_block(f.filters_a[a0], f.filters_a[a1], f.filters_b[b0], f.filters_b[b1], 1, f1);  // cos, sin
  __m256d axis_a[3], moved_b[3];
  for (int k = 0; k < 3; ++k) {
    axis_a[k] = lanes_a(f0[k]);
    moved_b[k] = lanes_b(lane_dot(l.rot, k, f0));  // in B's lanes, row k of the pose
  }
  const __m256d facing = _mm256_xor_pd(dot3(axis_a, moved_b), _mm256_set1_pd(-0.0));
  const __m256d angle_a = lanes_a(f0[3]), angle_b = lanes_b(f0[3]), zero = _mm256_setzero_pd();
  const __m256d degenerate = either(lt(angle_a, zero), lt(angle_b, zero));
  const __m256d total = add(add(angle_a, angle_b), _mm256_set1_pd(angle.theta));
  const __m256d wide = _mm256_cmp_pd(total, _mm256_set1_pd(std::numbers::pi), _CMP_GE_OQ);
  const __m256d ca = lanes_a(f1[0]), sa = lanes_a(f1[1]), cb = lanes_b(f1[0]), sb = lanes_b(f1[1]);
  const __m256d cos_ab = sub(mul(ca, cb), mul(sa, sb)), sin_ab = add(mul(sa, cb), mul(ca, sb));
  const __m256d cos_total = sub(mul(cos_ab, _mm256_set1_pd(angle.cos)), mul(sin_ab, _mm256_set1_pd(angle.sin)));
  const __m256d faces = _mm256_cmp_pd(facing, sub(cos_total, _mm256_set1_pd(angle.margin)), _CMP_GE_OQ);
  return _mm256_movemask_pd(_mm256_andnot_pd(degenerate, either(wide, faces)));
}

}  // namespace

CALIBER_AVX2 int node_within_2x2_double(const NodeTestFrame& f, const NodeLanes& l, std::uint32_t a0, std::uint32_t a1,
                                        std::uint32_t b0, std::uint32_t b1) {
  return node_within_2x2_lanes(f, l, a0, a1, b0, b1);
}

#undef CALIBER_AVX2

NodeWithin2x2 node_within_2x2_form(bool wide_registers, bool disks) {
  __builtin_cpu_init();
  if (wide_registers) {
    if (!__builtin_cpu_supports("avx512vl")) return nullptr;
    return disks ? &node_within_2x2_avx512vl : &node_within_one_side_avx512vl;
  }
  if (!__builtin_cpu_supports("avx2")) return nullptr;
  return disks ? &node_within_2x2_double : &node_within_one_side_avx2;
}

ConesFace2x2 cones_face_2x2_avx2_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? &cones_face_2x2_avx2 : nullptr;
}

NodeWithin2x2 node_within_2x2_avx2_if_supported(bool disks) {
  if (disks && node_within_2x2_float_form() != nullptr) return node_within_2x2_float_form();
  const NodeWithin2x2 wide = node_within_2x2_form(true, disks);
  return wide != nullptr ? wide : node_within_2x2_form(false, disks);
}

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
NodeWithin2x2 node_within_2x2_form(bool, bool) { return nullptr; }
ConesFace2x2 cones_face_2x2_avx2_if_supported() { return nullptr; }
int node_within_2x2_double(const NodeTestFrame&, const NodeLanes&, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t) {
  return 0xF;
}
NodeWithin2x2 node_within_2x2_avx2_if_supported(bool) { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
