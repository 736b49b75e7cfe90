#include "geometry/triangle_intersect.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "geometry/predicates.h"
#include "geometry/triangle_distance.h"

namespace caliber::geometry {
namespace {

using Vec3 = Eigen::Vector3d;

struct P2 {
  double v[2];
};

/// Given x collinear with a and b, whether x lies within the closed segment ab (coordinate bounds).
bool within_bounds(const P2& x, const P2& a, const P2& b) {
  for (int k = 0; k < 2; ++k) {
    if (x.v[k] < std::min(a.v[k], b.v[k]) || x.v[k] > std::max(a.v[k], b.v[k])) return false;
  }
  return true;
}

/// Closed 2-D segments pq and rs meet; exact, degenerate segments (points) included. Segments
/// whose bounding boxes do not meet are apart without an orientation (the comparisons are exact).
bool segments_intersect_2d(const P2& p, const P2& q, const P2& r, const P2& s) {
  for (int k = 0; k < 2; ++k) {
    if (std::max(p.v[k], q.v[k]) < std::min(r.v[k], s.v[k]) || std::max(r.v[k], s.v[k]) < std::min(p.v[k], q.v[k])) return false;
  }
  const int o1 = orient2d(p.v, q.v, r.v);
  const int o2 = orient2d(p.v, q.v, s.v);
  const int o3 = orient2d(r.v, s.v, p.v);
  const int o4 = orient2d(r.v, s.v, q.v);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  if (o1 == 0 && within_bounds(r, p, q)) return true;
  if (o2 == 0 && within_bounds(s, p, q)) return true;
  if (o3 == 0 && within_bounds(p, r, s)) return true;
  if (o4 == 0 && within_bounds(q, r, s)) return true;
  return false;
}

/// Point p lies in the closed 2-D triangle t (which may be degenerate); outside its bounding box,
/// not, without an orientation.
bool point_in_triangle_2d(const P2& p, const P2 t[3]) {
  for (int k = 0; k < 2; ++k) {
    if (p.v[k] < std::min({t[0].v[k], t[1].v[k], t[2].v[k]}) || p.v[k] > std::max({t[0].v[k], t[1].v[k], t[2].v[k]}))
      return false;
  }
  if (orient2d(t[0].v, t[1].v, t[2].v) != 0) {
    const int o1 = orient2d(t[0].v, t[1].v, p.v);
    const int o2 = orient2d(t[1].v, t[2].v, p.v);
    const int o3 = orient2d(t[2].v, t[0].v, p.v);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
  }
  for (int i = 0; i < 3; ++i) {
    const P2& a = t[i];
    const P2& b = t[(i + 1) % 3];
    if (orient2d(a.v, b.v, p.v) == 0 && within_bounds(p, a, b)) return true;
  }
  return false;
}

/// Closed 2-D triangles (possibly degenerate) meet: some edges cross, or one holds the other.
bool triangles_intersect_2d(const P2 a[3], const P2 b[3]) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (segments_intersect_2d(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3])) return true;
    }
  }
  return point_in_triangle_2d(a[0], b) || point_in_triangle_2d(b[0], a);
}

/// For point sets that lie in one common plane: their convex hulls meet iff they meet in all three
/// axis projections (one projection is injective on that plane, and projections keep meetings).
/// Hulls whose bounding boxes do not meet are apart at once (exact comparisons).
bool coplanar_hulls_intersect(const Vec3 a[3], const Vec3 b[3]) {
  for (int k = 0; k < 3; ++k) {
    const double a_lo = std::min({a[0][k], a[1][k], a[2][k]}), a_hi = std::max({a[0][k], a[1][k], a[2][k]});
    const double b_lo = std::min({b[0][k], b[1][k], b[2][k]}), b_hi = std::max({b[0][k], b[1][k], b[2][k]});
    if (a_hi < b_lo || b_hi < a_lo) return false;
  }
  for (int drop = 0; drop < 3; ++drop) {
    const int u = (drop + 1) % 3, v = (drop + 2) % 3;
    P2 pa[3], pb[3];
    for (int i = 0; i < 3; ++i) {
      pa[i] = P2{{a[i][u], a[i][v]}};
      pb[i] = P2{{b[i][u], b[i][v]}};
    }
    if (!triangles_intersect_2d(pa, pb)) return false;
  }
  return true;
}

/// a, b, c lie on one line (or coincide), exactly.
bool collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  for (int drop = 0; drop < 3; ++drop) {
    const int u = (drop + 1) % 3, v = (drop + 2) % 3;
    const double pa[2] = {a[u], a[v]}, pb[2] = {b[u], b[v]}, pc[2] = {c[u], c[v]};
    if (orient2d(pa, pb, pc) != 0) return false;
  }
  return true;
}

/// Segment pq against triangle abc, given sp = orient3d(a,b,c,p) and sq = orient3d(a,b,c,q).
bool segment_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, int sp, int sq) {
  if (sp * sq > 0) return false;
  const int o1 = orient3d(p.data(), q.data(), a.data(), b.data());
  const int o2 = orient3d(p.data(), q.data(), b.data(), c.data());
  const int o3 = orient3d(p.data(), q.data(), c.data(), a.data());
  if (sp != 0 || sq != 0) {
    // The line pq crosses the plane of a non-degenerate triangle at one point of the segment;
    // that point is in the closed triangle iff pq turns the same way around all three edges.
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
  }
  // Here the segment lies in the triangle's plane, or the triangle is degenerate (a segment or a
  // point). In the latter case the five points are coplanar only if all three orientations vanish.
  if (collinear(a, b, c) && (o1 != 0 || o2 != 0 || o3 != 0)) return false;
  const Vec3 seg[3] = {p, q, q};
  const Vec3 tri[3] = {a, b, c};
  return coplanar_hulls_intersect(seg, tri);
}

/// Signs of orient3d(p0, p1, p2, q[i]) for three points, mostly without calling orient3d: the
/// float value s = ((p1 - p0) x (p2 - p0)) . (p0 - q) is trusted when |s| > 1e-13 |u| |v| |w|
/// (u, v the edge vectors, w = q - p0), about 45 times the worst-case rounding of these few
/// operations; otherwise the exact predicate decides. So the signs are always exact.
void plane_signs(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3 q[3], int out[3]) {
  const Vec3 u = p1 - p0, v = p2 - p0;
  const Vec3 n = u.cross(v);
  const double uv2 = u.squaredNorm() * v.squaredNorm();
  for (int i = 0; i < 3; ++i) {
    const Vec3 w = p0 - q[i];
    const double s = n.dot(w);
    if (s * s > 1e-26 * uv2 * w.squaredNorm()) {
      out[i] = s > 0.0 ? 1 : -1;
    } else {
      out[i] = orient3d(p0.data(), p1.data(), p2.data(), q[i].data());
    }
  }
}

bool same_strict_side(const int s[3]) { return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0); }

/// The edge tests: two closed triangles meet iff an edge of one meets the other (the intersection
/// is convex, and its boundary points lie on an edge of one triangle, or one triangle holds the
/// other whole). Given the plane signs sa (A's corners against B's plane) and sb.
bool edges_meet(const Vec3 a[3], const Vec3 b[3], const int sa[3], const int sb[3]) {
  // Coplanar, non-degenerate triangles: one 2-D test instead of six edge tests.
  const bool a_in_plane_of_b = sa[0] == 0 && sa[1] == 0 && sa[2] == 0;
  if (a_in_plane_of_b && !collinear(b[0], b[1], b[2])) return coplanar_hulls_intersect(a, b);
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (segment_triangle(a[i], a[j], b[0], b[1], b[2], sa[i], sa[j])) return true;
  }
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (segment_triangle(b[i], b[j], a[0], a[1], a[2], sb[i], sb[j])) return true;
  }
  return false;
}

/// The corner whose sign differs from the other two (signs nonzero, not all equal).
int lone(const int s[3]) { return s[0] == s[1] ? 2 : (s[0] == s[2] ? 1 : 0); }

/// Guigue and Devillers' test ("Fast and robust triangle-triangle overlap test using orientation
/// predicates", 2003) where no corner lies in the other triangle's plane and each plane cuts the
/// other triangle (every sign nonzero, neither set all equal): both triangles are then proper, and
/// each meets the planes' common line in a segment; they meet iff the two segments overlap, which
/// two orientations decide. A is turned (a rotation keeps its plane's orientation) so that its lone
/// corner p1 comes first, and B's order reversed where orient3d puts p1 on B's negative side (so
/// that orient3d(p2, q2, r2, p1) > 0); then B the same way against A. The paper's two conditions,
/// [p1, q1, p2, q2] <= 0 and [p1, r1, r2, p2] <= 0, hold for any one orientation determinant used
/// throughout (a mirror image flips every sign), here orient3d's. Two orient3d instead of up to
/// eighteen for the edge tests.
bool planes_cross_meet(const Vec3 a[3], const Vec3 b[3], const int sa[3], const int sb[3]) {
  const int i = lone(sa);
  const Vec3* t1[3] = {&a[i], &a[(i + 1) % 3], &a[(i + 2) % 3]};
  const bool keep_b = sa[i] > 0;
  const Vec3* t2[3] = {&b[0], keep_b ? &b[1] : &b[2], keep_b ? &b[2] : &b[1]};
  const int d2[3] = {sb[0], keep_b ? sb[1] : sb[2], keep_b ? sb[2] : sb[1]};
  const int k = lone(d2);
  const Vec3& p2 = *t2[k];
  const Vec3& q2 = *t2[(k + 1) % 3];
  const Vec3& r2 = *t2[(k + 2) % 3];
  const Vec3& p1 = *t1[0];
  const Vec3& q1 = d2[k] > 0 ? *t1[1] : *t1[2];
  const Vec3& r1 = d2[k] > 0 ? *t1[2] : *t1[1];
  return orient3d(p1.data(), q1.data(), p2.data(), q2.data()) <= 0 && orient3d(p1.data(), r1.data(), r2.data(), p2.data()) <= 0;
}

bool no_zero(const int s[3]) { return s[0] != 0 && s[1] != 0 && s[2] != 0; }

}  // namespace

bool segment_intersects_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  return segment_triangle(p, q, a, b, c, orient3d(a.data(), b.data(), c.data(), p.data()),
                          orient3d(a.data(), b.data(), c.data(), q.data()));
}

bool triangles_intersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1, const Vec3& b2) {
  const Vec3 a[3] = {a0, a1, a2};
  const Vec3 b[3] = {b0, b1, b2};
  // Most pairs that reach here are apart: one plane leaves the other triangle on one side.
  int sa[3], sb[3];
  plane_signs(b0, b1, b2, a, sa);
  if (same_strict_side(sa)) return false;
  plane_signs(a0, a1, a2, b, sb);
  if (same_strict_side(sb)) return false;
  if (no_zero(sa) && no_zero(sb)) return planes_cross_meet(a, b, sa, sb);
  return edges_meet(a, b, sa, sb);
}

unsigned triangles_intersect_batch(TriangleBatch& batch) {
  static const detail::IntersectBatch chosen = [] {
    const detail::IntersectBatch lanes = detail::triangles_intersect_batch_lanes_if_supported();
    return lanes != nullptr ? lanes : &detail::triangles_intersect_batch_by_pair;
  }();
  if (batch.size == 0) return 0;
  batch.pad();
  return chosen(batch);
}

namespace detail {

IntersectBatch triangles_intersect_batch_lanes_if_supported() {
  const IntersectBatch avx512 = triangles_intersect_batch_avx512_if_supported();
  return avx512 != nullptr ? avx512 : triangles_intersect_batch_avx2_if_supported();
}

unsigned triangles_intersect_batch_by_pair(const TriangleBatch& batch) {
  return triangles_intersect_lanes(batch, (1u << batch.size) - 1u);
}

unsigned triangles_intersect_lanes(const TriangleBatch& batch, unsigned lanes) {
  unsigned meet = 0;
  for (unsigned left = lanes; left != 0; left &= left - 1) {
    const int l = __builtin_ctz(left);
    Vec3 a[3], b[3];
    batch.get(l, a, b);
    meet |= static_cast<unsigned>(triangles_intersect(a[0], a[1], a[2], b[0], b[1], b[2])) << l;
  }
  return meet;
}

bool triangles_intersect_by_edges(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0, const Vec3& b1,
                                  const Vec3& b2) {
  const Vec3 a[3] = {a0, a1, a2};
  const Vec3 b[3] = {b0, b1, b2};
  int sa[3], sb[3];
  for (int i = 0; i < 3; ++i) {
    sa[i] = orient3d(b0.data(), b1.data(), b2.data(), a[i].data());
    sb[i] = orient3d(a0.data(), a1.data(), a2.data(), b[i].data());
  }
  if (same_strict_side(sa) || same_strict_side(sb)) return false;
  return edges_meet(a, b, sa, sb);
}

}  // namespace detail
}  // namespace caliber::geometry
