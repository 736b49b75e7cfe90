#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cfloat>

#include "geometry/edge_axes.h"
#include "geometry/lanes_avx2.h"

namespace caliber::geometry {

// triangles_apart on a batch's pairs four at a time, one pair per AVX2 lane (x86-64, chosen at run
// time where the CPU has AVX2 but not AVX-512F): the AVX-512 form's operations
// (triangle_apart_avx512.cpp), which are the portable form's expressions in their order, so each
// lane's verdict is the portable one (tests/geometry/triangle_distance_test.cpp compares them on
// 100,000 pairs). Where a half's four verdicts are settled by the planes, its edge axes are
// skipped; an axis's square root is taken only where some lane's gap is positive.
namespace {

using namespace lanes4;

#define CALIBER_AVX2 __attribute__((target("avx2")))

CALIBER_AVX2 inline __m256d abs4(__m256d u) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), u); }
/// kernel::one_norm: (|x| + |y|) + |z|.
CALIBER_AVX2 inline __m256d one_norm(const Pack3& w) { return _mm256_add_pd(_mm256_add_pd(abs4(w.x), abs4(w.y)), abs4(w.z)); }
/// Eigen's cross product, coordinate by coordinate.
CALIBER_AVX2 inline Pack3 cross(const Pack3& u, const Pack3& v) {
  return {_mm256_sub_pd(_mm256_mul_pd(u.y, v.z), _mm256_mul_pd(u.z, v.y)),
          _mm256_sub_pd(_mm256_mul_pd(u.z, v.x), _mm256_mul_pd(u.x, v.z)),
          _mm256_sub_pd(_mm256_mul_pd(u.x, v.y), _mm256_mul_pd(u.y, v.x))};
}

/// Half `half` of a batch's triangles of one side (lanes 4 half to 4 half + 3), with what the
/// refusal reads: lanes8::Triangle8's values, the same operations.
struct Half {
  Pack3 v[3], e[3], ac, normal;
  __m256d ab2, ac2, normal2;

  CALIBER_AVX2 Half(const double (&c)[3][3][TriangleBatch::kLanes], int half) {
    for (int k = 0; k < 3; ++k) {
      v[k] = {_mm256_load_pd(c[k][0] + 4 * half), _mm256_load_pd(c[k][1] + 4 * half), _mm256_load_pd(c[k][2] + 4 * half)};
    }
    for (int i = 0; i < 3; ++i) e[i] = v[(i + 1) % 3] - v[i];
    ac = v[2] - v[0];
    normal = cross(e[0], ac);  // ab is e[0], v1 - v0: the same subtraction
    ab2 = dot(e[0], e[0]);
    ac2 = dot(ac, ac);
    normal2 = dot(normal, normal);
  }
};

/// kernel::beyond_plane of q's corners against the plane of p, per lane (bits).
CALIBER_AVX2 int beyond_plane(const Half& p, const Half& q, __m256d reach) {
  const __m256d len = _mm256_sqrt_pd(p.normal2);
  const __m256d base = _mm256_mul_pd(_mm256_mul_pd(reach, len), _mm256_set1_pd(1.0 + 1e-12));               // plane_need
  const __m256d slack = _mm256_mul_pd(_mm256_set1_pd(1e-13), _mm256_sqrt_pd(_mm256_mul_pd(p.ab2, p.ac2)));  // plane_slack
  __m256d above = _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), below = above;
  for (int i = 0; i < 3; ++i) {
    const Pack3 w = q.v[i] - p.v[0];
    const __m256d s = dot(p.normal, w);
    const __m256d need = _mm256_add_pd(base, _mm256_mul_pd(slack, one_norm(w)));
    above = _mm256_and_pd(above, gt(s, need));
    below = _mm256_and_pd(below, lt(s, negate(need)));
  }
  return _mm256_movemask_pd(all(gt(len, _mm256_setzero_pd()), any(above, below)));
}

/// kernel::edges_apart per lane: the nine axes' verdicts, ored (bits).
CALIBER_AVX2 int edges_apart(const Half& a, const Half& b, __m256d reach) {
  // kernel::EdgeAxesPair: B's corners less A's first, and the largest 1-norm (lane_max order).
  const Pack3 wb[3] = {b.v[0] - a.v[0], b.v[1] - a.v[0], b.v[2] - a.v[0]};
  const __m256d scale = _mm256_max_pd(_mm256_max_pd(one_norm(a.e[0]), one_norm(a.ac)),
                                      _mm256_max_pd(_mm256_max_pd(one_norm(wb[0]), one_norm(wb[1])), one_norm(wb[2])));
  const __m256d zero = _mm256_setzero_pd();
  int apart = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Pack3 n = cross(a.e[i], b.e[j]);
      const __m256d pa1 = dot(n, a.e[0]), pa2 = dot(n, a.ac);
      const __m256d pb0 = dot(n, wb[0]), pb1 = dot(n, wb[1]), pb2 = dot(n, wb[2]);
      const __m256d amin = _mm256_min_pd(_mm256_min_pd(zero, pa1), pa2);
      const __m256d amax = _mm256_max_pd(_mm256_max_pd(zero, pa1), pa2);
      const __m256d bmin = _mm256_min_pd(_mm256_min_pd(pb0, pb1), pb2);
      const __m256d bmax = _mm256_max_pd(_mm256_max_pd(pb0, pb1), pb2);
      const __m256d gap = _mm256_max_pd(_mm256_sub_pd(bmin, amax), _mm256_sub_pd(amin, bmax));
      const __m256d len2 = dot(n, n);
      const __m256d live =
          all(gt(len2, _mm256_set1_pd(kernel::kAxisLength2Floor)), gt(gap, zero), le(gap, _mm256_set1_pd(DBL_MAX)));
      if (_mm256_movemask_pd(live) == 0) continue;  // need >= 1e-300 > 0: no lane passes
      const __m256d len = _mm256_sqrt_pd(len2);
      const __m256d need =
          _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(reach, len), _mm256_set1_pd(1.0 + 1e-12)),
                        _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(1e-13), len), scale), _mm256_set1_pd(1e-300)));
      apart |= _mm256_movemask_pd(all(live, gt(gap, need)));
    }
  }
  return apart;
}

CALIBER_AVX2 unsigned apart_avx2(const TriangleBatch& batch, double reach) {
  const __m256d r = _mm256_set1_pd(reach);
  unsigned apart = 0;
  for (int half = 0; half < 2 && 4 * half < batch.size; ++half) {
    const Half ta(batch.a, half), tb(batch.b, half);
    int bits = beyond_plane(ta, tb, r) | beyond_plane(tb, ta, r);
    if (bits != 0xF) bits |= edges_apart(ta, tb, r);
    apart |= static_cast<unsigned>(bits) << (4 * half);
  }
  return apart & ((1u << batch.size) - 1u);
}

#undef CALIBER_AVX2

}  // namespace

namespace detail {

ApartBatchTest triangles_apart_batch_avx2_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") ? &apart_avx2 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
ApartBatchTest triangles_apart_batch_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
