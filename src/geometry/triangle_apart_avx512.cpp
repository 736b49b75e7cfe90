#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <cfloat>

#include "geometry/edge_axes.h"
#include "geometry/lanes_avx512.h"

namespace caliber::geometry {

// triangles_apart on eight pairs at once, one pair per AVX-512 lane (x86-64, chosen at run time
// where the CPU has AVX-512F): the portable form's tests (kernel::beyond_plane both ways,
// kernel::edges_apart's nine axes; triangle_kernel.h, edge_axes.h) with their expressions in their
// order, so each lane's verdict is the portable one (tests/geometry/triangle_distance_test.cpp
// compares them on 100,000 pairs at reaches on both sides of each pair's distance). The verdict is
// an or of the tests, so every test runs in every lane; the square roots of the axes are taken
// only where some lane's gap is positive (elsewhere no lane can pass `gap > need`).
namespace {

using namespace lanes8;

#define CALIBER_AVX512 __attribute__((target("avx512f")))

CALIBER_AVX512 inline D abs(D u) {
  return _mm512_castsi512_pd(_mm512_andnot_si512(_mm512_set1_epi64(INT64_MIN), _mm512_castpd_si512(u)));
}
/// kernel::one_norm: (|x| + |y|) + |z|.
CALIBER_AVX512 inline D one_norm(const P3& w) { return add(add(abs(w.x), abs(w.y)), abs(w.z)); }

/// kernel::beyond_plane of q's corners against the plane of p, per lane.
CALIBER_AVX512 M beyond_plane(const Triangle8& p, const Triangle8& q, D reach) {
  const D len = _mm512_sqrt_pd(p.normal2);
  const D base = mul(mul(reach, len), all_lanes(1.0 + 1e-12));               // plane_need
  const D slack = mul(all_lanes(1e-13), _mm512_sqrt_pd(mul(p.ab2, p.ac2)));  // plane_slack
  M above = 0xFF, below = 0xFF;
  for (int i = 0; i < 3; ++i) {
    const P3 w = q.v[i] - p.v[0];
    const D s = dot(p.normal, w);
    const D need = add(base, mul(slack, one_norm(w)));
    above &= gt(s, need);
    below &= lt(s, negate(need));
  }
  return gt(len, _mm512_setzero_pd()) & (above | below);
}

/// kernel::edges_apart per lane: the nine axes' verdicts, ored.
CALIBER_AVX512 M edges_apart(const Triangle8& a, const Triangle8& b, D reach) {
  // kernel::EdgeAxesPair: B's corners less A's first, and the largest 1-norm (lane_max order).
  const P3 wb[3] = {b.v[0] - a.v[0], b.v[1] - a.v[0], b.v[2] - a.v[0]};
  const D scale = _mm512_max_pd(_mm512_max_pd(one_norm(a.ab), one_norm(a.ac)),
                                _mm512_max_pd(_mm512_max_pd(one_norm(wb[0]), one_norm(wb[1])), one_norm(wb[2])));
  const D zero = _mm512_setzero_pd();
  M apart = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const P3 n = cross(a.e[i], b.e[j]);  // cross3: the same expressions
      const D pa1 = dot(n, a.ab), pa2 = dot(n, a.ac);
      const D pb0 = dot(n, wb[0]), pb1 = dot(n, wb[1]), pb2 = dot(n, wb[2]);
      const D amin = _mm512_min_pd(_mm512_min_pd(zero, pa1), pa2), amax = _mm512_max_pd(_mm512_max_pd(zero, pa1), pa2);
      const D bmin = _mm512_min_pd(_mm512_min_pd(pb0, pb1), pb2), bmax = _mm512_max_pd(_mm512_max_pd(pb0, pb1), pb2);
      const D gap = _mm512_max_pd(sub(bmin, amax), sub(amin, bmax));
      const D len2 = dot(n, n);
      const M live = gt(len2, all_lanes(kernel::kAxisLength2Floor)) & gt(gap, zero) & le(gap, all_lanes(DBL_MAX));
      if (live == 0) continue;  // need >= 1e-300 > 0: no lane passes
      const D len = _mm512_sqrt_pd(len2);
      const D need =
          add(mul(mul(reach, len), all_lanes(1.0 + 1e-12)), add(mul(mul(all_lanes(1e-13), len), scale), all_lanes(1e-300)));
      apart |= live & gt(gap, need);
    }
  }
  return apart;
}

CALIBER_AVX512 unsigned apart_avx512(const TriangleBatch& batch, double reach) {
  const Triangle8 ta(batch.a), tb(batch.b);
  const D r = all_lanes(reach);
  M apart = beyond_plane(ta, tb, r) | beyond_plane(tb, ta, r);
  if (apart != 0xFF) apart |= edges_apart(ta, tb, r);
  return static_cast<unsigned>(apart) & ((1u << batch.size) - 1u);
}

#undef CALIBER_AVX512

}  // namespace

namespace detail {

ApartBatchTest triangles_apart_batch_avx512_if_supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") ? &apart_avx512 : nullptr;
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
ApartBatchTest triangles_apart_batch_avx512_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
