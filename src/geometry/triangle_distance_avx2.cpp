#include "geometry/triangle_distance.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cfloat>
#include <cstdint>

#include "geometry/edge_axes.h"
#include "geometry/lanes_avx2.h"
#include "geometry/triangle_kernel.h"

namespace caliber::geometry {

using kernel::Nearest;
using kernel::TriangleFrame;
using kernel::Vec3;

// The same kernel, four feature pairs at a time in AVX2 registers (x86-64, chosen at run time where the CPU has AVX2 and FMA). Each lane
// computes exactly what the portable code computes for its feature pair: the same IEEE operations in the same order (a fused
// multiply-add only where the portable code calls std::fma: this file is built with -ffp-contract=off, so the compiler fuses
// nothing itself, and enables "avx2" and "fma", where the CPU has both), every region and case of the branches
// evaluated and the one the branches would take selected by masks. Comparisons are the ordered, quiet ones (false on NaN, as in
// C++), and clamp01 is max then min with the operands in the order of the scalar maxsd/minsd of clamp01
// (triangle_distance.cpp), so NaN falls to 0 in every lane as it does there. The feature pairs are then taken by the same Nearest
// in the portable order, so the same pair wins. Eigen computes a 3-vector's dot product as (x0*y0 + x1*y1) + x2*y2; so does
// dot() (lanes_avx2.h; tests/geometry/triangle_distance_test.cpp compares both paths bit for bit).
namespace {

#define CALIBER_AVX2 __attribute__((target("avx2,fma")))

using namespace lanes4;
using lanes4::broadcast;  // beside broadcast and pick on Frame4 below, which would hide them
using lanes4::pick;

/// Four feature pairs' points and squared distances, lane by lane, for Nearest.
struct FeaturePairs4 {
  alignas(32) double px[4], py[4], pz[4], qx[4], qy[4], qz[4], d2[4], d[4];
  int swapped = 0;  ///< bit l: lane l holds (q, p), not (p, q)

  /// Stores the pairs (p, q), or (q, p) in the lanes of `swap` (bits): the squared distance is the
  /// same either way round, since p - q is exactly -(q - p).
  CALIBER_AVX2 void store(const Pack3& p, const Pack3& q, int swap = 0) {
    _mm256_store_pd(px, p.x);
    _mm256_store_pd(py, p.y);
    _mm256_store_pd(pz, p.z);
    _mm256_store_pd(qx, q.x);
    _mm256_store_pd(qy, q.y);
    _mm256_store_pd(qz, q.z);
    swapped = swap;
    const Pack3 pq = q - p;
    const __m256d squared = dot(pq, pq);
    _mm256_store_pd(d2, squared);
    _mm256_store_pd(d, _mm256_sqrt_pd(squared));  // IEEE square roots, as std::sqrt's
  }
  Vec3 p(int l) const { return (swapped >> l) & 1 ? Vec3{qx[l], qy[l], qz[l]} : Vec3{px[l], py[l], pz[l]}; }
  Vec3 q(int l) const { return (swapped >> l) & 1 ? Vec3{px[l], py[l], pz[l]} : Vec3{qx[l], qy[l], qz[l]}; }
};

/// Offers the lanes of `c` in `offered` (bit l for lane l) to `nearest`, in lane order. Lanes whose
/// squared distance is not below the best one at the start are left out: they would be refused,
/// since the best squared distance only ever decreases.
CALIBER_AVX2 __attribute__((always_inline)) inline void take(const FeaturePairs4& c, int offered, Nearest& nearest) {
  int left = offered & _mm256_movemask_pd(lt(_mm256_load_pd(c.d2), _mm256_set1_pd(nearest.best_d2)));
  while (left != 0) {
    const int l = __builtin_ctz(static_cast<unsigned>(left));
    left &= left - 1;
    if (c.d2[l] < nearest.best_d2) nearest.consider(c.p(l), c.q(l), c.d2[l], c.d[l]);
  }
}

/// closest_points_edges in four lanes: every case computed, the branches' choice selected.
CALIBER_AVX2 void closest_points_edges_x4(const Pack3& p1, const Pack3& d1, __m256d a, const Pack3& p2, const Pack3& d2,
                                          __m256d e, FeaturePairs4& out) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const Pack3 r = p1 - p2;
  const __m256d f = dot(d2, r);
  const __m256d c = dot(d1, r);
  const __m256d b = dot(d1, d2);
  const __m256d a_pos = gt(a, zero), e_pos = gt(e, zero), e_ok = ge(e, _mm256_set1_pd(0x1p-1022));
  // a > 0 and e_ok (e at least 2^-1022, so that 1 / e is finite): the general case.
  const __m256d inv_e = _mm256_div_pd(one, e);
  const Pack3 h = d1 - _mm256_mul_pd(b, inv_e) * d2, u = r - _mm256_mul_pd(f, inv_e) * d2;
  const __m256d hh = dot(h, h), s_general = _mm256_and_pd(gt(hh, zero), clamp01x4(_mm256_div_pd(negate(dot(u, h)), hh)));
  const __m256d t_general = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(b, s_general), f), e);
  const __m256d s_at_0 = clamp01x4(_mm256_div_pd(negate(c), a));            // clamp01(-c / a)
  const __m256d s_at_1 = clamp01x4(_mm256_div_pd(_mm256_sub_pd(b, c), a));  // clamp01((b - c) / a)
  const __m256d t_below = lt(t_general, zero), t_above = gt(t_general, one);
  __m256d s = pick(t_below, s_at_0, pick(t_above, s_at_1, s_general));
  __m256d t = clamp01x4(pick(t_below, zero, pick(t_above, one, t_general)));
  // a > 0, e below 2^-1022: t = 0, s = clamp01(-c / a). a not, e > 0: s = 0, t = clamp01(f / e). Neither: 0, 0.
  s = pick(e_ok, s, s_at_0);
  t = _mm256_and_pd(e_ok, t);
  s = _mm256_and_pd(a_pos, s);
  t = pick(a_pos, t, _mm256_and_pd(e_pos, clamp01x4(_mm256_div_pd(f, e))));
  out.store(p1 + s * d1, p2 + t * d2);
}

/// A triangle in four lanes (one triangle or several), with what face_projection reads: its
/// corners and its kernel::FacePlane.
struct Frame4 {
  Pack3 v[3], inward[3], n;
  __m256d inv2;
  __m256d solid;  ///< all ones where the lane's triangle is solid
};

/// kernel::face_projection in four lanes: the projections, and `inside`, the lanes where x projects
/// into the face of a solid triangle (elsewhere the lane's values are not used).
CALIBER_AVX2 Pack3 face_projection_x4(const Pack3& x, const Frame4& t, __m256d& inside) {
  const __m256d zero = _mm256_setzero_pd();
  const Pack3 ax = x - t.v[0];
  const __m256d s0 = dot(t.inward[0], ax), s1 = dot(t.inward[1], x - t.v[1]), s2 = dot(t.inward[2], x - t.v[2]);
  inside = all(t.solid, all(ge(s0, zero), ge(s1, zero), ge(s2, zero)));
  return x - _mm256_mul_pd(dot(t.n, ax), t.inv2) * t.n;
}

/// One triangle's frame in all four lanes.
CALIBER_AVX2 Frame4 broadcast(const TriangleFrame& f, const kernel::FacePlane& p) {
  return {{broadcast(f.v[0]), broadcast(f.v[1]), broadcast(f.v[2])},
          {broadcast(p.inward[0]), broadcast(p.inward[1]), broadcast(p.inward[2])},
          broadcast(p.n),
          _mm256_set1_pd(p.inv2),
          _mm256_castsi256_pd(_mm256_set1_epi64x(p.solid ? -1 : 0))};
}

CALIBER_AVX2 Frame4 pick(__m256d mask, const Frame4& u, const Frame4& v) {
  Frame4 w;
  for (int i = 0; i < 3; ++i) {
    w.v[i] = pick(mask, u.v[i], v.v[i]);
    w.inward[i] = pick(mask, u.inward[i], v.inward[i]);
  }
  w.n = pick(mask, u.n, v.n);
  w.inv2 = pick(mask, u.inv2, v.inv2);
  w.solid = pick(mask, u.solid, v.solid);
  return w;
}

/// The points the kernel projects into the other triangle's face, in the portable order: a[0], b[0],
/// a[1], b[1], a[2], b[2], then the crossing points of the edges that cross the other's plane
/// (edge 0 of A, of B, edge 1 of A, ...). A point of A goes onto B, a point of B onto A; the
/// feature pair is (point, its projection) for A's, (projection, point) for B's.
struct Projections {
  static constexpr int kMost = 12;  ///< 6 corners, 6 crossings
  alignas(32) double x[kMost], y[kMost], z[kMost];
  alignas(32) std::int64_t of_a[kMost];  ///< all ones for a point of A
  int count = 0;

  void add(double px, double py, double pz, bool from_a) {
    x[count] = px;
    y[count] = py;
    z[count] = pz;
    of_a[count] = from_a ? -1 : 0;
    ++count;
  }
  /// Repeats the first point up to a whole number of lanes, so that every loaded lane is defined.
  void pad() {
    for (int i = count; i % 4 != 0; ++i) x[i] = x[0], y[i] = y[0], z[i] = z[0], of_a[i] = of_a[0];
  }
};

/// Each projection of `points` into the other's face, four at a time: batch k of `out` holds points
/// 4k to 4k + 3 with their projections, and bit l of inside[k] is set where point 4k + l has one
/// (the caller offers those to Nearest in that order).
CALIBER_AVX2 void project(const Projections& points, const Frame4& onto_a, const Frame4& onto_b,
                          FeaturePairs4 out[Projections::kMost / 4], int inside[Projections::kMost / 4]) {
  for (int first = 0; first < points.count; first += 4) {
    const Pack3 x{_mm256_load_pd(points.x + first), _mm256_load_pd(points.y + first), _mm256_load_pd(points.z + first)};
    const __m256d of_a = _mm256_castsi256_pd(_mm256_load_si256(reinterpret_cast<const __m256i*>(points.of_a + first)));
    __m256d in_face;
    const Pack3 y = face_projection_x4(x, pick(of_a, onto_b, onto_a), in_face);
    // A's point with its projection on B; B's point's projection on A with the point.
    out[first / 4].store(x, y, ~_mm256_movemask_pd(of_a) & 0xF);
    inside[first / 4] = _mm256_movemask_pd(in_face);
  }
}

/// crossing_point in four lanes: edges p to p + e (e = q - p) whose ends lie sp and sq along the
/// other's normal. Appends the crossing points of the first `count` lanes, in lane order, to
/// `points` (lane l from A where l is even).
CALIBER_AVX2 void add_crossings(const Pack3& p, const Pack3& e, __m256d sp, __m256d sq, int count, Projections& points) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d apart = any(all(gt(sp, zero), gt(sq, zero)), all(lt(sp, zero), lt(sq, zero)), _mm256_cmp_pd(sp, sq, _CMP_EQ_OQ));
  const int crossing = ~_mm256_movemask_pd(apart) & ((1 << count) - 1);
  if (crossing == 0) return;
  const Pack3 x = p + clamp01x4(_mm256_div_pd(sp, _mm256_sub_pd(sp, sq))) * e;
  alignas(32) double xs[4], ys[4], zs[4];
  _mm256_store_pd(xs, x.x);
  _mm256_store_pd(ys, x.y);
  _mm256_store_pd(zs, x.z);
  for (int l = 0; l < count; ++l) {
    if ((crossing >> l) & 1) points.add(xs[l], ys[l], zs[l], l % 2 == 0);
  }
}

/// kernel::beyond_plane of the corners w (relative to the plane's first corner; lanes 0-2) with
/// their signed distances s along the plane's normal, given the normal's length and
/// uv = sqrt(|ab|^2 |ac|^2): the scalar's expressions in its order, so the same verdict.
CALIBER_AVX2 inline bool beyond_plane_x4(const Pack3& w, __m256d s, double len, double uv, double reach) {
  if (!(len > 0.0)) return false;
  const Pack3 m = magnitude(w);
  const __m256d one_norm = _mm256_add_pd(_mm256_add_pd(m.x, m.y), m.z);
  const __m256d need = _mm256_add_pd(_mm256_set1_pd(kernel::plane_need(reach, len)),
                                     _mm256_mul_pd(_mm256_set1_pd(kernel::plane_slack(uv)), one_norm));
  const int above = _mm256_movemask_pd(gt(s, need)) & 0x7, below = _mm256_movemask_pd(lt(s, negate(need))) & 0x7;
  return (above == 0x7) | (below == 0x7);
}

/// kernel::axis_apart on four axes at once (edge e of A and f of B in each lane): bit l set where
/// lane l's axis puts the pair apart. The portable form's expressions in its order.
CALIBER_AVX2 inline int axes_apart_x4(const Pack3& e, const Pack3& f, const kernel::EdgeAxesPair& pair, double reach) {
  const Pack3 n = cross(e, f);
  const __m256d pa1 = dot(n, broadcast(pair.ab)), pa2 = dot(n, broadcast(pair.ac));
  const __m256d pb0 = dot(n, broadcast(pair.wb[0])), pb1 = dot(n, broadcast(pair.wb[1])), pb2 = dot(n, broadcast(pair.wb[2]));
  const __m256d zero = _mm256_setzero_pd();
  const __m256d amin = _mm256_min_pd(_mm256_min_pd(zero, pa1), pa2), amax = _mm256_max_pd(_mm256_max_pd(zero, pa1), pa2);
  const __m256d bmin = _mm256_min_pd(_mm256_min_pd(pb0, pb1), pb2), bmax = _mm256_max_pd(_mm256_max_pd(pb0, pb1), pb2);
  const __m256d gap = _mm256_max_pd(_mm256_sub_pd(bmin, amax), _mm256_sub_pd(amin, bmax));
  const __m256d len2 = dot(n, n), len = _mm256_sqrt_pd(len2);
  const __m256d need =
      _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(reach), len), _mm256_set1_pd(1.0 + 1e-12)),
                    _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(1e-13), len), _mm256_set1_pd(pair.scale)),
                                  _mm256_set1_pd(1e-300)));
  return _mm256_movemask_pd(
      all(gt(len2, _mm256_set1_pd(kernel::kAxisLength2Floor)), gt(gap, need), le(gap, _mm256_set1_pd(DBL_MAX))));
}

/// kernel::edges_apart: the nine edge pairs' axes in the kernel's batches, stopping at the first
/// batch with an axis that puts the pair apart (which one does not matter: the verdict is an or).
CALIBER_AVX2 inline bool edges_apart_x4(const TriangleFrame& fa, const Vec3 b[3], const Triangle4& ta, const Triangle4& tb,
                                        double reach) {
  const kernel::EdgeAxesPair pair(fa, b);
  if (axes_apart_x4(gather<0, 0, 0, 1>(ta.e), gather<0, 1, 2, 0>(tb.e), pair, reach) != 0) return true;
  if (axes_apart_x4(gather<1, 1, 2, 2>(ta.e), gather<1, 2, 0, 1>(tb.e), pair, reach) != 0) return true;
  return (axes_apart_x4(gather<2, 2, 2, 2>(ta.e), gather<2, 2, 2, 2>(tb.e), pair, reach) & 1) != 0;
}

/// The kernel's edge pairs, taken into `nearest` (which starts at the corners 0): true where the
/// early stop (kernel::slab_clear) settles the pair there.
CALIBER_AVX2 __attribute__((always_inline)) inline bool edge_pairs(const Triangle4& ta, const Triangle4& tb, Nearest& nearest) {
  // Edge pairs (i, j) in the portable order: (0,0) (0,1) (0,2) (1,0) in the first four lanes,
  // (1,1) (1,2) (2,0) (2,1) in the next four, (2,2) alone in a third (every lane; lane 0 offered).
  // All three batches are computed before any is offered, so that they do not wait on one another.
  FeaturePairs4 edges[3];
  closest_points_edges_x4(gather<0, 0, 0, 1>(ta.v), gather<0, 0, 0, 1>(ta.e), gather<0, 0, 0, 1>(ta.len2),
                          gather<0, 1, 2, 0>(tb.v), gather<0, 1, 2, 0>(tb.e), gather<0, 1, 2, 0>(tb.len2), edges[0]);
  closest_points_edges_x4(gather<1, 1, 2, 2>(ta.v), gather<1, 1, 2, 2>(ta.e), gather<1, 1, 2, 2>(ta.len2),
                          gather<1, 2, 0, 1>(tb.v), gather<1, 2, 0, 1>(tb.e), gather<1, 2, 0, 1>(tb.len2), edges[1]);
  closest_points_edges_x4(gather<2, 2, 2, 2>(ta.v), gather<2, 2, 2, 2>(ta.e), gather<2, 2, 2, 2>(ta.len2),
                          gather<2, 2, 2, 2>(tb.v), gather<2, 2, 2, 2>(tb.e), gather<2, 2, 2, 2>(tb.len2), edges[2]);
  take(edges[0], 0xF, nearest);
  take(edges[1], 0xF, nearest);
  take(edges[2], 0x1, nearest);
  return slab_clear_x4(ta.v, tb.v, nearest.best.on_a, nearest.best.on_b);
}

/// The kernel's other feature pairs, taken into `nearest` after the edge pairs, given the frames,
/// the corners' lanes, and the corners less the other's first (wa: A's less B's, wb: B's less A's).
CALIBER_AVX2 __attribute__((always_inline)) inline void face_pairs(const Triangle4& ta, const Triangle4& tb,
                                                                   const TriangleFrame& fa, const TriangleFrame& fb,
                                                                   const Pack3& wa, const Pack3& wb, Nearest& nearest) {
  const kernel::FacePlane pa(fa), pb(fb);
  // Each corner's signed distance along the other's normal, as crossing_point computes it.
  const __m256d sa = dot(broadcast(pb.n), wa), sb = dot(broadcast(pa.n), wb);
  // Corner-face feature pairs, then edge-plane crossings (edge i of A and of B against the other's
  // plane: normal n through its first corner), as Projections lists them.
  Projections points;
  const Pack3 corners01 = interleave<0, 1>(ta.v, tb.v), corners2 = interleave<2, 2>(ta.v, tb.v);
  _mm256_store_pd(points.x, corners01.x);
  _mm256_store_pd(points.y, corners01.y);
  _mm256_store_pd(points.z, corners01.z);
  _mm256_store_pd(points.x + 4, corners2.x);
  _mm256_store_pd(points.y + 4, corners2.y);
  _mm256_store_pd(points.z + 4, corners2.z);
  for (int i = 0; i < 6; ++i) points.of_a[i] = i % 2 == 0 ? -1 : 0;
  points.count = 6;
  add_crossings(corners01, interleave<0, 1>(ta.e, tb.e), interleave<0, 1>(sa, sb), interleave<1, 2>(sa, sb), 4, points);
  add_crossings(corners2, interleave<2, 2>(ta.e, tb.e), interleave<2, 2>(sa, sb), interleave<0, 0>(sa, sb), 2, points);
  points.pad();
  FeaturePairs4 projected[Projections::kMost / 4];
  int inside[Projections::kMost / 4];
  project(points, broadcast(fa, pa), broadcast(fb, pb), projected, inside);

  for (int first = 0; first < points.count; first += 4) {
    const int lanes = points.count - first >= 4 ? 0xF : (1 << (points.count - first)) - 1;
    take(projected[first / 4], lanes & inside[first / 4], nearest);
  }
}

/// A triangle pair's lanes and frames: what the plane test and the feature pairs share.
struct Pair4 {
  Triangle4 ta, tb;
  TriangleFrame fa, fb;
  Pack3 wa, wb;  ///< A's corners less B's first, B's less A's

  CALIBER_AVX2 Pair4(const Vec3 a[3], const Vec3 b[3])
      : ta(load(a)), tb(load(b)), fa(a), fb(b), wa(ta.v - broadcast(b[0])), wb(tb.v - broadcast(a[0])) {}
};

#undef CALIBER_AVX2

}  // namespace

namespace detail {

__attribute__((target("avx2,fma"))) ClosestPoints closest_points_triangles_avx2(const Vec3 a[3], const Vec3 b[3]) {
  const Pair4 p(a, b);
  Nearest nearest(a[0], b[0]);
  if (!edge_pairs(p.ta, p.tb, nearest)) face_pairs(p.ta, p.tb, p.fa, p.fb, p.wa, p.wb, nearest);
  return nearest.best;
}

/// The plane tests of the refusal on the pair's lanes: each corner's signed distance along the
/// other's normal as beyond_plane computes it; both planes' lengths and uv in one square root of four
/// lanes (correctly rounded, as std::sqrt).
__attribute__((target("avx2,fma"), always_inline)) inline bool planes_apart(const Pair4& p, double reach) {
  const __m256d sa = dot(broadcast(p.fb.normal), p.wa), sb = dot(broadcast(p.fa.normal), p.wb);
  alignas(32) double roots[4];
  _mm256_store_pd(roots, _mm256_sqrt_pd(lanes(p.fb.normal2, p.fa.normal2, p.fb.ab2 * p.fb.ac2, p.fa.ab2 * p.fa.ac2)));
  return beyond_plane_x4(p.wa, sa, roots[0], roots[2], reach) || beyond_plane_x4(p.wb, sb, roots[1], roots[3], reach);
}

/// closest_points_triangles_within_portable's steps in its order, on the pair's lanes.
__attribute__((target("avx2,fma"))) bool closest_points_triangles_within_avx2(const Vec3 a[3], const Vec3 b[3], double reach,
                                                                              ClosestPoints& out) {
  const Pair4 p(a, b);
  if (planes_apart(p, reach)) return false;
  Nearest nearest(a[0], b[0]);
  if (!edge_pairs(p.ta, p.tb, nearest)) {
    if (edges_apart_x4(p.fa, b, p.ta, p.tb, reach)) return false;
    face_pairs(p.ta, p.tb, p.fa, p.fb, p.wa, p.wb, nearest);
  }
  out = nearest.best;
  return true;
}

__attribute__((target("avx2,fma"))) bool triangles_apart_avx2(const Vec3 a[3], const Vec3 b[3], double reach) {
  const Pair4 p(a, b);
  return planes_apart(p, reach) || edges_apart_x4(p.fa, b, p.ta, p.tb, reach);
}

template <class Form>
Form where_avx2(Form form) {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") ? form : nullptr;
}

ApartTest triangles_apart_avx2_if_supported() { return where_avx2<ApartTest>(&triangles_apart_avx2); }
TriangleKernel closest_points_triangles_avx2_if_supported() { return where_avx2<TriangleKernel>(&closest_points_triangles_avx2); }
WithinKernel closest_points_triangles_within_avx2_if_supported() {
  return where_avx2<WithinKernel>(&closest_points_triangles_within_avx2);
}

}  // namespace detail
}  // namespace caliber::geometry

#else

namespace caliber::geometry::detail {
ApartTest triangles_apart_avx2_if_supported() { return nullptr; }
TriangleKernel closest_points_triangles_avx2_if_supported() { return nullptr; }
WithinKernel closest_points_triangles_within_avx2_if_supported() { return nullptr; }
}  // namespace caliber::geometry::detail

#endif
