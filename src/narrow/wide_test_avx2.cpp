// The wide node test in AVX2 (wide_test.h): the staying node moved in four double lanes, the
// eight slots in eight float lanes; each lane makes wide_test_scalar's operations in its order
// (the multiply-adds fused, as std::fma fuses them there). The test and the traversal loop that
// inlines it are built twice, for AVX2 and for AVX-512VL (its 32 registers): the same operations.

#include "narrow/wide_test.h"

#include "narrow/visit.h"

#include <cmath>
#include <cstddef>
#include <limits>

#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>
#include <immintrin.h>

#include "narrow/lanes8_avx2.h"

namespace caliber::narrow::detail {
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2,fma,f16c")))

using V = __m256;
using D = __m256d;

using namespace lanes8;
/// u v + w, rounded once.
CALIBER_AVX2 inline V fma(V u, V v, V w) { return _mm256_fmadd_ps(u, v, w); }
CALIBER_AVX2 inline V at_most(V u, V v) { return _mm256_cmp_ps(u, v, _CMP_LE_OQ); }
CALIBER_AVX2 inline V at_least(V u, V v) { return _mm256_cmp_ps(u, v, _CMP_GE_OQ); }
CALIBER_AVX2 inline V all(float x) { return _mm256_set1_ps(x); }
CALIBER_AVX2 inline V load(const float* p) { return _mm256_load_ps(p); }
CALIBER_AVX2 inline D addd(D u, D v) { return _mm256_add_pd(u, v); }
CALIBER_AVX2 inline D fmad(D u, D v, D w) { return _mm256_fmadd_pd(u, v, w); }
/// Lanes (x, y, z, 0) of col2 x2 + (col1 x1 + (col0 x0 + w)), each step rounded once.
CALIBER_AVX2 inline D times(const double col[3][4], const double x[3], D w) {
  return fmad(_mm256_load_pd(col[2]), _mm256_set1_pd(x[2]),
              fmad(_mm256_load_pd(col[1]), _mm256_set1_pd(x[1]), fmad(_mm256_load_pd(col[0]), _mm256_set1_pd(x[0]), w)));
}
/// Eight 16-bit grid steps (16-byte aligned), as floats.
CALIBER_AVX2 inline V steps(const std::int16_t* q) {
  return _mm256_cvtepi32_ps(_mm256_cvtepi16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(q))));
}
/// Eight half floats (16-byte aligned), as floats (exact).
CALIBER_AVX2 inline V halves(const std::uint16_t* h) {
  return _mm256_cvtph_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(h)));
}
/// m[2][i] x2 + (m[1][i] x1 + (m[0][i] x0 + w)), lane by lane, each step rounded once.
CALIBER_AVX2 inline V project(const float m[3][3][8], int i, V x0, V x1, V x2, V w) {
  return fma(load(m[2][i]), x2, fma(load(m[1][i]), x1, fma(load(m[0][i]), x0, w)));
}

/// Stage 2 (wide_test_scalar's floats_pass) on every lane, in units: the slots' bounds cl, ch;
/// the staying node as st.
CALIBER_AVX2 __attribute__((always_inline)) inline V floats_pass(const WideLanes& l, const WideSide& s, const WideNode& w,
                                                                 const V cl[3], const V ch[3], const StayingFloats& st) {
  V cc[3], hh[3];
  for (int i = 0; i < 3; ++i) {
    cc[i] = mul(add(cl[i], ch[i]), all(l.half_unit));
    hh[i] = mul(sub(ch[i], cl[i]), all(l.half_unit));
  }
  V pass = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int i = 0; i < 3; ++i) {  // the staying node's axes
    const V p = project(s.m, i, cc[0], cc[1], cc[2], _mm256_setzero_ps());
    const V r = project(s.abs_m, i, hh[0], hh[1], hh[2], all(st.ho[i]));
    pass = both(pass, at_most(magnitude(sub(p, all(st.co[i]))), r));
  }
  const V ax[3] = {halves(w.axis[0]), halves(w.axis[1]), halves(w.axis[2])};
  const V unit = all(l.unit_f), slab_f = all(l.slab_f);
  {  // the staying node's slab: lambda (the slot's slab) + the rest (its box) along the axis
    const V nf[3] = {all(st.nf[0]), all(st.nf[1]), all(st.nf[2])};
    const V dot = fma(ax[2], nf[2], fma(ax[1], nf[1], mul(ax[0], nf[0])));
    const V lambda = both(dot, at_least(magnitude(dot), all(0.5f)));
    V rest[3];
    for (int i = 0; i < 3; ++i) rest[i] = _mm256_fnmadd_ps(lambda, ax[i], nf[i]);
    const V at = fma(rest[2], cc[2], fma(rest[1], cc[1], fma(rest[0], cc[0], all(st.off))));
    const V r = fma(magnitude(rest[2]), hh[2], fma(magnitude(rest[1]), hh[1], mul(magnitude(rest[0]), hh[0])));
    const V e0 = mul(lambda, mul(load(w.slab_lo), unit)), e1 = mul(lambda, mul(load(w.slab_hi), unit));
    const V low = _mm256_min_ps(e0, e1), high = _mm256_max_ps(e0, e1);
    pass = both(pass, both(at_most(add(sub(at, r), low), all(st.slab_hi)), at_least(add(add(at, r), high), all(st.slab_lo))));
  }
  const V slot_hi_reach = fma(load(w.slab_hi), unit, slab_f);
  const V slot_lo_reach = fma(load(w.slab_lo), unit, _mm256_sub_ps(_mm256_setzero_ps(), slab_f));
  if (st.triangle != 0) {  // the slot's slab against the staying triangle's corners
    V at[3];
    for (int j = 0; j < 3; ++j) {
      at[j] = fma(ax[2], all(st.corner[j][2]), fma(ax[1], all(st.corner[j][1]), mul(ax[0], all(st.corner[j][0]))));
    }
    const V low = _mm256_min_ps(_mm256_min_ps(at[0], at[1]), at[2]);
    const V high = _mm256_max_ps(_mm256_max_ps(at[0], at[1]), at[2]);
    const V error = all(st.corner_error);
    return both(pass, both(at_most(sub(low, error), slot_hi_reach), at_least(add(high, error), slot_lo_reach)));
  }
  {  // the slot's slab against the staying box
    const V at = fma(ax[2], all(st.cf[2]), fma(ax[1], all(st.cf[1]), mul(ax[0], all(st.cf[0]))));
    V on[3];
    for (int j = 0; j < 3; ++j) on[j] = fma(ax[2], load(s.m[2][j]), fma(ax[1], load(s.m[1][j]), mul(ax[0], load(s.m[0][j]))));
    const V r = fma(magnitude(on[2]), all(st.sh[2]), fma(magnitude(on[1]), all(st.sh[1]), mul(magnitude(on[0]), all(st.sh[0]))));
    pass = both(pass, both(at_most(sub(at, r), slot_hi_reach), at_least(add(at, r), slot_lo_reach)));
  }
  return pass;
}

/// staying_corners in double lanes (x, y, z, 0), each lane making its operations in its order.
CALIBER_AVX2 inline void staying_corners_avx2(const WideLanes& l, const WideSide& s, const BvhNode& sn, StayingFloats& out) {
  out.triangle = sn.is_leaf() ? 1u : 0u;
  out.corner_error = 0.0f;
  for (float(&c)[4] : out.corner) _mm_storeu_ps(c, _mm_setzero_ps());
  if (out.triangle == 0) return;
  double p[3][3], error;
  bvh::leaf_corners(sn, p, error);
  const D unit = _mm256_set1_pd(l.unit);
  for (int j = 0; j < 3; ++j)
    _mm_storeu_ps(out.corner[j], _mm256_cvtpd_ps(_mm256_mul_pd(times(s.col, p[j], _mm256_load_pd(s.t)), unit)));
  out.corner_error = static_cast<float>(1.75 * error * l.unit);
}

/// make_staying_floats (staying_floats) in double lanes (x, y, z, 0), each lane making its
/// operations in its order; the offset and slab bounds as it computes them.
CALIBER_AVX2 inline void make_staying_floats_avx2(const NodeTestFrame& f, const WideLanes& l, const WideSide& s, bool a_descends,
                                                  std::uint32_t stay, const BvhNode& sn, StayingCache::Entry& kept) {
  if (kept.has_floats) return;
  const StayingSlab sf = staying_slab(f, l, a_descends, stay, sn, [](std::uint16_t h) CALIBER_AVX2 { return _cvtsh_ss(h); });
  const D unit = _mm256_set1_pd(l.unit);
  const D nd = fmad(_mm256_load_pd(s.col[2]), _mm256_set1_pd(sf.axis[2]),
                    fmad(_mm256_load_pd(s.col[1]), _mm256_set1_pd(sf.axis[1]),
                         _mm256_mul_pd(_mm256_load_pd(s.col[0]), _mm256_set1_pd(sf.axis[0]))));
  // Four floats from box_center and box_half, their fourth lanes unused: box_half[0], and `index`
  // (an integer, a subnormal or NaN as a float: zeroed, as such values cost assists).
  const D center = _mm256_cvtps_pd(_mm_loadu_ps(sn.box_center));
  const D half = _mm256_cvtps_pd(_mm_blend_ps(_mm_loadu_ps(sn.box_half), _mm_setzero_ps(), 8));
  const __m128 sh = _mm256_cvtpd_ps(_mm256_mul_pd(half, unit));
  StayingFloats& out = kept.floats;
  // Each four-lane store's fourth lane is overwritten by the next.
  _mm_storeu_ps(out.co, _mm256_cvtpd_ps(_mm256_mul_pd(addd(center, _mm256_load_pd(s.mt_t)), unit)));
  _mm_storeu_ps(out.ho, _mm_add_ps(sh, _mm_set1_ps(l.reach_f)));
  _mm_storeu_ps(out.nf, _mm256_cvtpd_ps(nd));
  alignas(32) double n[4];
  _mm256_store_pd(n, nd);
  out.off = static_cast<float>(-((n[0] * s.t[0] + n[1] * s.t[1]) + n[2] * s.t[2]) * l.unit);
  _mm_storeu_ps(out.cf, _mm256_cvtpd_ps(_mm256_mul_pd(_mm256_load_pd(kept.moved), unit)));
  _mm_storeu_ps(out.sh, sh);
  out.slab_lo = static_cast<float>(sf.lo * l.unit) - l.slab_f;
  out.slab_hi = static_cast<float>(sf.hi * l.unit) + l.slab_f;
  staying_corners_avx2(l, s, sn, out);
  kept.has_floats = true;
}

/// The AVX2 wide test (WideTest). Always inlined where a visit's loop calls it: GCC's limit on an
/// inlined call's stack frame would otherwise keep it out of line (its spare cache entry).
CALIBER_AVX2 __attribute__((always_inline)) inline unsigned wide_test_avx2(const NodeTestFrame& f, const WideLanes& l,
                                                                           bool a_descends, std::uint32_t stay, const BvhNode& sn,
                                                                           const WideNode& w, StayingCache* cache) {
  const WideSide& s = side_of(l, a_descends);
  bool held;
  StayingCache::Entry spare;
  StayingCache::Entry& kept = staying_entry(cache, spare, stay, a_descends, held);
  if (!held) {
    // Stage 1's box: the staying box in the descending frame, in double lanes (x, y, z, 0).
    const StayingBox box = staying_box(sn);
    const D c = times(s.col, box.c, _mm256_load_pd(s.t));
    const D e = times(s.abs_col, box.h, _mm256_set1_pd(l.reach));
    const D magnitude_c = _mm256_andnot_pd(_mm256_set1_pd(-0.0), c);
    const D g = fmad(addd(magnitude_c, e), _mm256_set1_pd(0x1p-22), addd(e, _mm256_set1_pd(l.round_floor)));
    alignas(32) double moved[4];
    _mm256_store_pd(moved, c);
    alignas(16) float lo[4], hi[4];
    _mm_store_ps(lo, _mm256_cvtpd_ps(_mm256_sub_pd(c, g)));
    _mm_store_ps(hi, _mm256_cvtpd_ps(addd(c, g)));
    StayingCache::fill(kept, moved, lo, hi);
  }
  // The slots' bounds from the grid (exact: origin + q step is a float), the empty slots refused.
  V cl[3], ch[3];
  const V step = all(w.step());
  const __m256i ids = _mm256_load_si256(reinterpret_cast<const __m256i*>(w.node));
  V pass = _mm256_castsi256_ps(_mm256_xor_si256(_mm256_cmpeq_epi32(ids, _mm256_set1_epi32(-1)), _mm256_set1_epi32(-1)));
  for (int i = 0; i < 3; ++i) {
    cl[i] = fma(steps(w.lo[i]), step, all(w.origin[i]));
    ch[i] = fma(steps(w.hi[i]), step, all(w.origin[i]));
    pass = both(pass, both(at_most(cl[i], all(kept.hi[i])), at_least(ch[i], all(kept.lo[i]))));
  }
  const auto bits = static_cast<unsigned>(_mm256_movemask_ps(pass));
  if (bits == 0 || !l.floats) return bits;
  // Stage 2 on every lane (each bound is finite, the empty slots' too); only the lanes stage 1
  // passed are kept.
  make_staying_floats_avx2(f, l, s, a_descends, stay, sn, kept);
  return bits & static_cast<unsigned>(_mm256_movemask_ps(floats_pass(l, s, w, cl, ch, kept.floats)));
}

/// For each mask of eight lanes, the lanes set in it, ascending (kReversed: descending), as byte
/// indices, then zeros.
template <bool kReversed>
struct PackTable {
  std::uint64_t order[256];
  constexpr PackTable() : order() {
    for (unsigned m = 0; m < 256; ++m) {
      std::uint64_t packed = 0;
      int at = 0;
      for (int i = 0; i < 8; ++i) {
        const int k = kReversed ? 7 - i : i;
        if ((m >> k & 1u) != 0) packed |= std::uint64_t(k) << (8 * at++);
      }
      order[m] = packed;
    }
  }
};
template <bool kReversed>
inline constexpr PackTable<kReversed> kPackTable{};

static_assert(sizeof(NodePair) == 8 && offsetof(NodePair, a) == 0 && offsetof(NodePair, b) == 4,
              "write_passed writes a NodePair as two 32-bit lanes, A's node first");

/// wide_test_avx2, inlined where a visit calls it.
struct InlinedTest {
  CALIBER_AVX2 unsigned operator()(const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay,
                                   const BvhNode& sn, const WideNode& w, StayingCache* cache) const {
    return wide_test_avx2(f, l, a_descends, stay, sn, w, cache);
  }
  /// Writes the children of visit v that `pass` names to `passed` as visit_wide's loop writes
  /// them, with no branch on the bits: all eight places written, the first popcount(pass) of them
  /// the children (passed has room for kMaxChildren).
  template <bool kReversed>
  CALIBER_AVX2 int write_passed(const WideVisit& v, unsigned pass, NodePair passed[]) const {
    const __m256i ids = _mm256_load_si256(reinterpret_cast<const __m256i*>(v.node->node));
    const __m256i order =
        _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPackTable<kReversed>.order[pass & 0xFFu])));
    const __m256i slots = _mm256_permutevar8x32_epi32(ids, order);
    const __m256i stay = _mm256_set1_epi32(static_cast<int>(v.stay));
    // (a_descends: the slots are A's nodes, the first of each pair; chosen by mask, not by branch.)
    const __m256i slots_first = _mm256_set1_epi32(-static_cast<int>(v.a_descends));
    const __m256i first = _mm256_blendv_epi8(stay, slots, slots_first);
    const __m256i second = _mm256_blendv_epi8(slots, stay, slots_first);
    const __m256i lo = _mm256_unpacklo_epi32(first, second), hi = _mm256_unpackhi_epi32(first, second);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(passed), _mm256_permute2x128_si256(lo, hi, 0x20));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(passed + 4), _mm256_permute2x128_si256(lo, hi, 0x31));
    return __builtin_popcount(pass);
  }
};

/// WideLoop built for AVX2: visit_until_empty with each visit's wide test inlined (no call through
/// a pointer, its per-traversal values kept in registers across visits: flatten).
CALIBER_AVX2 __attribute__((flatten)) void wide_loop_avx2(const PairContext& ctx, std::vector<NodePair>& stack, std::size_t size,
                                                          std::vector<Candidate>& out, QueryStats& stats, TabooView taboo,
                                                          LeafBuffer& buffer, VisitLanes lanes) {
  visit_until_empty(ctx, stack, size, out, stats, taboo, buffer, lanes, InlinedTest{});
}

/// The same loop built for AVX-512VL as well: the same operations on the same lanes (the
/// intrinsics name them, and -ffp-contract=off fuses nothing else), with 32 vector registers, so
/// that more of a visit's values stay in registers rather than being read from the stack again.
__attribute__((target("avx2,fma,f16c,avx512f,avx512vl"), flatten)) void wide_loop_avx512vl(
    const PairContext& ctx, std::vector<NodePair>& stack, std::size_t size, std::vector<Candidate>& out, QueryStats& stats,
    TabooView taboo, LeafBuffer& buffer, VisitLanes lanes) {
  visit_until_empty(ctx, stack, size, out, stats, taboo, buffer, lanes, InlinedTest{});
}

/// The wide test alone (where a visit calls it through kWideTest: a traversal with a limit, the
/// cut of a split pair) built for AVX-512VL as well, as wide_loop_avx512vl.
__attribute__((target("avx2,fma,f16c,avx512f,avx512vl"), flatten)) unsigned wide_test_avx512vl(
    const NodeTestFrame& f, const WideLanes& l, bool a_descends, std::uint32_t stay, const BvhNode& sn, const WideNode& w,
    StayingCache* cache) {
  return wide_test_avx2(f, l, a_descends, stay, sn, w, cache);
}

/// Whether this CPU has AVX-512F and AVX-512VL (the forms built for their 32 registers).
bool avx512vl() { return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"); }

/// slot_order_keys_portable in eight lanes: each lane its operations, in its order, unfused.
CALIBER_AVX2 void slot_order_keys_avx2(const StayingCache::Entry& kept, const WideNode& w, float keys[WideNode::kSlots]) {
  const V step = all(w.step()), magnitude_bits = _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF));
  V offset = _mm256_setzero_ps(), extent = _mm256_setzero_ps();
  for (int i = 0; i < 3; ++i) {
    const V lo = mul(steps(w.lo[i]), step), hi = mul(steps(w.hi[i]), step);
    const float kept_sum = (kept.lo[i] - w.origin[i]) + (kept.hi[i] - w.origin[i]);
    offset = add(offset, _mm256_and_ps(sub(add(lo, hi), all(kept_sum)), magnitude_bits));
    extent = add(extent, add(sub(hi, lo), all(kept.hi[i] - kept.lo[i])));
  }
  _mm256_storeu_ps(keys, _mm256_div_ps(offset, add(extent, all(std::numeric_limits<float>::min()))));
}

/// Whether this CPU runs what this file builds (AVX2, FMA and F16C; F16C from CPUID leaf 1, as
/// clang 14's __builtin_cpu_supports does not know it). Called by the library's constants'
/// initializers: the CPU's features are read first (__builtin_cpu_init), whatever runs before.
bool avx2_and_fma() {
  __builtin_cpu_init();
  unsigned a = 0, b = 0, c = 0, d = 0;
  const bool f16c = __get_cpuid(1, &a, &b, &c, &d) != 0 && (c & bit_F16C) != 0;
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && f16c;
}

}  // namespace

WideTest wide_test_form(bool wide_registers) {
  if (!avx2_and_fma()) return nullptr;
  if (!wide_registers) return wide_test_avx2;
  return avx512vl() ? wide_test_avx512vl : nullptr;
}

WideLoop wide_loop_form(bool wide_registers) {
  if (!avx2_and_fma()) return nullptr;
  if (!wide_registers) return wide_loop_avx2;
  return avx512vl() ? wide_loop_avx512vl : nullptr;
}

SlotOrderKeys slot_order_keys_avx2_if_supported() { return avx2_and_fma() ? slot_order_keys_avx2 : nullptr; }

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
WideTest wide_test_form(bool) { return nullptr; }
WideLoop wide_loop_form(bool) { return nullptr; }
SlotOrderKeys slot_order_keys_avx2_if_supported() { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
