#include "geometry/triangle_distance.h"
#include "geometry/edge_axes.h"
#include "geometry/triangle_kernel.h"
#include "util/assert.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <Eigen/Geometry>

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

/// t > 0 ? (t < 1 ? t : 1) : 0: NaN (from 0/0 on a degenerate input) falls to 0 as well. With SSE2
/// as a max then a min, each instruction defined to return exactly what the expression beside it
/// does (NaN and signed zeros included): the same values, and no branch to mispredict.
double clamp01(double t) {
#if defined(__SSE2__)
  const __m128d m = _mm_max_sd(_mm_set_sd(t), _mm_setzero_pd());  // t > 0 ? t : 0
  return _mm_cvtsd_f64(_mm_min_sd(m, _mm_set_sd(1.0)));           // m < 1 ? m : 1
#else
  return t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
#endif
}

/// Where segment pq crosses the plane through a with normal n (floating point), if it does.
bool crossing_point(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& n, Vec3& out) {
  const double sp = n.dot(p - a);
  const double sq = n.dot(q - a);
  if ((sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) || sp == sq) return false;
  const double t = clamp01(sp / (sp - sq));
  out = p + t * (q - p);
  return true;
}

}  // namespace

Vec3 closest_point_on_segment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double len2 = d.squaredNorm();
  if (!(len2 > 0.0)) return p;
  return p + clamp01((x - p).dot(d) / len2) * d;
}

namespace kernel {

Vec3 closest_point_on_frame(const Vec3& x, const TriangleFrame& t) {
  // Ericson, Real-Time Collision Detection, 5.1.5, with guards: a degenerate triangle, or any
  // division that cannot be trusted, falls back to the nearest point on the three edges.
  const Vec3& a = t.v[0];
  const Vec3& b = t.v[1];
  const Vec3& c = t.v[2];
  if (t.solid) {
    const Vec3& ab = t.ab;
    const Vec3& ac = t.ac;
    const Vec3 ax = x - a;
    const double d1 = ab.dot(ax), d2 = ac.dot(ax);
    if (d1 <= 0.0 && d2 <= 0.0) return a;
    const Vec3 bx = x - b;
    const double d3 = ab.dot(bx), d4 = ac.dot(bx);
    if (d3 >= 0.0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) return a + (d1 / (d1 - d3)) * ab;
    const Vec3 cx = x - c;
    const double d5 = ab.dot(cx), d6 = ac.dot(cx);
    if (d6 >= 0.0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {
      return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    }
    if (va >= 0.0 && vb >= 0.0 && vc >= 0.0 && va + vb + vc > 0.0) {
      const double denom = 1.0 / (va + vb + vc);
      const double v = vb * denom, w = vc * denom;
      if (v >= 0.0 && w >= 0.0 && v + w <= 1.0) return a + v * ab + w * ac;
    }
  }
  Vec3 best = closest_point_on_segment(x, a, b);
  double best_d = (best - x).squaredNorm();
  for (const auto& [p, q] : {std::pair<const Vec3&, const Vec3&>{b, c}, std::pair<const Vec3&, const Vec3&>{c, a}}) {
    const Vec3 y = closest_point_on_segment(x, p, q);
    const double d = (y - x).squaredNorm();
    if (d < best_d) {
      best = y;
      best_d = d;
    }
  }
  return best;
}

bool face_projection(const Vec3& x, const TriangleFrame& t, const FacePlane& f, Vec3& out) {
  if (!f.solid) return false;
  const Vec3 ax = x - t.v[0];
  const double s0 = f.inward[0].dot(ax), s1 = f.inward[1].dot(Vec3(x - t.v[1])), s2 = f.inward[2].dot(Vec3(x - t.v[2]));
  if (!(s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0)) return false;
  out = x - (f.n.dot(ax) * f.inv2) * f.n;
  return true;
}

void closest_points_edges(const Vec3& p1, const Vec3& d1, double a, const Vec3& p2, const Vec3& d2, double e, Vec3& c1,
                          Vec3& c2) {
  // Ericson 5.1.9, with the parameters always clamped to [0, 1]. In the general case s minimizes
  // |u + s h| over the lines' parts across d2, h = d1 - (b / e) d2 and u = r - (f / e) d2, both
  // computed: s = -(u . h) / |h|^2. Ericson's (b f - c e) / (a e - b^2) loses the difference of
  // nearly parallel edges' directions to rounding (a e - b^2 cancels to about 2^-53 a e), and its
  // point wanders along the edges, some 2^26 units of rounding farther; from h and u the error
  // stays a few units of rounding of the edges' and r's lengths at any angle (where |h|^2 is a
  // normal number).
  const Vec3 r = p1 - p2;
  const double f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (!(a > 0.0) && !(e > 0.0)) {
    s = t = 0.0;
  } else if (!(a > 0.0)) {
    t = clamp01(f / e);
  } else {
    const double c = d1.dot(r);
    if (!(e >= 0x1p-1022)) {  // zero, or so short that 1 / e overflows: the edge is taken at p2
      s = clamp01(-c / a);
    } else {
      const double b = d1.dot(d2);
      const double inv_e = 1.0 / e;
      const Vec3 h = d1 - (b * inv_e) * d2;
      const Vec3 u = r - (f * inv_e) * d2;
      const double hh = h.squaredNorm();
      s = hh > 0.0 ? clamp01(-u.dot(h) / hh) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = clamp01(-c / a);
      } else if (t > 1.0) {
        t = 1.0;
        s = clamp01((b - c) / a);
      }
      t = clamp01(t);
    }
  }
  c1 = p1 + s * d1;
  c2 = p2 + t * d2;
}

namespace {

/// Each edge vector (corner i to corner i + 1) of both triangles and its squared length: computed
/// once and shared by the 9 edge pairs (the same expressions as computing them per pair).
struct EdgeVectors {
  Vec3 a[3], b[3];
  double la[3], lb[3];

  EdgeVectors(const Vec3 ta[3], const Vec3 tb[3]) {
    for (int i = 0; i < 3; ++i) {
      a[i] = ta[(i + 1) % 3] - ta[i];
      b[i] = tb[(i + 1) % 3] - tb[i];
      la[i] = a[i].squaredNorm();
      lb[i] = b[i].squaredNorm();
    }
  }
};

/// The last feature pairs of the triangle kernel, in its order. Intersecting triangles: an edge of
/// one pierces the other; its crossing point, where it projects into the other's face, and that
/// projection are a feature pair (face_projection).
void consider_crossings(const Vec3 a[3], const Vec3 b[3], const TriangleFrame& fa, const TriangleFrame& fb, const FacePlane& pa,
                        const FacePlane& pb, Nearest& nearest) {
  Vec3 x, y;
  for (int i = 0; i < 3; ++i) {
    if (crossing_point(a[i], a[(i + 1) % 3], b[0], pb.n, x) && face_projection(x, fb, pb, y)) nearest.consider(x, y);
    if (crossing_point(b[i], b[(i + 1) % 3], a[0], pa.n, x) && face_projection(x, fa, pa, y)) nearest.consider(y, x);
  }
}

}  // namespace
}  // namespace kernel

Vec3 closest_point_on_triangle(const Vec3& x, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 corners[3] = {a, b, c};
  return kernel::closest_point_on_frame(x, kernel::TriangleFrame(corners));
}

void closest_points_segments(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, Vec3& c1, Vec3& c2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2;
  kernel::closest_points_edges(p1, d1, d1.squaredNorm(), p2, d2, d2.squaredNorm(), c1, c2);
}

namespace detail {

namespace {

/// The kernel's edge pairs, taken into `nearest` (which starts at the corners 0): true where the
/// early stop (slab_clear) settles the pair there.
bool edge_pairs(const Vec3 a[3], const Vec3 b[3], kernel::Nearest& nearest) {
  const kernel::EdgeVectors e(a, b);
  Vec3 c1, c2;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      kernel::closest_points_edges(a[i], e.a[i], e.la[i], b[j], e.b[j], e.lb[j], c1, c2);
      nearest.consider(c1, c2);
    }
  }
  return kernel::slab_clear(a, b, nearest.best.on_a, nearest.best.on_b);
}

/// The kernel's other feature pairs, taken into `nearest` after the edge pairs: each corner with its
/// projection into the other's face, where it has one (kernel::face_projection), then the crossings.
void face_pairs(const Vec3 a[3], const Vec3 b[3], const kernel::TriangleFrame& fa, const kernel::TriangleFrame& fb,
                kernel::Nearest& nearest) {
  using kernel::face_projection;
  const kernel::FacePlane pa(fa), pb(fb);
  Vec3 y;
  for (int i = 0; i < 3; ++i) {
    if (face_projection(a[i], fb, pb, y)) nearest.consider(a[i], y);
    if (face_projection(b[i], fa, pa, y)) nearest.consider(y, b[i]);
  }
  kernel::consider_crossings(a, b, fa, fb, pa, pb, nearest);
}

}  // namespace

ClosestPoints closest_points_triangles_portable(const Vec3 a[3], const Vec3 b[3]) {
  kernel::Nearest nearest(a[0], b[0]);
  if (!edge_pairs(a, b, nearest)) face_pairs(a, b, kernel::TriangleFrame(a), kernel::TriangleFrame(b), nearest);
  return nearest.best;
}

bool closest_points_triangles_within_portable(const Vec3 a[3], const Vec3 b[3], double reach, ClosestPoints& out) {
  const kernel::TriangleFrame fa(a), fb(b);
  if (kernel::beyond_plane(fa, b, reach) || kernel::beyond_plane(fb, a, reach)) return false;
  kernel::Nearest nearest(a[0], b[0]);
  if (!edge_pairs(a, b, nearest)) {
    if (kernel::edges_apart(fa, b, reach)) return false;
    face_pairs(a, b, fa, fb, nearest);
  }
  out = nearest.best;
  return true;
}

bool triangles_apart_portable(const Vec3 a[3], const Vec3 b[3], double reach) {
  const kernel::TriangleFrame fa(a), fb(b);
  return kernel::beyond_plane(fa, b, reach) || kernel::beyond_plane(fb, a, reach) || kernel::edges_apart(fa, b, reach);
}

void closest_points_triangles_batch_by_pair(const TriangleBatch& batch, ClosestPointsBatch& out) {
  for (int l = 0; l < batch.size; ++l) {
    Vec3 a[3], b[3];
    batch.get(l, a, b);
    out.set(l, closest_points_triangles(a, b));
  }
}

unsigned triangles_apart_batch_by_pair(const TriangleBatch& batch, double reach) {
  unsigned apart = 0;
  for (int l = 0; l < batch.size; ++l) {
    Vec3 a[3], b[3];
    batch.get(l, a, b);
    apart |= static_cast<unsigned>(triangles_apart(a, b, reach)) << l;
  }
  return apart;
}

}  // namespace detail

void TriangleBatch::add(const Vec3 pa[3], const Vec3 pb[3]) {
  CALIBER_ASSERT(size < kLanes, "a triangle batch takes at most kLanes pairs");
  for (int k = 0; k < 3; ++k) {
    for (int c = 0; c < 3; ++c) {
      a[k][c][size] = pa[k][c];
      b[k][c][size] = pb[k][c];
    }
  }
  ++size;
}

void TriangleBatch::get(int lane, Vec3 pa[3], Vec3 pb[3]) const {
  for (int k = 0; k < 3; ++k) {
    pa[k] = Vec3(a[k][0][lane], a[k][1][lane], a[k][2][lane]);
    pb[k] = Vec3(b[k][0][lane], b[k][1][lane], b[k][2][lane]);
  }
}

void TriangleBatch::pad() {
  for (int k = 0; k < 3; ++k) {
    for (int c = 0; c < 3; ++c) {
      for (int l = size; l < kLanes; ++l) {
        a[k][c][l] = a[k][c][0];
        b[k][c][l] = b[k][c][0];
      }
    }
  }
}

void closest_points_triangles_batch(TriangleBatch& batch, ClosestPointsBatch& out) {
  static const detail::BatchKernel chosen = [] {
    if (const detail::BatchKernel avx512 = detail::closest_points_triangles_batch_avx512_if_supported()) return avx512;
    const detail::BatchKernel avx2 = detail::closest_points_triangles_batch_avx2_if_supported();
    return avx2 != nullptr ? avx2 : &detail::closest_points_triangles_batch_by_pair;
  }();
  if (batch.size == 0) return;
  batch.pad();
  chosen(batch, out);
}

unsigned triangles_apart_batch(TriangleBatch& batch, double reach) {
  static const detail::ApartBatchTest chosen = [] {
    if (const detail::ApartBatchTest avx512 = detail::triangles_apart_batch_avx512_if_supported()) return avx512;
    const detail::ApartBatchTest avx2 = detail::triangles_apart_batch_avx2_if_supported();
    return avx2 != nullptr ? avx2 : &detail::triangles_apart_batch_by_pair;
  }();
  if (batch.size == 0) return 0;
  batch.pad();
  return chosen(batch, reach);
}

bool beyond_plane(const Vec3 p[3], const Vec3 q[3], double reach) {
  return kernel::beyond_plane(kernel::TriangleFrame(p), q, reach);
}

/// The AVX2 kernel where the CPU has it, the portable one elsewhere: chosen at the first call.
ClosestPoints closest_points_triangles(const Vec3 a[3], const Vec3 b[3]) {
  static const detail::TriangleKernel chosen = [] {
    const detail::TriangleKernel avx2 = detail::closest_points_triangles_avx2_if_supported();
    return avx2 != nullptr ? avx2 : &detail::closest_points_triangles_portable;
  }();
  return chosen(a, b);
}

bool triangles_apart(const Vec3 a[3], const Vec3 b[3], double reach) {
  static const detail::ApartTest chosen = [] {
    const detail::ApartTest avx2 = detail::triangles_apart_avx2_if_supported();
    return avx2 != nullptr ? avx2 : &detail::triangles_apart_portable;
  }();
  return chosen(a, b, reach);
}

bool closest_points_triangles_within(const Vec3 a[3], const Vec3 b[3], double reach, ClosestPoints& out) {
  static const detail::WithinKernel chosen = [] {
    const detail::WithinKernel avx2 = detail::closest_points_triangles_within_avx2_if_supported();
    return avx2 != nullptr ? avx2 : &detail::closest_points_triangles_within_portable;
  }();
  return chosen(a, b, reach, out);
}

}  // namespace caliber::geometry
