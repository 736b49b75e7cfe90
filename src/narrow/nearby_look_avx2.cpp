// The contact reduction's look at each candidate's neighbours in the list (nearby_look.h) in
// vector lanes: the sixteen candidates from eight places before it to seven after it (itself in
// one lane, which never dominates: not closer than itself) in one window of sixteen lanes
// (AVX-512F) or two of eight (AVX2), every comparison made in every lane.

#include "narrow/nearby_look.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

namespace caliber::narrow::detail {
namespace {

using F = NearbyColumns;

/// Column f's field for the field `first` + k.
F::Field field(F::Field first, int k) { return static_cast<F::Field>(first + k); }

#define CALIBER_AVX2 __attribute__((target("avx2")))

using I = __m256i;

CALIBER_AVX2 inline I all(std::uint32_t x) { return _mm256_set1_epi32(static_cast<int>(x)); }
CALIBER_AVX2 inline I load(const std::uint32_t* p) { return _mm256_loadu_si256(reinterpret_cast<const I*>(p)); }

/// The candidate at place p, in every lane.
struct Broadcast {
  __m256d distance;
  I key;  ///< its key with the sign bit flipped (the unsigned order as signed)
  I tri_a, tri_b, corner_a[3], corner_b[3];
};

/// Lanes where one of the three welded corners from column `first` at w equals one of `mine`.
CALIBER_AVX2 inline I shares_corner(const F& c, F::Field first, std::size_t w, const I mine[3]) {
  I shared = _mm256_setzero_si256();
  for (int k = 0; k < 3; ++k) {
    const I corner = load(c.ids(field(first, k)) + w);
    for (int j = 0; j < 3; ++j) shared = _mm256_or_si256(shared, _mm256_cmpeq_epi32(corner, mine[j]));
  }
  return shared;
}

/// Bit l set where the candidate at place w + l dominates the broadcast one (nearby_dominates).
CALIBER_AVX2 inline unsigned dominating(const F& c, std::size_t w, const Broadcast& b) {
  const I same_a = _mm256_cmpeq_epi32(load(c.ids(F::kTriA) + w), b.tri_a);
  const I same_b = _mm256_cmpeq_epi32(load(c.ids(F::kTriB) + w), b.tri_b);
  // B's triangle shared and A's adjacent (distinct, sharing a corner), or the other way round.
  const I by_a = _mm256_and_si256(same_b, _mm256_andnot_si256(same_a, shares_corner(c, F::kCornerA0, w, b.corner_a)));
  const I by_b = _mm256_and_si256(same_a, _mm256_andnot_si256(same_b, shares_corner(c, F::kCornerB0, w, b.corner_b)));
  const auto side = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_or_si256(by_a, by_b))));
  // Closer: a smaller distance, or the same and a smaller key (as the scalar's `!=` and `<`: a NaN
  // is never closer nor passed; a pad, +inf with the largest key, never closer than a candidate).
  const I sign = _mm256_set1_epi64x(static_cast<long long>(std::uint64_t{1} << 63));
  unsigned closer = 0;
  for (int h = 0; h < 2; ++h) {
    const __m256d d = _mm256_loadu_pd(c.distance() + w + 4 * h);
    const I key = _mm256_xor_si256(_mm256_loadu_si256(reinterpret_cast<const I*>(c.key() + w + 4 * h)), sign);
    const __m256d less = _mm256_cmp_pd(d, b.distance, _CMP_LT_OQ);
    const __m256d tie =
        _mm256_and_pd(_mm256_cmp_pd(d, b.distance, _CMP_EQ_OQ), _mm256_castsi256_pd(_mm256_cmpgt_epi64(b.key, key)));
    closer |= static_cast<unsigned>(_mm256_movemask_pd(_mm256_or_pd(less, tie))) << (4 * h);
  }
  return side & closer;
}

CALIBER_AVX2 void nearby_look_avx2(const F& c, std::size_t lo, std::size_t hi, char* dominated) {
  for (std::size_t i = lo; i < hi; ++i) {
    const std::size_t p = i + F::kPad;
    Broadcast b;
    b.distance = _mm256_set1_pd(c.distance()[p]);
    b.key = _mm256_set1_epi64x(static_cast<long long>(c.key()[p] ^ (std::uint64_t{1} << 63)));
    b.tri_a = all(c.ids(F::kTriA)[p]);
    b.tri_b = all(c.ids(F::kTriB)[p]);
    for (int k = 0; k < 3; ++k) {
      b.corner_a[k] = all(c.ids(field(F::kCornerA0, k))[p]);
      b.corner_b[k] = all(c.ids(field(F::kCornerB0, k))[p]);
    }
    const unsigned found = dominating(c, p - F::kPad, b) | dominating(c, p, b);
    dominated[i] = static_cast<char>(found != 0);
  }
}

#undef CALIBER_AVX2

#define CALIBER_AVX512 __attribute__((target("avx2,avx512f")))

/// The same look in sixteen lanes, its comparisons' results as masks.
CALIBER_AVX512 void nearby_look_avx512(const F& c, std::size_t lo, std::size_t hi, char* dominated) {
  const auto column = [&c](F::Field f, std::size_t w) CALIBER_AVX512 { return _mm512_loadu_si512(c.ids(f) + w); };
  const auto mine = [&c](F::Field f, std::size_t p) CALIBER_AVX512 { return _mm512_set1_epi32(static_cast<int>(c.ids(f)[p])); };
  for (std::size_t i = lo; i < hi; ++i) {
    const std::size_t p = i + F::kPad, w = i;  // (the window's first place, p - kPad)
    const __mmask16 same_a = _mm512_cmpeq_epi32_mask(column(F::kTriA, w), mine(F::kTriA, p));
    const __mmask16 same_b = _mm512_cmpeq_epi32_mask(column(F::kTriB, w), mine(F::kTriB, p));
    __mmask16 shared_a = 0, shared_b = 0;
    for (int k = 0; k < 3; ++k) {
      const __m512i corner_a = column(field(F::kCornerA0, k), w), corner_b = column(field(F::kCornerB0, k), w);
      for (int j = 0; j < 3; ++j) {
        shared_a |= _mm512_cmpeq_epi32_mask(corner_a, mine(field(F::kCornerA0, j), p));
        shared_b |= _mm512_cmpeq_epi32_mask(corner_b, mine(field(F::kCornerB0, j), p));
      }
    }
    const unsigned side = (same_b & shared_a & ~same_a) | (same_a & shared_b & ~same_b);
    const __m512d distance = _mm512_set1_pd(c.distance()[p]);
    const __m512i key = _mm512_set1_epi64(static_cast<long long>(c.key()[p]));
    unsigned closer = 0;
    for (int h = 0; h < 2; ++h) {
      const __m512d d = _mm512_loadu_pd(c.distance() + w + 8 * h);
      const __m512i k = _mm512_loadu_si512(c.key() + w + 8 * h);
      const __mmask8 less = _mm512_cmp_pd_mask(d, distance, _CMP_LT_OQ);
      const __mmask8 tie = _mm512_cmp_pd_mask(d, distance, _CMP_EQ_OQ) & _mm512_cmplt_epu64_mask(k, key);
      closer |= static_cast<unsigned>(less | tie) << (8 * h);
    }
    dominated[i] = static_cast<char>((side & closer) != 0);
  }
}

#undef CALIBER_AVX512

}  // namespace

NearbyLook nearby_look_form(int lanes) {
  __builtin_cpu_init();
  if (lanes == 16) return __builtin_cpu_supports("avx512f") ? nearby_look_avx512 : nullptr;
  if (lanes == 8) return __builtin_cpu_supports("avx2") ? nearby_look_avx2 : nullptr;
  return nullptr;
}

}  // namespace caliber::narrow::detail

#else

namespace caliber::narrow::detail {
NearbyLook nearby_look_form(int) { return nullptr; }
}  // namespace caliber::narrow::detail

#endif
